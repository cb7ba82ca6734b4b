#pragma once
// sin x and cos x together, without the library call, for the circle analysis' per-sample
// angles and phases (issue 32: glibc's sincos, with its rounding-mode save and restore and its
// slow-path checks, was 10 - 14 % of a long ballbar replay at five or six calls a sample).
// Error, the worst measured (analysis/tools/sin_cos_ulps.cpp against long double, its worst
// cases confirmed with mpmath at 400 bits; sample maxima, not proven bounds): within 0.79 ulp of
// the exact values (0.7803 for sin, 0.7881 for cos) on 10^7 random arguments in each of |x| < pi /
// 4, 20, 2000 and 823549.6; within 0.78 on every double within 8 ulps of n pi / 4 (|n| <= 400);
// within 1.07 on every double within 8 ulps of n pi / 2 (|n| < 2^19), where one value is near 0
// (1.0631 for cos at x = +-0x1.93c05c9ed3cbcp+18, cos x = -2.2756539951781543e-16: the reduction's
// error, n p2t's rounding, is an ulp of so small a value; 0.78 elsewhere). glibc's are within 0.52,
// so about one value in 30 differs from glibc's, by one ulp. The same bounds to 0.01 ulp as with
// fdlibm's coefficients and expressions (this code's first version, measured alike). SinCos.* in
// tests/analysis/circle_kernels_test.cpp checks them. Branch-free for |x| < 2^19 pi / 2 (the
// analysis' angles are a few turns and its phases k c at most 2 pi R / p_min); elsewhere glibc's
// sincos.
//
// Method after fdlibm (Sun, 1993: e_rem_pio2.c, k_sin.c, k_cos.c, as FreeBSD's msun has them).
// The steps are the textbook ones fdlibm takes too, so some expressions have its form: the
// reduction's Cody-Waite steps as in e_rem_pio2.c, and cos's 1 - z / 2 with its rounding error
// recovered by Dekker's Fast2Sum, which k_cos.c writes the same way. The polynomials (Estrin's
// scheme) and every coefficient are this project's: derived here by Remez, see
// analysis/tools/sin_cos_coefficients.py (which prints them, and checks this file with --check).
//   * Reduction (Cody and Waite's): n = nearest(x 2 / pi), r + y = x - n pi / 2 with pi / 2 in
//     three parts, p1 and p2 of 33 bits each, so that n p1 and n p2 are exact for |n| < 2^20,
//     and p2t the rest; r is that difference rounded, y what the rounding left (|y| <= r's ulp).
//   * Kernels on |r| <= pi / 4, z = r^2: sin r ~ r + r^3 (S1 + S2 z + ... + S6 z^5) and
//     cos r ~ 1 - z / 2 + z^2 (C1 + ... + C6 z^5), minimax in the relative error (the
//     polynomials' own: 2^-57.9 and 2^-63.9), y entering to first order: sin(r + y) =
//     sin r + y cos r, cos(r + y) = cos r - y sin r.
//   * The quadrant n mod 4 picks and signs them.
#include <bit>
#include <cmath>
#include <cstdint>

namespace cal {

struct SinCos {
  double s, c;
};

inline SinCos sin_cos(double x) {
  constexpr double limit = 823549.6;  // below 2^19 pi / 2 = 823549.66
  if (!(std::abs(x) < limit)) {
    SinCos out{};
    ::sincos(x, &out.s, &out.c);
    return out;
  }
  // The constants as analysis/tools/sin_cos_coefficients.py derives them (its output, verbatim).
  constexpr double two_over_pi = 0x1.45f306dc9c883p-1;  // 2 / pi rounded
  constexpr double p1 = 0x1.921fb54400000p+0;           // pi / 2's first 33 bits
  constexpr double p2 = 0x1.0b4611a600000p-34;          // the next 33
  constexpr double p2t = 0x1.3198a2e037073p-69;         // pi / 2 - p1 - p2 rounded
  constexpr double S1 = -0x1.5555555555548p-3, S2 = 0x1.111111110f730p-7,
                   S3 = -0x1.a01a019be9217p-13, S4 = 0x1.71de35552b52cp-19,
                   S5 = -0x1.ae5e4b83e46f4p-26, S6 = 0x1.5d8b559495e1dp-33;
  constexpr double C1 = 0x1.555555555554bp-5, C2 = -0x1.6c16c16c15015p-10,
                   C3 = 0x1.a01a019c8f254p-16, C4 = -0x1.27e4f7f19148bp-22,
                   C5 = 0x1.1ee9dbcefbddep-29, C6 = -0x1.8fa684873ff41p-37;

  constexpr double shifter = 0x1.8p52;  // adding it rounds to an integer, kept in the low bits
  const double t = x * two_over_pi + shifter;
  const double n = t - shifter;
  const auto quadrant = std::bit_cast<std::uint64_t>(t);  // n mod 2^51, two's complement
  const double a = x - n * p1;                            // exact (n p1 exact, Sterbenz)
  const double b = a - n * p2;
  const double tail = ((a - b) - n * p2) - n * p2t;  // b's rounding error (exact), less n p2t
  const double r = b + tail, y = (b - r) + tail;     // r + y: x - n pi / 2

  const double z = r * r, w = z * z, v = z * r;
  // sin(r + y) = r + r^3 (S1 + z q) + y (1 - z / 2): the small terms summed first, r last.
  // Both polynomials by Estrin's scheme (independent pairs: fewer dependent multiplications).
  const double q = (S2 + z * S3) + w * (S4 + z * S5) + (w * w) * S6;
  const double sin_r = r + (v * S1 + (v * (z * q) + y * (1.0 - 0.5 * z)));
  // cos(r + y) = 1 - z / 2 + z^2 p - r y, with 1 - z / 2 rounded to `head` and its rounding
  // error recovered exactly (Dekker's Fast2Sum: 1 >= z / 2; 1 - head exact as head >= 1 / 2)
  // and added with the small terms.
  const double p = (C1 + z * C2) + w * (C3 + z * C4) + (w * w) * (C5 + z * C6);
  const double half_z = 0.5 * z, head = 1.0 - half_z;
  const double cos_r = head + (((1.0 - head) - half_z) + (w * p - r * y));

  // Quadrant n mod 4: sin x = sin r, cos r, -sin r, -cos r; cos x = cos r, -sin r, -cos r,
  // sin r. Selected by masks, not branches (the quadrant of a phase k c is not predictable).
  const std::uint64_t swap = 0 - (quadrant & 1);
  const std::uint64_t sb = std::bit_cast<std::uint64_t>(sin_r);
  const std::uint64_t cb = std::bit_cast<std::uint64_t>(cos_r);
  const std::uint64_t s_sign = (quadrant & 2) << 62, c_sign = ((quadrant + 1) & 2) << 62;
  return {std::bit_cast<double>(((cb & swap) | (sb & ~swap)) ^ s_sign),
          std::bit_cast<double>(((sb & swap) | (cb & ~swap)) ^ c_sign)};
}

}  // namespace cal
