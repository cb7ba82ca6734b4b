#!/usr/bin/env python3
"""The constants of cal::sin_cos (analysis/include/cal/analysis/sin_cos.hpp), derived here.

Run:  python3 analysis/tools/sin_cos_coefficients.py            (prints the C++ block, ~1 min)
      python3 analysis/tools/sin_cos_coefficients.py --check analysis/include/cal/analysis/sin_cos.hpp
                                                    (fails unless the header holds exactly these)
Needs mpmath (1.3 tried).

What it computes, all from mpmath's pi and its series of sin and cos at 256 bits:
  * 2 / pi rounded to a double, and pi / 2 split into p1 (its first 33 bits), p2 (the next 33)
    and p2t (the rest rounded to a double): n p1 and n p2 are exact for |n| < 2^20.
  * The kernels' polynomials on the reduced interval |r| <= pi / 4, z = r^2 in [0, pi^2 / 16]:
      sin r ~ r + r^3 (S1 + S2 z + ... + S6 z^5),  weighted by the relative error of sin r;
      cos r ~ 1 - z / 2 + z^2 (C1 + C2 z + ... + C6 z^5),  weighted by the relative error of cos r.
    Each by the Remez exchange algorithm (minimax in the weighted error), then rounded to doubles
    one coefficient at a time, lowest first, the ones not yet rounded fitted again by Remez to
    what the rounded ones leave (so the rounding of S1 is absorbed by S2 .. S6, and so on).
    The printed bound is the rounded polynomial's own error (max over a dense grid), before the
    kernel's arithmetic adds its roundings; the ulps of the whole are measured by
    analysis/tools/sin_cos_ulps.cpp and tests/analysis/circle_kernels_test.cpp (SinCos.*).
"""
import argparse
import re
import sys

import mpmath as mp

mp.mp.prec = 256
DEGREE = 5  # six coefficients each
Z_MAX = (mp.pi / 4) ** 2


def sin_series(z):
    """(sin x - x) / x^3 for z = x^2, by its Taylor series (no cancellation near 0)."""
    total, term, k = mp.mpf(0), mp.mpf(-1) / 6, 1
    while abs(term) > mp.mpf(2) ** -300:
        total += term
        k += 1
        term = term * (-z) / ((2 * k) * (2 * k + 1))
    return total


def cos_series(z):
    """(cos x - 1 + x^2 / 2) / x^4 for z = x^2, by its Taylor series."""
    total, term, k = mp.mpf(0), mp.mpf(1) / 24, 2
    while abs(term) > mp.mpf(2) ** -300:
        total += term
        k += 1
        term = term * (-z) / ((2 * k - 1) * (2 * k))
    return total


def sin_weight(z):  # r^3 / sin r: the polynomial's error over z's range as sin r's relative one
    x = mp.sqrt(z)
    return z * x / mp.sin(x) if z > 0 else mp.mpf(0)


def cos_weight(z):  # z^2 / cos r
    return z * z / mp.cos(mp.sqrt(z))


def remez(target, weight, powers, lo, hi, iterations=40):
    """Coefficients c of sum c_i z^powers[i] minimising max |weight (target - sum)| on [lo, hi]."""
    n = len(powers)
    # Chebyshev extrema as the first reference (n + 1 points), kept off z = 0 where weight is 0.
    ref = [lo + (hi - lo) * (1 - mp.cos(mp.pi * (j + 0.5) / (n + 1))) / 2 for j in range(n + 1)]
    grid = [lo + (hi - lo) * mp.mpf(j) / 4000 for j in range(1, 4001)]
    coeffs = None
    for _ in range(iterations):
        rows = [[z ** p for p in powers] + [(-1) ** j / weight(z)] for j, z in enumerate(ref)]
        sol = mp.lu_solve(mp.matrix(rows), mp.matrix([target(z) for z in ref]))
        coeffs, level = [sol[i] for i in range(n)], abs(sol[n])

        def err(z, c=coeffs):
            return weight(z) * (target(z) - sum(ci * z ** p for ci, p in zip(c, powers)))

        values = [err(z) for z in grid]
        # Local extrema of the error on the grid, refined by golden-section search.
        ext = []
        for j, v in enumerate(values):
            left = values[j - 1] if j > 0 else None
            right = values[j + 1] if j + 1 < len(values) else None
            if (left is None or abs(v) >= abs(left)) and (right is None or abs(v) >= abs(right)):
                a = grid[max(j - 1, 0)]
                b = grid[min(j + 1, len(grid) - 1)]
                sign = 1 if v > 0 else -1
                for _ in range(60):
                    m1, m2 = a + (b - a) * 0.382, a + (b - a) * 0.618
                    if sign * err(m1) > sign * err(m2):
                        b = m2
                    else:
                        a = m1
                ext.append(((a + b) / 2, err((a + b) / 2)))
        # Keep alternating signs (the larger of neighbours with the same sign).
        alt = []
        for z, e in ext:
            if alt and (alt[-1][1] > 0) == (e > 0):
                if abs(e) > abs(alt[-1][1]):
                    alt[-1] = (z, e)
            else:
                alt.append((z, e))
        while len(alt) > n + 1:  # drop the smaller end
            alt.pop(0 if abs(alt[0][1]) < abs(alt[-1][1]) else -1)
        worst = max(abs(e) for _, e in alt)
        if len(alt) == n + 1:
            ref = [z for z, _ in alt]
        if worst - level < level * mp.mpf(10) ** -12:
            break
    return coeffs, worst


