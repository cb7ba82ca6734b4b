#pragma once
// std::fmod and |std::remainder| of angles, the same values without the library call for the
// arguments the circle analysis meets (a few turns at most). The calls were four to six a
// sample of the ballbar analysis (issue 32, docs/benchmarks.md). Both are exact, so the results
// are the library's bit for bit (tests/analysis/angle_reduce_test.cpp).
#include <algorithm>
#include <cmath>

namespace cal {

// std::fmod(x, y), y > 0. Where |x| < 2 y it is x, or x -+ y, which is exact (Sterbenz:
// y / 2 <= |x| <= 2 y), and a zero keeps the sign of x as fmod's does; elsewhere the call.
inline double fmod_near(double x, double y) {
  const double a = std::abs(x);
  if (a < y) return x;
  if (!(a < 2 * y)) return std::fmod(x, y);
  const double r = x > 0 ? x - y : x + y;
  return r == 0 ? std::copysign(0.0, x) : r;
}

// |std::remainder(x, y)|, y > 0. Where |x| <= 2 y the nearest multiple of y is 0, y or 2 y:
// |x| - y is exact (Sterbenz: y / 2 <= |x| <= 2 y), as is |x| - 2 y from |x| >= y, and below y
// |x| - 2 y exceeds y however it rounds, so the smaller is the exact one (a tie, |x| = 1.5 y,
// gives y / 2 either way). Where 2 y < |x| <= 4 y, |x| - 2 y is exact (Sterbenz again, with
// 2 y) and has the same remainder (its quotient is 2 less, so a tie rounds to even alike):
// the ballbar's angles run past two half turns of the reversals (the stick-slip's distances,
// issue 32). Elsewhere the call.
inline double abs_remainder(double x, double y) {
  double a = std::abs(x);
  if (a > 2 * y && a <= 4 * y) a -= 2 * y;
  if (a <= 0.5 * y) return a;
  if (a <= 2 * y) return std::min(std::abs(a - y), std::abs(a - 2 * y));
  return std::abs(std::remainder(x, y));
}

}  // namespace cal
