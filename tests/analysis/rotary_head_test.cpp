// Sphere probing of a head (spindle-side) rotary axis: fit_head_axis_line and the simulated probe
// with a head axis turned. The machine: a C table with a B head (FXYZ: the linear axes carry the
// head), in home coordinates (mm):
//   C table: pivot (0, 0, -400)
//   B head:  pivot c = (0, 0, 150) (150 mm above the spindle gauge point), the probe tip at
//            t = (0, 0, -100): L = 250 mm below the B pivot.
// Injected (SIMULATED truth): B: E_X0B = 20, E_Z0B = -15 um; E_A0B = 12, E_C0B = -7 urad.
//   C: E_X0C = 15, E_Y0C = -10 um; E_A0C = 6, E_B0C = -4 urad.
// The sphere S = (120, 40, -300) on the C table.
//
// What a control reports (written out here, not taken from the code): the linear position p at
// which the ACTUAL probe tip is on S, and where the control's kinematics puts the tip at p. The
// actual tip at p, B = theta: p + the tip t turned by theta about the actual B line (through
// c + o, direction n = Rz(E_C0B) Rx(E_A0B) y = (-cos a sin g, cos a cos g, sin a), a = E_A0B,
// g = E_C0B); the control's (nominal) tip: p + t turned by theta about the nominal line
// (through c, along y). So
//   reported(theta) = S - turn(t, c + o, n, theta) + turn(t, c, y, theta),
// S at theta = 0, and to first order S - Delta with (docs/kinematics.md, the B head)
//   Delta = (E_X0B (1 - cos B) - E_Z0B sin B, -L (E_A0B (1 - cos B) + E_C0B sin B),
//            E_Z0B (1 - cos B) + E_X0B sin B).
// The fit's parameters are S and the four errors; with the angles symmetric about 0, least
// squares on that linear form decouples (sums over the N angles: sum sin = 0, sum sin (1 - cos) =
// 0), which gives the uncertainties by hand:
//   u(E_X0B) = u(E_Z0B) = sigma / sqrt(sum sin^2 + sum (cos - mean cos)^2)
//   u(E_C0B) = sigma / (L sqrt(sum sin^2)),  u(E_A0B) = sigma / (L sqrt(sum (cos - mean cos)^2))
// (x and z carry the positions, each with its own coordinate of S; y carries the tilts with S_y).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "cal/analysis/error.hpp"
#include "cal/analysis/rotary.hpp"
#include "rotary_fixtures.hpp"

namespace {

using namespace cal::kinematics;
using cal::InputError;
using cal::test::turn;

constexpr double kX0B = 20, kZ0B = -15, kA0B = 12, kC0B = -7;
constexpr Vec3 kBPivot{0, 0, 150}, kTool{0, 0, -100}, kSphere{120, 40, -300};
constexpr double kArmMm = 250;  // the tip below the B pivot

RotaryAxis axis(RotaryLetter l, Side side, const Vec3& pivot, const Vec3& pos_um,
                const Vec3& orient_urad) {
  RotaryAxis r = cal::test::table_axis(l, pivot, pos_um, orient_urad);
  r.side = side;
  return r;
}

// The truth (k = 1) or the nominal machine (k = 0).
FiveAxisMachine table_c_head_b(double k = 1.0) {
  FiveAxisMachine m;
  m.linear.topology = Topology::fxyz;
  m.linear.tool_offset_mm = kTool;
  m.rotary.push_back(
      axis(RotaryLetter::c, Side::table, {0, 0, -400}, {k * 15, k * -10, 0}, {k * 6, k * -4, 0}));
  m.rotary.push_back(axis(RotaryLetter::b, Side::spindle, kBPivot, {k * kX0B, 0, k * kZ0B},
                          {k * kA0B, 0, k * kC0B}));
  return m;
}

Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 plus(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }

void expect_near(const Vec3& got, const Vec3& want, double tol, const std::string& what) {
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(got[i], want[i], tol) << what << " [" << i << "]";
}

// The closed form above.
Vec3 reported_by_hand(double b_deg) {
  const double a = kA0B * 1e-6, g = kC0B * 1e-6;
  const Vec3 n{-std::cos(a) * std::sin(g), std::cos(a) * std::cos(g), std::sin(a)};
  const Vec3 actual_pivot = plus(kBPivot, {kX0B * 1e-3, 0, kZ0B * 1e-3});
  const Vec3 actual = turn(kTool, actual_pivot, n, b_deg);
  const Vec3 control = turn(kTool, kBPivot, {0, 1, 0}, b_deg);
  return plus(sub(kSphere, actual), control);
}

std::vector<double> b_angles() {  // -90 .. 90 deg in 15 deg steps: 13 angles
  std::vector<double> v;
  for (int k = -6; k <= 6; ++k) v.push_back(15.0 * k);
  return v;
}

std::vector<ProbedCentre> probe_b(const FiveAxisMachine& m, double noise_um, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_um * 1e-3);
  std::vector<ProbedCentre> out;
  for (double deg : b_angles()) {
    const std::vector angles{0.0, deg};
    Vec3 c = probed_centre_mm(m, kSphere, angles);
    for (double& x : c) x += noise_um > 0 ? noise(rng) : 0.0;
    out.push_back({deg, c});
  }
  return out;
}