def fit_rounded(series, weight):
    """Remez fit of series(z) by DEGREE + 1 coefficients, rounded to doubles one at a time."""
    fixed = []
    for k in range(DEGREE + 1):
        powers = list(range(k, DEGREE + 1))

        def target(z, done=tuple(fixed)):
            return series(z) - sum(c * z ** i for i, c in enumerate(done))

        coeffs, _ = remez(target, weight, powers, mp.mpf(0), Z_MAX)
        fixed.append(mp.mpf(float(coeffs[0])))  # round to nearest double
    grid = [Z_MAX * mp.mpf(j) / 20000 for j in range(1, 20001)]
    bound = max(abs(weight(z) * (series(z) - sum(c * z ** i for i, c in enumerate(fixed))))
                for z in grid)
    return [float(c) for c in fixed], bound


def pi_over_2_split():
    half_pi = mp.pi / 2
    p1 = mp.floor(half_pi * 2 ** 32) / 2 ** 32  # 33 bits: 1 before the point, 32 after
    rest = half_pi - p1
    e = int(mp.floor(mp.log(rest, 2)))  # rest in [2^e, 2^(e + 1))
    p2 = mp.floor(rest * mp.mpf(2) ** (32 - e)) / mp.mpf(2) ** (32 - e)  # its first 33 bits
    p2t = half_pi - p1 - p2
    assert float(p1) == p1 and float(p2) == p2  # exact doubles, 33 significant bits each
    assert (p1 * 2 ** 32) % 1 == 0 and (p2 * mp.mpf(2) ** (32 - e)) % 1 == 0
    return float(p1), float(p2), float(p2t)


def constants():
    p1, p2, p2t = pi_over_2_split()
    s, s_bound = fit_rounded(sin_series, sin_weight)
    c, c_bound = fit_rounded(cos_series, cos_weight)
    return {
        "two_over_pi": float(2 / mp.pi),
        "p1": p1, "p2": p2, "p2t": p2t,
        **{f"S{i + 1}": v for i, v in enumerate(s)},
        **{f"C{i + 1}": v for i, v in enumerate(c)},
    }, s_bound, c_bound


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", metavar="HEADER", help="fail unless HEADER holds these values")
    args = parser.parse_args()
    values, s_bound, c_bound = constants()
    print(f"// sin kernel polynomial: relative error <= 2^{float(mp.log(s_bound, 2)):.2f}")
    print(f"// cos kernel polynomial: relative error <= 2^{float(mp.log(c_bound, 2)):.2f}")
    for name, v in values.items():
        print(f"{name} = {v.hex()};  // {v!r}")
    if args.check:
        text = open(args.check, encoding="utf-8").read()
        bad = []
        for name, v in values.items():
            m = re.search(rf"\b{name} = (-?0x[0-9a-fA-Fp.+-]+)", text)
            if not m or float.fromhex(m.group(1)) != v:
                bad.append(f"{name}: header {m.group(1) if m else 'missing'}, derived {v.hex()}")
        if bad:
            print("\n".join(["sin_cos.hpp differs from the derived constants:"] + bad))
            sys.exit(1)
        print(f"{args.check}: every constant as derived")


if __name__ == "__main__":
    main()
