// The circle analysis' per-sample kernels (issue 32): cal::sin_cos against long double sin and
// cos, and cal::add_outer_products against exact integer sums and its own portable loop, bit
// for bit.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include "cal/analysis/outer_sums.hpp"
#include "cal/analysis/sin_cos.hpp"

namespace {

constexpr double pi = std::numbers::pi;

// |got - exact| in ulps of the exact value rounded to double.
long double ulps(double got, long double exact) {
  const double e = std::abs(static_cast<double>(exact));
  const double ulp = std::nextafter(e, std::numeric_limits<double>::infinity()) - e;
  return std::abs(static_cast<long double>(got) - exact) / ulp;
}

// Random arguments over the ranges the analysis meets (the reduced range itself, a few turns,
// the phases k c of a short period on a large circle), each quadrant's edges and the doubles
// nearest n pi / 2: within the bounds sin_cos.hpp states (0.79, 0.78 and 1.07 ulp: measured by
// analysis/tools/sin_cos_ulps.cpp on 10^7 arguments a range) of long double's sinl and cosl
// (64-bit mantissas: their own error is 2^-11 of a double's ulp). glibc's sincos is within
// 0.52 ulp on the same arguments; a wrong quadrant, sign or reduction constant is off by 1e14
// ulps and more, a polynomial coefficient wrong in its 10th digit by 10 ulps and more.
TEST(SinCos, WithinTheStatedUlpsOfLongDouble) {
  std::mt19937_64 rng(11);
  for (const double limit : {pi / 4, 20.0, 2000.0, 823549.6}) {
    SCOPED_TRACE(limit);
    std::uniform_real_distribution<double> u(-limit, limit);
    long double worst_s = 0, worst_c = 0;
    for (int i = 0; i < 1'000'000; ++i) {
      const double x = u(rng);
      const cal::SinCos got = cal::sin_cos(x);
      const long double lx = x;
      worst_s = std::max(worst_s, ulps(got.s, std::sin(lx)));
      worst_c = std::max(worst_c, ulps(got.c, std::cos(lx)));
    }
    EXPECT_LT(worst_s, 0.79L);
    EXPECT_LT(worst_c, 0.79L);
    std::printf("sin_cos, |x| < %g: sin within %.3Lf ulp, cos %.3Lf\n", limit, worst_s, worst_c);
  }
  // The edges between quadrants (n pi / 4, where the reduction rounds n one way or the other),
  // 8 ulps either side, values near 0 included (x next to n pi / 2 for even n).
  long double worst = 0;
  for (int n = -400; n <= 400; ++n) {
    double x = n * pi / 4;
    for (int k = 0; k < 8; ++k) x = std::nextafter(x, -1e300);
    for (int k = 0; k < 17; ++k, x = std::nextafter(x, 1e300)) {
      const cal::SinCos got = cal::sin_cos(x);
      const long double lx = x;
      worst = std::max({worst, ulps(got.s, std::sin(lx)), ulps(got.c, std::cos(lx))});
    }
  }
  EXPECT_LT(worst, 0.78L);
  std::printf("sin_cos at the quadrants' edges: within %.3Lf ulp\n", worst);
  // The double nearest n pi / 2 for every n < 2^19, where sin or cos is near 0 (as small as
  // x's ulp times 1e-6 or so): the reduction's own error shows, up to the stated 1.07 ulp.
  const long double half_pi = std::numbers::pi_v<long double> / 2;
  worst = 0;
  double worst_x = 0;
  for (long n = 1; n < (1L << 19); ++n) {
    const double x = static_cast<double>(n * half_pi);
    const cal::SinCos got = cal::sin_cos(x);
    const long double lx = x;
    if (const long double e = std::max(ulps(got.s, std::sin(lx)), ulps(got.c, std::cos(lx)));
        e > worst)
      worst = e, worst_x = x;
  }
  EXPECT_LT(worst, 1.07L);
  std::printf("sin_cos at the doubles nearest n pi / 2, n < 2^19: within %.3Lf ulp (x = %a)\n",
              worst, worst_x);
  // The worst of those, against its exact value: a search of the doubles nearest n pi / 2 for
  // n < 2^19 (mpmath at 400 bits) found cos(0x1.93c05c9ed3cbcp+18) = -2.27565399517815432442e-16,
  // where sin_cos gives 1.0631 ulp from it (glibc: the correctly rounded -2.2756539951781544e-16).
  const long double exact_c = -2.27565399517815432442e-16L;
  const double got_c = cal::sin_cos(0x1.93c05c9ed3cbcp+18).c;
  EXPECT_LT(ulps(got_c, exact_c), 1.07L) << got_c;
  EXPECT_EQ(cal::sin_cos(-0x1.93c05c9ed3cbcp+18).c, got_c);  // cos is even, bit for bit
  std::printf("sin_cos near 0 (x = 0x1.93c05c9ed3cbcp+18): cos within %.4Lf ulp\n",
              ulps(got_c, exact_c));
}

// Beyond the reduction's range (|x| >= 2^19 pi / 2), and for inf and NaN, glibc's values.
TEST(SinCos, LargeAndNonFiniteArgumentsAreGlibcs) {
  for (const double x :
       {823549.6, -823549.6, 1e6, -3e9, 1e300, std::numeric_limits<double>::infinity(),
        std::numeric_limits<double>::quiet_NaN()}) {
    double s = 0, c = 0;
    ::sincos(x, &s, &c);
    const cal::SinCos got = cal::sin_cos(x);
    if (std::isnan(s)) {
      EXPECT_TRUE(std::isnan(got.s) && std::isnan(got.c)) << x;
    } else {
      EXPECT_EQ(got.s, s) << x;
      EXPECT_EQ(got.c, c) << x;
    }
  }
}

// Integers below 2^10 multiplied and summed over at most 300 rows stay below 2^29: every
// product and sum is exact, so each path must give the exact integer sums (checked against
// int64 arithmetic), and a wrong tile, index or row is found at once.
TEST(OuterSums, EveryPathGivesTheExactSumsOfIntegers) {
  std::mt19937_64 rng(5);
  std::uniform_int_distribution<int> v(-1000, 1000);
  for (const std::size_t rows : {1u, 7u, 128u, 300u})
    for (const std::size_t np : {4u, 8u, 12u, 24u, 36u, 52u, 68u}) {
      const std::size_t nw = 16;
      std::vector<double> w(rows * nw), p(rows * np), s(nw * np), sp(nw * np);
      std::vector<std::int64_t> exact(nw * np);
      for (auto& x : w) x = v(rng);
      for (auto& x : p) x = v(rng);
      for (std::size_t k = 0; k < s.size(); ++k) s[k] = sp[k] = static_cast<double>(v(rng));
      for (std::size_t k = 0; k < s.size(); ++k) exact[k] = static_cast<std::int64_t>(s[k]);
      for (std::size_t i = 0; i < rows; ++i)
        for (std::size_t j = 0; j < nw; ++j)
          for (std::size_t m = 0; m < np; ++m)
            exact[j * np + m] +=
                static_cast<std::int64_t>(w[i * nw + j]) * static_cast<std::int64_t>(p[i * np + m]);
      cal::add_outer_products(s.data(), w.data(), p.data(), rows, nw, np);
      cal::add_outer_products_portable(sp.data(), w.data(), p.data(), rows, nw, np);
      for (std::size_t k = 0; k < s.size(); ++k) {
        ASSERT_EQ(s[k], static_cast<double>(exact[k])) << rows << " rows, " << np << ", " << k;
        ASSERT_EQ(sp[k], static_cast<double>(exact[k])) << rows << " rows, " << np << ", " << k;
      }
    }
}

// On values whose sums round, the dispatched path (AVX2 where the CPU has it, else SSE2) and
// the portable loop agree bit for bit: the same products added in the same order.
TEST(OuterSums, DispatchedPathEqualsThePortableLoopBitForBit) {
  std::mt19937_64 rng(9);
  std::normal_distribution<double> v(0.0, 1.0);
  const std::size_t rows = 128, nw = 16, np = 52;
  std::vector<double> w(rows * nw), p(rows * np), s(nw * np, 0.0), sp(nw * np, 0.0);
  for (int block = 0; block < 20; ++block) {
    for (auto& x : w) x = v(rng);
    for (auto& x : p) x = v(rng) * 1e3;
    cal::add_outer_products(s.data(), w.data(), p.data(), rows, nw, np);
    cal::add_outer_products_portable(sp.data(), w.data(), p.data(), rows, nw, np);
  }
  EXPECT_EQ(s, sp);
  std::printf("outer products: %s path\n", cal::outer_products_avx2() ? "AVX2" : "SSE2");
}

// The SSE2 tiles (2 doubles a register, 6 columns a tile) and the AVX2 ones (4, 12) against each
// other, bit for bit, on sums that round: doubles of mixed signs and magnitudes (2^-30 .. 2^30,
// so that nearly every addition rounds and any change in the order of a sum's terms shows),
// onto sums already holding values, at shapes that take each path's wide and narrow tiles
// (np = 4 .. 68) and short and long row counts. Both paths are called explicitly, whatever the
// dispatch picks; without AVX2 on this CPU the SSE2 path is held to the portable loop instead
// (the same order: the reference both tile paths must equal), and the output says which.
TEST(OuterSums, SseTilesEqualAvx2TilesBitForBitOnRoundedSums) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> mantissa(1.0, 2.0);
  std::uniform_int_distribution<int> exponent(-30, 30), sign(0, 1);
  auto mixed = [&] { return (sign(rng) ? -1.0 : 1.0) * std::ldexp(mantissa(rng), exponent(rng)); };
#if !defined(__x86_64__)
  // No tiles in this build (not x86-64): add_outer_products is the portable loop, and the
  // paths say they did not run.
  EXPECT_FALSE(cal::detail::add_outer_products_sse2(nullptr, nullptr, nullptr, 0, 0, 0));
  EXPECT_FALSE(cal::detail::add_outer_products_avx2(nullptr, nullptr, nullptr, 0, 0, 0));
  std::printf("outer products: no SSE2 or AVX2 tiles in this build (not x86-64)\n");
  return;
#endif
  // Nothing to sum: only whether the AVX2 path runs on this CPU.
  const bool avx2 = cal::detail::add_outer_products_avx2(nullptr, nullptr, nullptr, 0, 0, 0);
  std::size_t differing_from_unrounded = 0, compared = 0;
  for (const std::size_t rows : {1u, 3u, 64u, 257u})
    for (const std::size_t np : {4u, 8u, 12u, 16u, 20u, 24u, 36u, 52u, 68u}) {
      const std::size_t nw = 8;
      std::vector<double> w(rows * nw), p(rows * np), s0(nw * np);
      for (auto& x : w) x = mixed();
      for (auto& x : p) x = mixed();
      for (auto& x : s0) x = mixed();
      std::vector<double> sse = s0, other = s0;
      ASSERT_TRUE(
          cal::detail::add_outer_products_sse2(sse.data(), w.data(), p.data(), rows, nw, np));
      if (avx2)
        ASSERT_TRUE(
            cal::detail::add_outer_products_avx2(other.data(), w.data(), p.data(), rows, nw, np));
      else
        cal::add_outer_products_portable(other.data(), w.data(), p.data(), rows, nw, np);
      for (std::size_t k = 0; k < sse.size(); ++k) {
        ASSERT_EQ(std::bit_cast<std::uint64_t>(sse[k]), std::bit_cast<std::uint64_t>(other[k]))
            << rows << " rows, np " << np << ", sum " << k << ": " << sse[k] << " vs " << other[k];
        // That the sums do round: the same terms summed in long double (64-bit mantissas)
        // mostly differ from the double sums (a test on exact sums could not see the order).
        long double wide = s0[k];
        for (std::size_t i = 0; i < rows; ++i)
          wide += static_cast<long double>(w[i * nw + k / np]) * p[i * np + k % np];
        differing_from_unrounded += static_cast<long double>(sse[k]) != wide;
        ++compared;
      }
    }
  // Of the 1 row cases' sums (one product added) some land exactly; the longer sums nearly never.
  EXPECT_GT(differing_from_unrounded, compared / 2) << compared;
  std::printf("outer products: SSE2 tiles against the %s, bit for bit, on %zu sums (%zu rounded)\n",
              avx2 ? "AVX2 tiles" : "portable loop (no AVX2 on this CPU)", compared,
              differing_from_unrounded);
}

}  // namespace
