// cal::fmod_near and cal::abs_remainder against std::fmod and std::remainder, bit for bit (the
// circle analysis' results must not move with them: issue 32).
#include "cal/analysis/angle_reduce.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

namespace {

constexpr double pi = std::numbers::pi;

// Values about every boundary of the fast paths (0, y / 2, y, 1.5 y, 2 y, 3 y, 3.5 y, 4 y) and
// their neighbours a few ulps away, both signs, plus random ones over a few turns and far beyond.
std::vector<double> cases(double y) {
  std::vector<double> v = {0.0,
                           -0.0,
                           std::numeric_limits<double>::denorm_min(),
                           std::numeric_limits<double>::infinity(),
                           std::numeric_limits<double>::quiet_NaN(),
                           1e300};
  for (double m : {0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0, 4.5}) {
    double x = m * y;
    for (int k = 0; k < 4; ++k) x = std::nextafter(x, 0.0);
    for (int k = 0; k < 9; ++k, x = std::nextafter(x, 1e300)) v.push_back(x);
  }
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> turns(-5 * y, 5 * y), far(-1e6, 1e6);
  for (int i = 0; i < 200'000; ++i) v.push_back(turns(rng));
  for (int i = 0; i < 10'000; ++i) v.push_back(far(rng));
  const std::size_t n = v.size();
  for (std::size_t i = 0; i < n; ++i) v.push_back(-v[i]);
  return v;
}

bool same_bits(double a, double b) {
  return std::isnan(a) ? std::isnan(b)
                       : std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

TEST(AngleReduce, FmodNearIsStdFmodBitForBit) {
  for (double y : {2 * pi, 360.0, pi, 1.0}) {
    int wrong = 0;
    for (double x : cases(y))
      if (!same_bits(cal::fmod_near(x, y), std::fmod(x, y)) && ++wrong < 5)
        ADD_FAILURE() << "x " << x << " y " << y << ": " << cal::fmod_near(x, y) << " against "
                      << std::fmod(x, y);
    EXPECT_EQ(wrong, 0) << "y " << y;
  }
  // The sign of a zero result is x's (fmod's): -y gives -0, not +0.
  EXPECT_TRUE(std::signbit(cal::fmod_near(-2 * pi, 2 * pi)));
}

TEST(AngleReduce, AbsRemainderIsStdRemainderBitForBit) {
  for (double y : {pi, 2 * pi, 360.0, 1.0}) {
    int wrong = 0;
    for (double x : cases(y))
      if (!same_bits(cal::abs_remainder(x, y), std::abs(std::remainder(x, y))) && ++wrong < 5)
        ADD_FAILURE() << "x " << x << " y " << y << ": " << cal::abs_remainder(x, y) << " against "
                      << std::abs(std::remainder(x, y));
    EXPECT_EQ(wrong, 0) << "y " << y;
  }
  // By hand: 2.9 pi is 0.9 pi past 2 pi, 0.1 pi short of 3 pi; 1.2 pi is 0.2 pi past pi.
  EXPECT_NEAR(cal::abs_remainder(1.2 * pi, pi), 0.2 * pi, 1e-15);
  EXPECT_NEAR(cal::abs_remainder(-1.7 * pi, pi), 0.3 * pi, 1e-15);
  // Past two periods (the ballbar's angles): 3.2 pi is 0.2 pi past 3 pi, -3.6 pi 0.4 pi short
  // of -4 pi.
  EXPECT_NEAR(cal::abs_remainder(3.2 * pi, pi), 0.2 * pi, 1e-15);
  EXPECT_NEAR(cal::abs_remainder(-3.6 * pi, pi), 0.4 * pi, 1e-15);
}

}  // namespace
