// Tests of the ballbar on a rotary table axis (ballbar5x.hpp). The sensitivities are derived by
// hand below and checked against the code's and against finite differences of the exact
// (HTM) simulation; the fit is checked against the injected truth.
//
// Hand derivation. For a table axis turned by R (about its nominal direction d), a point v of
// the table (relative to the pivot) is displaced by the location errors o (position) and e0
// (orientation) by Delta(v) = (I - R) o + e0 x (R v) - R (e0 x v) (docs/kinematics.md, "First
// order"), and the tool's error relative to the workpiece, in the workpiece frame, is
//   e = -R^T Delta(v) = (I - R^T) o - (R^T e0) x v + e0 x v = (I - R^T) o + ((I - R^T) e0) x v
// (R^T (a x b) = R^T a x R^T b). The bar, fixed in the workpiece frame along the unit u from the
// table ball to the spindle ball v, reads |L u + e| - L = u . e to first order:
//   d reading / d o_j = u . (I - R^T) x_j,   d reading / d e0_j = ((I - R^T) x_j) . (v x u)
// (x_j the unit vector of slot j; um per um, and 1e-3 um per urad per mm of v).
//
// C axis (d = z, c = cos C, s = sin C): (I - R^T) x = (1 - c, s, 0), (I - R^T) y = (-s, 1 - c, 0).
// Table ball at pivot + (r, 0, h):
//   radial     u = x, v = (r + L, 0, h), v x u = (0, h, 0):
//     E_X0C: 1 - c   E_Y0C: -s   E_A0C: 1e-3 h s        E_B0C: 1e-3 h (1 - c)
//   tangential u = z x x = y, v = (r, L, h), v x u = (-h, 0, r):
//     E_X0C: s       E_Y0C: 1 - c   E_A0C: -1e-3 h (1 - c)   E_B0C: 1e-3 h s
//   axial      u = z, v = (r, 0, h + L), v x u = (0, -r, 0):
//     E_X0C: 0       E_Y0C: 0   E_A0C: -1e-3 r s       E_B0C: -1e-3 r (1 - c)
// So a radial (or tangential) test sees E_X0C + h E_B0C and E_Y0C - h E_A0C only: tests at one
// height cannot separate position from orientation; the axial test sees the orientation alone.
//
// A axis (d = x, c = cos A, s = sin A): R^T = Rx(-A) = [1 0 0; 0 c s; 0 -s c],
// (I - R^T) y = (0, 1 - c, s), (I - R^T) z = (0, -s, 1 - c). Table ball at pivot + (x, 0, h):
//   radial     u = z, v = (x, 0, h + L), v x u = (0, -x, 0):
//     E_Y0A: s       E_Z0A: 1 - c   E_B0A: -1e-3 x (1 - c)   E_C0A: 1e-3 x s
//   tangential u = x x z = -y, v = (x, -L, h), v x u = (h, 0, -x):
//     E_Y0A: -(1 - c)   E_Z0A: s   E_B0A: -1e-3 x s        E_C0A: -1e-3 x (1 - c)
//   axial      u = x, v = (x + L, 0, h), v x u = (0, h, 0):
//     E_Y0A: 0       E_Z0A: 0   E_B0A: 1e-3 h (1 - c)     E_C0A: -1e-3 h s
#include "cal/analysis/ballbar5x.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "cal/analysis/error.hpp"

