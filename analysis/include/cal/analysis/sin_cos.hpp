#pragma once
// sin x and cos x together, without the library call, for the circle analysis' per-sample
// angles and phases (issue 32: glibc's sincos, with its rounding-mode save and restore and its
// slow-path checks, was 10 - 14 % of a long ballbar replay at five or six calls a sample).
// Within 0.8 ulp of the exact values on 10^7 random arguments in each of three ranges and at
// the quadrants' edges for |n| <= 400 (against long double: tests/analysis/circle_kernels_test.cpp,
// SinCos.*), where glibc's are within 0.52: so about one value in 30 differs from glibc's, by one
// ulp. Where the value is near 0 (x next to a multiple of pi / 2 far out) it is within 1.1 ulp:
// 1.06 at x = 0x1.93c05c9ed3cbcp+18, the worst of the doubles nearest n pi / 2 for n < 2^19. Branch-free for
// |x| < 2^19 pi / 2 (the analysis' angles are a few turns and its phases k c at most 2 pi R /
// p_min); elsewhere glibc's sincos.
//
// Method (Sun's fdlibm, as FreeBSD's msun has it: e_rem_pio2.c's medium-size reduction,
// k_sin.c and k_cos.c; "Copyright (C) 1993 by Sun Microsystems, Inc. All rights reserved.
// Developed at SunPro, a Sun Microsystems, Inc. business. Permission to use, copy, modify, and
// distribute this software is freely granted, provided that this notice is preserved."):
// n = nearest(x 2 / pi) and r = x - n pi / 2 in two parts (head r, tail y) from pi / 2 split into
// 33-bit pieces, so that n p1 and n p2 are exact for |n| < 2^20; then the minimax polynomials
// of sin and cos on [-pi / 4, pi / 4] (their own error below 2^-58), and the quadrant n mod 4
// picks and signs them.
#include <bit>
#include <cmath>
#include <cstdint>

namespace cal {

struct SinCos {
  double s, c;
};

inline SinCos sin_cos(double x) {
  constexpr double limit = 823549.6;  // 2^19 pi / 2
  if (!(std::abs(x) < limit)) {
    SinCos out{};
    ::sincos(x, &out.s, &out.c);
    return out;
  }
  constexpr double two_over_pi = 6.36619772367581382433e-01;
  constexpr double shifter = 0x1.8p52;  // adding it rounds to an integer, kept in the low bits
  constexpr double p1 = 1.57079632673412561417e+00;   // the first 33 bits of pi / 2
  constexpr double p2 = 6.07710050630396597660e-11;   // the next 33
  constexpr double p2t = 2.02226624879595063154e-21;  // pi / 2 - p1 - p2
  const double t = x * two_over_pi + shifter;
  const double n = t - shifter;
  const auto quadrant = std::bit_cast<std::uint64_t>(t);  // n mod 2^51, two's complement
  const double a = x - n * p1;                            // exact
  const double b = a - n * p2;
  const double tail = ((a - b) - n * p2) - n * p2t;  // b's rounding error (exact), less n p2t
  const double r = b + tail, y = (b - r) + tail;     // r + y: x - n pi / 2, y within r's ulp
  const double z = r * r, w = z * z, v = z * r;
  constexpr double S1 = -1.66666666666666324348e-01, S2 = 8.33333333332248946124e-03,
                   S3 = -1.98412698298579493134e-04, S4 = 2.75573137070700676789e-06,
                   S5 = -2.50507602534068634195e-08, S6 = 1.58969099521155010221e-10;
  const double ps = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6);
  const double sin_r = r - ((z * (0.5 * y - v * ps) - y) - v * S1);
  constexpr double C1 = 4.16666666666666019037e-02, C2 = -1.38888888888741095749e-03,
                   C3 = 2.48015872894767294178e-05, C4 = -2.75573143513906633035e-07,
                   C5 = 2.08757232129817482790e-09, C6 = -1.13596475577881948265e-11;
  const double pc = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
  const double hz = 0.5 * z, one_hz = 1.0 - hz;
  const double cos_r = one_hz + (((1.0 - one_hz) - hz) + (z * pc - r * y));
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
