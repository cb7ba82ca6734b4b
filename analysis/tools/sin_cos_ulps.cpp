// The measurement behind the error bounds sin_cos.hpp states: cal::sin_cos against long double
// sinl and cosl (glibc's, within one long double ulp: 2^-11 of a double's) on
//   * N random arguments (default 10^7) in each of |x| < pi / 4 (the kernels' own interval),
//     |x| < 20, |x| < 2000 and |x| < 823549.6 (the whole branch-free range), and
//   * every double within 8 ulps of n pi / 2 for |n| < 2^19, and of n pi / 4 for |n| <= 400
//     (where a value is near 0, or the reduction rounds n one way or the other).
// Prints the worst error in ulps (of the exact value rounded to double) of sin and of cos in each
// set and the argument where it is. Run by hand: build/analysis/sin_cos_ulps [N]
// (compiled as the analysis is, -ffp-contract=off: analysis/CMakeLists.txt).
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <random>

#include "cal/analysis/sin_cos.hpp"

namespace {

// |got - exact| in ulps of the exact value rounded to double.
long double ulps(double got, long double exact) {
  const double e = std::abs(static_cast<double>(exact));
  const double ulp = std::nextafter(e, std::numeric_limits<double>::infinity()) - e;
  return std::abs(static_cast<long double>(got) - exact) / ulp;
}

struct Worst {
  long double sin_ulps = 0, cos_ulps = 0;
  double sin_at = 0, cos_at = 0;
  void add(double x) {
    const cal::SinCos got = cal::sin_cos(x);
    const long double lx = x;
    if (const long double e = ulps(got.s, sinl(lx)); e > sin_ulps) sin_ulps = e, sin_at = x;
    if (const long double e = ulps(got.c, cosl(lx)); e > cos_ulps) cos_ulps = e, cos_at = x;
  }
  void print(const char* what) const {
    std::printf("%-34s sin %.4Lf ulp at %a, cos %.4Lf ulp at %a\n", what, sin_ulps, sin_at,
                cos_ulps, cos_at);
  }
};

// Every double within 8 ulps of n step for |n| <= n_max (n step rounded from long double).
Worst near_multiples(long double step, long n_max) {
  Worst worst;
  for (long n = -n_max; n <= n_max; ++n) {
    double x = static_cast<double>(static_cast<long double>(n) * step);
    for (int k = 0; k < 8; ++k) x = std::nextafter(x, -1e300);
    for (int k = 0; k < 17; ++k, x = std::nextafter(x, 1e300))
      if (std::abs(x) < 823549.6) worst.add(x);
  }
  return worst;
}

}  // namespace

int main(int argc, char** argv) {
  const long count = argc > 1 ? std::strtol(argv[1], nullptr, 10) : 10'000'000;
  std::mt19937_64 rng(20261129);
  char label[64];
  for (const double limit : {std::numbers::pi / 4, 20.0, 2000.0, 823549.6}) {
    std::uniform_real_distribution<double> u(-limit, limit);
    Worst worst;
    for (long i = 0; i < count; ++i) worst.add(u(rng));
    std::snprintf(label, sizeof label, "%ld random, |x| < %g:", count, limit);
    worst.print(label);
  }
  const long double pi_l = 3.14159265358979323846264338327950288L;
  near_multiples(pi_l / 2, (1L << 19) - 1).print("within 8 ulps of n pi/2, n < 2^19:");
  near_multiples(pi_l / 4, 400).print("within 8 ulps of n pi/4, n <= 400:");
}