namespace {

using namespace cal::kinematics;
using cal::InputError;

constexpr double kDeg = std::numbers::pi / 180.0;

// The simulated shop's trunnion (tests/data/model/trunnion_truth.json): C pivot (0, 0, -350),
// A pivot (0, 0, -300), a 100 mm tool pointing down.
constexpr std::array<double, 4> kC{25.0, -18.0, 10.0, -6.0};  // E_X0C, E_Y0C, E_A0C, E_B0C
constexpr std::array<double, 4> kA{30.0, -22.0, 8.0, -5.0};   // E_Y0A, E_Z0A, E_B0A, E_C0A

FiveAxisMachine nominal() {
  FiveAxisMachine m;
  m.linear.topology = Topology::fxyz;
  m.linear.tool_offset_mm = {0, 0, -100};
  RotaryAxis c;
  c.letter = RotaryLetter::c;
  c.pivot_mm = {0, 0, -350};
  RotaryAxis a;
  a.letter = RotaryLetter::a;
  a.pivot_mm = {0, 0, -300};
  m.rotary = {c, a};
  return m;
}

FiveAxisMachine truth() {
  return with_location_errors(with_location_errors(nominal(), RotaryLetter::c, kC), RotaryLetter::a,
                              kA);
}

// The ball at (150, 0, -250): C pivot + (r, 0, h) with r = 150, h = 100; A pivot + (x, 0, h)
// with x = 150, h = 50.
constexpr Vec3 kBall{150, 0, -250};
constexpr double kL = 100.0;

std::vector<double> steps(double from, double to, double by) {
  std::vector<double> v;
  for (double a = from; a <= to + 1e-9; a += by) v.push_back(a);
  return v;
}

RotaryBallbarTest test_of(RotaryLetter axis, BarSetup setup, const Vec3& ball = kBall) {
  RotaryBallbarTest t;
  t.name = std::string(to_string(axis)) + "-" + std::string(to_string(setup));
  t.axis = axis;
  t.setup = setup;
  t.table_ball_mm = ball;
  t.length_mm = kL;
  t.angles_deg = axis == RotaryLetter::c ? steps(0, 330, 30) : steps(-90, 90, 15);
  return t;
}

// The hand derivation above, at angle deg.
std::array<double, 4> hand(RotaryLetter axis, BarSetup setup, double deg) {
  const double c = std::cos(deg * kDeg), s = std::sin(deg * kDeg);
  if (axis == RotaryLetter::c) {
    const double r = 150, h = 100;
    switch (setup) {
      case BarSetup::radial:
        return {1 - c, -s, 1e-3 * h * s, 1e-3 * h * (1 - c)};
      case BarSetup::tangential:
        return {s, 1 - c, -1e-3 * h * (1 - c), 1e-3 * h * s};
      case BarSetup::axial:
        return {0, 0, -1e-3 * r * s, -1e-3 * r * (1 - c)};
    }
  }
  const double x = 150, h = 50;
  switch (setup) {
    case BarSetup::radial:
      return {s, 1 - c, -1e-3 * x * (1 - c), 1e-3 * x * s};
    case BarSetup::tangential:
      return {-(1 - c), s, -1e-3 * x * s, -1e-3 * x * (1 - c)};
    case BarSetup::axial:
    default:
      return {0, 0, 1e-3 * h * (1 - c), -1e-3 * h * s};
  }
}

constexpr std::array kSetups{BarSetup::radial, BarSetup::tangential, BarSetup::axial};
constexpr std::array kAxes{RotaryLetter::c, RotaryLetter::a};

TEST(RotaryBallbar, BarDirectionsAndToolBall) {
  const auto m = nominal();
  // C: radial along +X from the C line, tangential +Y, axial +Z.
  EXPECT_EQ(bar_direction(m, test_of(RotaryLetter::c, BarSetup::radial)), (Vec3{1, 0, 0}));
  EXPECT_EQ(bar_direction(m, test_of(RotaryLetter::c, BarSetup::tangential)), (Vec3{0, 1, 0}));
  EXPECT_EQ(bar_direction(m, test_of(RotaryLetter::c, BarSetup::axial)), (Vec3{0, 0, 1}));
  // A: the ball 50 mm above the A line: radial +Z, tangential x cross z = -Y.
  EXPECT_EQ(bar_direction(m, test_of(RotaryLetter::a, BarSetup::radial)), (Vec3{0, 0, 1}));
  EXPECT_EQ(bar_direction(m, test_of(RotaryLetter::a, BarSetup::tangential)), (Vec3{0, -1, 0}));
  EXPECT_EQ(tool_ball_mm(m, test_of(RotaryLetter::c, BarSetup::radial)), (Vec3{250, 0, -250}));
}

TEST(RotaryBallbar, CommandKeepsTheBallOnTheWorkpiece) {
  // On the nominal machine the command at C = 90 deg puts the tool ball where the table turned
  // its place: (250, 0) turned by +90 deg about the C line at (0, 0) is (0, 250); the ball's
  // machine coordinates (tool tip = ball) are those.
  const auto m = nominal();
  auto t = test_of(RotaryLetter::c, BarSetup::radial);
  const Vec3 p = rotary_ballbar_command_mm(m, t, 90.0);
  EXPECT_NEAR(p[0], 0.0, 1e-9);
  EXPECT_NEAR(p[1], 250.0, 1e-9);
  EXPECT_NEAR(p[2], -250.0, 1e-9);
  // A = 90 deg: the radial tool ball is (150, 0, -150), 150 mm above the A pivot (0, 0, -300);
  // turned by +90 deg about X, (y, z) = (0, 150) -> (-150, 0).
  t = test_of(RotaryLetter::a, BarSetup::radial);
  const Vec3 q = rotary_ballbar_command_mm(m, t, 90.0);
  EXPECT_NEAR(q[0], 150.0, 1e-9);
  EXPECT_NEAR(q[1], -150.0, 1e-9);
  EXPECT_NEAR(q[2], -300.0, 1e-9);
  // And the bar reads 0 everywhere on the nominal machine.
  for (double r : rotary_ballbar_readings_um(m, m, t)) EXPECT_NEAR(r, 0.0, 1e-9);
}

TEST(RotaryBallbar, SensitivitiesAreTheHandDerivation) {
  const auto m = nominal();
  for (auto axis : kAxes) {
    for (auto setup : kSetups) {
      const auto t = test_of(axis, setup);
      const auto s = rotary_ballbar_sensitivity(m, t);
      ASSERT_EQ(s.size(), t.angles_deg.size());
      for (std::size_t k = 0; k < s.size(); ++k) {
        const auto want = hand(axis, setup, t.angles_deg[k]);
        for (std::size_t j = 0; j < 4; ++j)
          EXPECT_NEAR(s[k][j], want[j], 1e-12)
              << t.name << " angle " << t.angles_deg[k] << " error " << j;
      }
    }
  }
}

TEST(RotaryBallbar, SensitivitiesAreTheExactModelsFiniteDifferences) {
  // Central differences of the exact (HTM) readings with each error +-1 um or urad alone: the
  // hand derivation to 1e-6 um per unit (the differences cancel the second-order terms).
  const auto m = nominal();
  for (auto axis : kAxes) {
    for (auto setup : kSetups) {
      const auto t = test_of(axis, setup);
      for (std::size_t j = 0; j < 4; ++j) {
        std::array<double, 4> plus{}, minus{};
        plus[j] = 1.0;
        minus[j] = -1.0;
        const auto up = rotary_ballbar_readings_um(with_location_errors(m, axis, plus), m, t);
        const auto down = rotary_ballbar_readings_um(with_location_errors(m, axis, minus), m, t);
        for (std::size_t k = 0; k < t.angles_deg.size(); ++k)
          EXPECT_NEAR((up[k] - down[k]) / 2.0, hand(axis, setup, t.angles_deg[k])[j], 1e-6)
              << t.name << " angle " << t.angles_deg[k] << " error " << j;
      }
    }
  }
}

TEST(RotaryBallbar, TheOtherAxisErrorsDoNotShow) {
  // At A = 0 the A axis turns by nothing about its actual line: a C test reads the C errors
  // only (the readings with A's errors injected equal those without, to 1e-9 um).
  const auto m = nominal();
  const auto t = test_of(RotaryLetter::c, BarSetup::radial);
  const auto only_c = with_location_errors(m, RotaryLetter::c, kC);
  const auto both = rotary_ballbar_readings_um(truth(), m, t);
  const auto c_alone = rotary_ballbar_readings_um(only_c, m, t);
  for (std::size_t k = 0; k < both.size(); ++k) EXPECT_NEAR(both[k], c_alone[k], 1e-9);
  // At C = 180 the radial bar reads 2 (E_X0C + h E_B0C) = 2 (25 - 0.1 * 6) = 48.8 um (first
  // order; the exact model adds |e across the bar|^2 / 2L, 0.007 um here).
  EXPECT_NEAR(both[6], 2 * (25.0 + 0.1 * -6.0), 0.02);
}

std::vector<RotaryBallbarRun> runs_of(const FiveAxisMachine& truth_m, RotaryLetter axis,
                                      std::initializer_list<BarSetup> setups, double noise_um,
                                      unsigned seed, double offset_um = 0.0) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_um);
  std::vector<RotaryBallbarRun> runs;
  for (auto setup : setups) {
    RotaryBallbarRun run{test_of(axis, setup), {}};
    run.reading_um = rotary_ballbar_readings_um(truth_m, nominal(), run.test);
    for (double& r : run.reading_um) r += offset_um + (noise_um > 0 ? noise(rng) : 0.0);
    offset_um = -offset_um;  // the next set-up's bar zero differs
    runs.push_back(std::move(run));
  }
  return runs;
}

