#!/usr/bin/python3
"""numpy peer of the ballbar fit in BM_BallbarDiagnostics_2x36000 (issue 32).

The same two traces (2 x 36,000 samples, R = 100 mm, cyclic period 10 mm given) and the same
18-term model as analysis/src/circle.cpp (docs/circle.md), fitted the way a numpy user would
write it: the dense design built with vectorised numpy, then np.linalg.lstsq, and again by the normal equations. This is the core
fit only: no ISO 230-4 values, no diagnostics' gains, no stick-slip or vibration.
Prints the median CPU time (time.process_time) of --rounds fits.

    /usr/bin/python3 tests/bench/circle_fit_numpy.py --rounds 20   # Debian numpy
"""
import argparse
import statistics
import time

import numpy as np


def traces(n=36_000, seed=1):
    rng = np.random.default_rng(seed)
    out = []
    for s in (1.0, -1.0):
        a = s * np.arange(n) * 360.0 / n
        r = np.radians(a)
        y = 3 * np.cos(2 * r) - 2 * np.sin(2 * r) + 1.5 * s * np.sin(2 * r) + rng.normal(0, 0.2, n)
        out.append((s, r, y))
    return out


def spike(t, s, first, phi):
    total = np.zeros_like(t)
    for tr in (first, first + np.pi):
        d = np.mod(s * (t - tr), 2 * np.pi)
        total += np.exp(-d / phi)
    return total


def fit(tr, solver, radius_mm=100.0, period_mm=10.0, phi=np.radians(6.0)):
    s = np.concatenate([np.full(t.size, sg) for sg, t, _ in tr])
    t = np.concatenate([t for _, t, _ in tr])
    y = np.concatenate([y for _, _, y in tr])
    c, n = np.cos(t), np.sin(t)
    k = 2 * np.pi * radius_mm / period_mm
    a = np.column_stack([
        c, n, np.ones_like(t), np.cos(2 * t), np.sin(2 * t), s * np.sin(2 * t),
        s * np.sign(n) * c, -s * np.sign(c) * n, s * np.abs(c), -s * np.abs(n),
        spike(t, s, 0.0, phi), spike(t, s, np.pi / 2, phi),
        c * np.sin(k * c), c * np.cos(k * c), n * np.sin(k * n), n * np.cos(k * n),
        n * n * c, c * c * n])
    if solver == "lstsq":  # SVD of the design (LAPACK gelsd)
        coef, *_ = np.linalg.lstsq(a, y, rcond=None)
    else:  # normal equations, as caldaq solves them
        coef = np.linalg.solve(a.T @ a, a.T @ y)
    return coef, y - a @ coef


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--rounds", type=int, default=20)
    args = p.parse_args()
    tr = traces()
    for solver in ("lstsq", "normal"):
        times = []
        for _ in range(args.rounds):
            t0 = time.process_time()
            coef, _ = fit(tr, solver)
            times.append(time.process_time() - t0)
        print(f"numpy {np.__version__} core fit ({solver}) of 2 x 36,000 samples: median "
              f"{statistics.median(times) * 1e3:.1f} ms CPU (min {min(times) * 1e3:.1f}, "
              f"{args.rounds} rounds); squareness term {coef[4]:.4f} um")


if __name__ == "__main__":
    main()