TEST(HeadSphereProbing, SimulatedCentreIsWhereTheControlPutsTheTurnedTip) {
  const FiveAxisMachine m = table_c_head_b();
  for (double deg : {-90.0, -30.0, 0.0, 45.0, 90.0}) {
    const std::vector angles{0.0, deg};
    expect_near(probed_centre_mm(m, kSphere, angles), reported_by_hand(deg), 1e-9,
                "B = " + std::to_string(deg));
    // A control that holds the actual lines reports the sphere itself.
    expect_near(probed_centre_mm(m, m, kSphere, angles), kSphere, 1e-9,
                "control = truth, B = " + std::to_string(deg));
  }
  // At B = 90 the first-order form: Delta = (E_X0B - E_Z0B, -L (E_A0B + E_C0B), E_Z0B + E_X0B)
  // = (35, -250 mm * 5 urad = -1.25, 5) um, so reported = S - Delta (second order: below
  // 1e-6 mm).
  const std::vector at90{0.0, 90.0};
  expect_near(probed_centre_mm(m, kSphere, at90), sub(kSphere, {35e-3, -1.25e-3, 5e-3}), 1e-6,
              "first order at 90");
  // Chains that differ are refused (a control reports for its own chain).
  FiveAxisMachine other = m;
  other.rotary[1].side = Side::table;
  EXPECT_THROW(probed_centre_mm(m, other, kSphere, at90), InputError);
}

TEST(HeadSphereProbing, RecoversTheLocationErrorsWithoutNoise) {
  const FiveAxisMachine truth = table_c_head_b(), nominal = table_c_head_b(0.0);
  const auto fit = fit_head_axis_line(nominal, 1, probe_b(truth, 0.0, 1));
  expect_near(fit.line.position_um, {kX0B, 0, kZ0B}, 1e-4, "position");
  expect_near(fit.line.orientation_urad, {kA0B, 0, kC0B}, 1e-3, "orientation");
  expect_near(fit.sphere_mm, kSphere, 1e-7, "sphere");
  EXPECT_LT(fit.line.rms_um, 1e-5);
  EXPECT_EQ(fit.line.dof, 3 * 13 - 7);
  // The tip relative to the actual line: w = t - c - o = (-0.020, 0, -249.985) mm; across the
  // B direction n (y tilted by 12 and -7 urad: w . n = -249.985 sin(12e-6) ~ -0.003 mm) the radius
  // is |w| to 1e-9 of it.
  EXPECT_NEAR(fit.line.radius_mm, std::hypot(0.020, 249.985), 1e-6);
  EXPECT_NEAR(fit.line.plane_offset_mm, -249.985 * std::sin(12e-6), 1e-6);
  for (double r : fit.line.radial_um) EXPECT_NEAR(r, 0.0, 1e-5);
}