TEST(RotaryBallbar, NoiseFreeRecovery) {
  // The exact readings of the trunnion (with a bar zero of +-3 um per set-up) give back the
  // injected errors to 1e-6 um / urad and the offsets to 1e-6 um.
  for (auto axis : kAxes) {
    const auto runs = runs_of(truth(), axis, {BarSetup::radial, BarSetup::axial}, 0.0, 1, 3.0);
    const auto fit = fit_rotary_ballbar(nominal(), axis, runs);
    const auto& want = axis == RotaryLetter::c ? kC : kA;
    for (std::size_t j = 0; j < 4; ++j) EXPECT_NEAR(fit.value[j], want[j], 1e-6) << j;
    EXPECT_NEAR(fit.offset_um[0], 3.0, 1e-6);
    EXPECT_NEAR(fit.offset_um[1], -3.0, 1e-6);
    EXPECT_LT(fit.rms_um, 1e-6);
    EXPECT_EQ(fit.dof, static_cast<int>(2 * runs[0].reading_um.size()) - 6);
  }
}

constexpr std::array<double, 4> kUc{0.198, 0.198, 1.361, 1.361}, kUa{0.592, 1.212, 8.002, 3.780};

TEST(RotaryBallbar, RecoveryWithNoiseWithinFourU) {
  // Gaussian noise of 0.5 um per reading, the three set-ups, seeds 1..4: every error within 4 u
  // of the injected value; sigma from the residuals within 40 % of 0.5 um; u below 1.5 times its
  // value with sigma = 0.5 um given (C: 0.198 um, 1.361 urad; A: E_Y0A 0.592, E_Z0A 1.212 um,
  // E_B0A 8.002, E_C0A 3.780 urad: half a turn of A only, the ball 50 mm above its line).
  for (auto axis : kAxes) {
    for (unsigned seed = 1; seed <= 4; ++seed) {
      const auto runs = runs_of(
          truth(), axis, {BarSetup::radial, BarSetup::tangential, BarSetup::axial}, 0.5, seed, 2.0);
      const auto fit = fit_rotary_ballbar(nominal(), axis, runs);
      const auto& want = axis == RotaryLetter::c ? kC : kA;
      const bool c = axis == RotaryLetter::c;
      for (std::size_t j = 0; j < 4; ++j) {
        EXPECT_LT(std::abs(fit.value[j] - want[j]), 4 * fit.uncertainty[j])
            << to_string(axis) << " seed " << seed << " error " << j;
        EXPECT_LT(fit.uncertainty[j], 1.5 * (c ? kUc : kUa)[j]) << j;
      }
      EXPECT_NEAR(fit.sigma_um, 0.5, 0.2);
    }
  }
}

