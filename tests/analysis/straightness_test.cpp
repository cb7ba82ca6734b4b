// Straightness reference lines against hand calculations.
#include "cal/analysis/straightness.hpp"

#include <gtest/gtest.h>

#include <random>

#include "cal/analysis/error.hpp"

namespace {

using namespace cal::straightness;

// Points (0, 0), (100, 3), (200, 1), (300, 4), (400, 3) (mm, um). By hand:
// LSQ: mean x 200, mean y 2.2; Sxy = 440 - 80 + 0 + 180 + 160 = 700, Sxx = 100000: slope
// 0.007 um/mm = 7 um/m, intercept 2.2 - 1.4 = 0.8; residuals -0.8, 1.5, -1.2, 1.1, -0.6:
// straightness 2.7 um.
// End point: slope 3 / 400 = 7.5 um/m through (0, 0); residuals 0, 2.25, -0.5, 1.75, 0:
// straightness 2.75 um.
// Minimum zone: hull edges' slopes 0.005, 0.01 (lower), 0.03, 0.005, -0.01 (upper) um/mm;
// widths 2.5, 3, 9, 2.5, 7: the zone is 2.5 um at 5 um/m (less than both others).
const std::vector<double> x{0, 100, 200, 300, 400};
const std::vector<double> y{0, 3, 1, 4, 3};

TEST(Straightness, LeastSquaresByHand) {
  const auto r = evaluate(x, y, Reference::least_squares);
  EXPECT_NEAR(r.slope_um_per_m, 7.0, 1e-12);
  EXPECT_NEAR(r.intercept_um, 0.8, 1e-12);
  EXPECT_NEAR(r.straightness_um, 2.7, 1e-12);
  EXPECT_NEAR(r.residual_um[1], 1.5, 1e-12);
}

TEST(Straightness, EndPointByHand) {
  const auto r = evaluate(x, y, Reference::end_point);
  EXPECT_NEAR(r.slope_um_per_m, 7.5, 1e-12);
  EXPECT_NEAR(r.straightness_um, 2.75, 1e-12);
}

TEST(Straightness, MinimumZoneByHand) {
  const auto r = evaluate(x, y, Reference::minimum_zone);
  EXPECT_NEAR(r.slope_um_per_m, 5.0, 1e-12);
  EXPECT_NEAR(r.straightness_um, 2.5, 1e-12);
}

TEST(Straightness, MinimumZoneIsNeverWiderThanTheOthers) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0.0, 2.0);
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<double> px, py;
    for (int i = 0; i < 3 + trial % 40; ++i)
      px.push_back(i * 25.0), py.push_back(n(rng) + 0.01 * i * i);
    const double mz = evaluate(px, py, Reference::minimum_zone).straightness_um;
    EXPECT_LE(mz, evaluate(px, py, Reference::least_squares).straightness_um + 1e-12);
    EXPECT_LE(mz, evaluate(px, py, Reference::end_point).straightness_um + 1e-12);
  }
}

TEST(Straightness, BowAndTiltAreSeparated) {
  // y = 5 + 0.02 x + bow, bow = 3 (1 - u^2), u = x / 500 - 1 over 0..1000 mm: symmetric, so
  // the LSQ slope is the tilt, 20 um/m; the bow's range is 3 um (u = 0 to u = +-1).
  std::vector<double> px, py;
  for (int i = 0; i <= 100; ++i) {
    const double xx = 10.0 * i, u = xx / 500 - 1;
    px.push_back(xx);
    py.push_back(5 + 0.02 * xx + 3 * (1 - u * u));
  }
  const auto r = evaluate(px, py, Reference::end_point);
  EXPECT_NEAR(r.slope_um_per_m, 20.0, 1e-9);  // both ends are on the tilt line
  EXPECT_NEAR(r.straightness_um, 3.0, 1e-9);
  EXPECT_NEAR(evaluate(px, py, Reference::least_squares).slope_um_per_m, 20.0, 1e-9);
}

TEST(Straightness, RefusesBadInput) {
  const std::vector<double> one{1.0}, two{1.0, 2.0}, same{3.0, 3.0};
  EXPECT_THROW(evaluate(one, one, Reference::least_squares), cal::InputError);
  EXPECT_THROW(evaluate(two, one, Reference::least_squares), cal::InputError);
  EXPECT_THROW(evaluate(same, two, Reference::minimum_zone), cal::InputError);
  EXPECT_THROW(reference_from_string("best"), cal::InputError);
}

}  // namespace