TEST(HeadSphereProbing, RecoversTheLocationErrorsWithinTheirUncertaintyUnderNoise) {
  // Gaussian noise sigma = 1 um per coordinate, 13 angles over -90 .. 90 deg (seeded). The
  // uncertainties by hand (head comment): sum sin^2 = 7 exactly (sin^2 of 0, 15, ..., 90 deg sum
  // to 3.5 on each side); the cosines' spread from their sum. About 0.342 um (positions),
  // 3.2 urad (E_A0B) and 1.51 urad (E_C0B).
  const std::vector<double> angles = b_angles();
  double ss = 0, sc = 0, scc = 0;
  for (double a : angles) {
    ss += std::pow(std::sin(a * std::numbers::pi / 180), 2);
    sc += std::cos(a * std::numbers::pi / 180);
    scc += std::pow(std::cos(a * std::numbers::pi / 180), 2);
  }
  const double n = static_cast<double>(angles.size()), sigma = 1.0;
  const double spread_c = scc - sc * sc / n;
  ASSERT_NEAR(ss, 7.0, 1e-12);
  const double u_pos = sigma / std::sqrt(ss + spread_c);
  const double u_a = sigma / (kArmMm * std::sqrt(spread_c)) * 1e3;  // um / mm = mrad -> urad
  const double u_c = sigma / (kArmMm * std::sqrt(ss)) * 1e3;
  const FiveAxisMachine truth = table_c_head_b(), nominal = table_c_head_b(0.0);
  for (unsigned seed : {1u, 2u, 3u, 4u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const auto centres = probe_b(truth, sigma, seed);
    const auto given = fit_head_axis_line(nominal, 1, centres, sigma).line;
    EXPECT_NEAR(given.position_u_um[0], u_pos, 0.02 * u_pos);
    EXPECT_NEAR(given.position_u_um[2], u_pos, 0.02 * u_pos);
    EXPECT_NEAR(given.orientation_u_urad[0], u_a, 0.02 * u_a);
    EXPECT_NEAR(given.orientation_u_urad[2], u_c, 0.02 * u_c);
    EXPECT_NEAR(given.position_um[0], kX0B, 4 * u_pos);
    EXPECT_NEAR(given.position_um[2], kZ0B, 4 * u_pos);
    EXPECT_NEAR(given.orientation_urad[0], kA0B, 4 * u_a);
    EXPECT_NEAR(given.orientation_urad[2], kC0B, 4 * u_c);
    const auto est = fit_head_axis_line(nominal, 1, centres).line;
    EXPECT_EQ(est.dof, 32);
    EXPECT_NEAR(est.sigma_um, sigma, 0.4 * sigma);
    EXPECT_NEAR(est.position_um[0], given.position_um[0], 1e-9);  // same fit, other sigma
  }
}

// The table C of the same machine, probed with the head at 0, is the table fit's as before (the
// head's errors move nothing at B = 0).
TEST(HeadSphereProbing, TheTableAxisOfTheSameMachineStillFits) {
  const FiveAxisMachine truth = table_c_head_b();
  std::vector<ProbedCentre> c;
  for (int k = 0; k < 8; ++k) {
    const std::vector angles{45.0 * k, 0.0};
    c.push_back({45.0 * k, probed_centre_mm(truth, kSphere, angles)});
  }
  const auto fit = fit_axis_line(RotaryLetter::c, {0, 0, -400}, c);
  expect_near(fit.position_um, {15, -10, 0}, 1e-4, "C position");
  expect_near(fit.orientation_urad, {6, -4, 0}, 1e-3, "C orientation");
}

// Linear errors on a head machine: X positioning 3 um + 0.02 um/mm (the head swings the X axis
// over +-250 mm, so about +-5 um along the sweep). In the fitted machine they are not read as
// the head's (recovered to the fit's rounding); fitted as if the linear axes were perfect, they
// bias the positions by micrometres.
TEST(HeadSphereProbing, LinearAxisErrorsAreNotReadAsTheHeads) {
  FiveAxisMachine truth = table_c_head_b(), nominal = table_c_head_b(0.0);
  truth.linear.axes[X].ex_um = ErrorFunction::polynomial({3, 0.02});
  nominal.linear.axes[X].ex_um = truth.linear.axes[X].ex_um;  // the measured linear axes
  const auto centres = probe_b(truth, 0.0, 1);
  const auto with = fit_head_axis_line(nominal, 1, centres).line;
  expect_near(with.position_um, {kX0B, 0, kZ0B}, 1e-4, "position, linear errors in the model");
  expect_near(with.orientation_urad, {kA0B, 0, kC0B}, 1e-3, "orientation");
  const auto without = fit_head_axis_line(nominal, 1, centres, 0.0, false).line;
  EXPECT_GT(std::abs(without.position_um[0] - kX0B) + std::abs(without.position_um[2] - kZ0B), 1.0);
}

TEST(HeadSphereProbing, RefusesWhatItCannotFit) {
  const FiveAxisMachine truth = table_c_head_b(), nominal = table_c_head_b(0.0);
  const auto centres = probe_b(truth, 0.0, 1);
  // Index 0 is the table C.
  EXPECT_THROW(fit_head_axis_line(nominal, 0, centres), InputError);
  EXPECT_THROW(fit_head_axis_line(nominal, 2, centres), InputError);
  // Two distinct angles.
  const std::vector two{centres[0], centres[6], centres[0]};
  EXPECT_THROW(fit_head_axis_line(nominal, 1, two), InputError);
  std::vector<ProbedCentre> nan = centres;
  nan[4].centre_mm[0] = std::nan("");
  EXPECT_THROW(fit_head_axis_line(nominal, 1, nan), InputError);
  EXPECT_THROW(fit_head_axis_line(nominal, 1, centres, -1.0), InputError);
  // The linear axes' raw positions (the tip's circle of 250 mm) instead of the control's tip.
  std::vector<ProbedCentre> raw = centres;
  for (auto& c : raw) {
    const Vec3 turned = turn(kTool, kBPivot, {0, 1, 0}, c.angle_deg);
    c.centre_mm = plus(sub(c.centre_mm, turned), kTool);
  }
  try {
    fit_head_axis_line(nominal, 1, raw);
    ADD_FAILURE() << "raw positions accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("raw positions"), std::string::npos) << e.what();
  }
  // A C head with the probe tip on its line: a position error o and a tilt e at the tip's
  // distance h along the line move the tip alike ((I - R)(o + e x h z)), so they are refused.
  FiveAxisMachine c_head;
  c_head.linear.tool_offset_mm = kTool;
  c_head.rotary.push_back(axis(RotaryLetter::c, Side::spindle, kBPivot, {10, 5, 0}, {8, 3, 0}));
  std::vector<ProbedCentre> on_line;
  for (int k = 0; k < 8; ++k) {
    const std::vector angles{45.0 * k};
    on_line.push_back({45.0 * k, probed_centre_mm(c_head, kSphere, angles)});
  }
  try {
    fit_head_axis_line(nominal_kinematics(c_head), 0, on_line);
    ADD_FAILURE() << "a tip on the axis line accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("position from its orientation"), std::string::npos)
        << e.what();
  }
  // The same head with the tip 40 mm off the line (a cranked probe): fitted.
  c_head.linear.tool_offset_mm = {40, 0, -100};
  on_line.clear();
  for (int k = 0; k < 8; ++k) {
    const std::vector angles{45.0 * k};
    on_line.push_back({45.0 * k, probed_centre_mm(c_head, kSphere, angles)});
  }
  const auto off = fit_head_axis_line(nominal_kinematics(c_head), 0, on_line).line;
  expect_near(off.position_um, {10, 5, 0}, 1e-4, "C head, tip off the line");
  expect_near(off.orientation_urad, {8, 3, 0}, 1e-3, "C head, tip off the line");
}

}  // namespace