TEST(RotaryBallbar, GivenReadingUncertaintyScalesU) {
  // With the reading's u given, the uncertainties are sigma sqrt(diag (J^T J)^-1): doubling it
  // doubles them.
  const auto runs = runs_of(truth(), RotaryLetter::c, {BarSetup::radial, BarSetup::axial}, 0.0, 1);
  const auto one = fit_rotary_ballbar(nominal(), RotaryLetter::c, runs, 0.5);
  const auto two = fit_rotary_ballbar(nominal(), RotaryLetter::c, runs, 1.0);
  for (std::size_t j = 0; j < 4; ++j)
    EXPECT_NEAR(two.uncertainty[j], 2 * one.uncertainty[j], 1e-12);
  // The axial test's orientation by hand: 12 angles, readings -r(B(1-c) + A s) + offset: the
  // sin column has sum s^2 = 6, so u(E_A0C) = 0.5 / (0.15 sqrt 6) = 1.361 urad (the radial
  // test adds nothing to it: its A and B enter with X, Y which it alone determines).
  EXPECT_NEAR(one.uncertainty[2], 0.5 / (0.15 * std::sqrt(6.0)), 1e-9);
  // The three set-ups with sigma given: the design's u (the bounds of the noise test above).
  for (auto axis : kAxes) {
    const auto three =
        runs_of(truth(), axis, {BarSetup::radial, BarSetup::tangential, BarSetup::axial}, 0.0, 1);
    const auto f = fit_rotary_ballbar(nominal(), axis, three, 0.5);
    for (std::size_t j = 0; j < 4; ++j)
      EXPECT_NEAR(f.uncertainty[j], (axis == RotaryLetter::c ? kUc : kUa)[j], 1e-3) << j;
  }
}

TEST(RotaryBallbar, Refusals) {
  const auto m = nominal();
  // A radial test alone cannot separate E_X0C from E_B0C.
  auto runs = runs_of(truth(), RotaryLetter::c, {BarSetup::radial}, 0.0, 1);
  EXPECT_THROW(fit_rotary_ballbar(m, RotaryLetter::c, runs), InputError);
  // Radial and tangential at one height: still not.
  runs = runs_of(truth(), RotaryLetter::c, {BarSetup::radial, BarSetup::tangential}, 0.0, 1);
  EXPECT_THROW(fit_rotary_ballbar(m, RotaryLetter::c, runs), InputError);
  // Radial at two heights: separable.
  auto high = runs_of(truth(), RotaryLetter::c, {BarSetup::radial}, 0.0, 1);
  RotaryBallbarRun second{test_of(RotaryLetter::c, BarSetup::radial, {150, 0, -150}), {}};
  second.reading_um = rotary_ballbar_readings_um(truth(), m, second.test);
  high.push_back(second);
  const auto fit = fit_rotary_ballbar(m, RotaryLetter::c, high);
  for (std::size_t j = 0; j < 4; ++j) EXPECT_NEAR(fit.value[j], kC[j], 1e-6);
  // A test of another axis, readings that do not match the angles, a NaN reading.
  runs = runs_of(truth(), RotaryLetter::c, {BarSetup::radial, BarSetup::axial}, 0.0, 1);
  EXPECT_THROW(fit_rotary_ballbar(m, RotaryLetter::a, runs), InputError);
  auto short_run = runs;
  short_run[0].reading_um.pop_back();
  EXPECT_THROW(fit_rotary_ballbar(m, RotaryLetter::c, short_run), InputError);
  auto nan_run = runs;
  nan_run[0].reading_um[1] = std::nan("");
  EXPECT_THROW(fit_rotary_ballbar(m, RotaryLetter::c, nan_run), InputError);
  EXPECT_THROW(fit_rotary_ballbar(m, RotaryLetter::c, runs, -1.0), InputError);
  // A radial set-up with the ball on the C line; a zero length; a spindle axis; no such axis.
  EXPECT_THROW(bar_direction(m, test_of(RotaryLetter::c, BarSetup::radial, {0, 0.5, -250})),
               InputError);
  auto zero = test_of(RotaryLetter::c, BarSetup::axial);
  zero.length_mm = 0;
  EXPECT_THROW(bar_direction(m, zero), InputError);
  auto head = m;
  head.rotary = {m.rotary[0]};
  head.rotary[0].side = Side::spindle;
  EXPECT_THROW(bar_direction(head, test_of(RotaryLetter::c, BarSetup::axial)), InputError);
  EXPECT_THROW(bar_direction(head, test_of(RotaryLetter::a, BarSetup::axial)), InputError);
  EXPECT_THROW(bar_setup_from_string("diagonal"), InputError);
}

}  // namespace
