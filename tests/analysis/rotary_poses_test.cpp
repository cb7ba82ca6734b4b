// Several rotary axes' location errors fitted together (rotary_fit.hpp): a table-table A/C
// trunnion probed at poses that turn C and A at once, and a C table with a B head turned
// together. Every expected value is the injected truth or written out here.
//
// The trunnion (the simulated shop's, tests/data/model/trunnion_truth.json), home coordinates:
//   C (carries the workpiece): pivot (0, 0, -350); E_X0C = 25, E_Y0C = -18 um; E_A0C = 10,
//     E_B0C = -6 urad
//   A (carries C):             pivot (0, 0, -300); E_Y0A = 30, E_Z0A = -22 um; E_B0A = 8,
//     E_C0A = -5 urad
//   tool (0, 0, -100); the sphere S = (150, 100, -250) on the C table.
// The program: C at 0, 60, ..., 300 deg times A at -60, 0, 60 deg (18 poses, both axes turned
// in 12 of them).
//
// The offset between the lines (with every axis at 0): the C line through p_C = (E_X0C, E_Y0C,
// -350) along n_C = Ry(E_B0C) Rx(E_A0C) z = (cos a sin b, -sin a, cos a cos b); the A line
// through p_A = (0, E_Y0A, -300 + E_Z0A) along n_A = Rz(E_C0A) Ry(E_B0A) x = (cos g cos e,
// sin g cos e, -sin e) (a = E_A0C, b = E_B0C, e = E_B0A, g = E_C0A); the signed length of the
// common perpendicular (p_A - p_C) . (n_C x n_A) / |n_C x n_A|. To first order n_C x n_A = y and
// the C line at z = -300 is at y = E_Y0C - 50 mm E_A0C = -18.5 um, so about 30 + 18.5 = 48.5 um:
// the LinuxCNC trunnion's y-offset less its nominal 0.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "cal/analysis/error.hpp"
#include "cal/analysis/rotary_fit.hpp"
#include "rotary_fixtures.hpp"

namespace {

using namespace cal::kinematics;
using cal::InputError;

constexpr double kX0C = 25, kY0C = -18, kA0C = 10, kB0C = -6;
constexpr double kY0A = 30, kZ0A = -22, kB0A = 8, kC0A = -5;
constexpr Vec3 kSphere{150, 100, -250};

FiveAxisMachine trunnion(double k = 1.0) {
  FiveAxisMachine m;
  m.linear.topology = Topology::fxyz;
  m.linear.tool_offset_mm = {0, 0, -100};
  m.rotary.push_back(cal::test::table_axis(RotaryLetter::c, {0, 0, -350}, {k * kX0C, k * kY0C, 0},
                                           {k * kA0C, k * kB0C, 0}));
  m.rotary.push_back(cal::test::table_axis(RotaryLetter::a, {0, 0, -300}, {0, k * kY0A, k * kZ0A},
                                           {0, k * kB0A, k * kC0A}));
  return m;
}

std::vector<ProbedPose> probe(const FiveAxisMachine& m, const std::vector<double>& first,
                              const std::vector<double>& second, double noise_um, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_um * 1e-3);
  std::vector<ProbedPose> out;
  for (double a : first)
    for (double b : second) {
      const std::vector angles{a, b};
      Vec3 c = probed_centre_mm(m, kSphere, angles);
      for (double& x : c) x += noise_um > 0 ? noise(rng) : 0.0;
      out.push_back({angles, c});
    }
  return out;
}

const std::vector<double> kC{0, 60, 120, 180, 240, 300};
const std::vector<double> kA{-60, 0, 60};
const std::vector<std::size_t> kBoth{0, 1};

double offset_by_hand() {
  const double a = kA0C * 1e-6, b = kB0C * 1e-6, e = kB0A * 1e-6, g = kC0A * 1e-6;
  const Vec3 nc{std::cos(a) * std::sin(b), -std::sin(a), std::cos(a) * std::cos(b)};
  const Vec3 na{std::cos(g) * std::cos(e), std::sin(g) * std::cos(e), -std::sin(e)};
  const Vec3 n{nc[1] * na[2] - nc[2] * na[1], nc[2] * na[0] - nc[0] * na[2],
               nc[0] * na[1] - nc[1] * na[0]};
  const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  const Vec3 d{0 - kX0C * 1e-3, kY0A * 1e-3 - kY0C * 1e-3, (-300 + kZ0A * 1e-3) - (-350)};
  return (d[0] * n[0] + d[1] * n[1] + d[2] * n[2]) / len;
}

TEST(RotaryPoses, TrunnionBothAxesTogetherWithoutNoise) {
  const auto poses = probe(trunnion(), kC, kA, 0.0, 1);
  const auto fit = fit_location_errors(trunnion(0.0), kBoth, poses);
  ASSERT_EQ(fit.position_um.size(), 2u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(fit.position_um[0][i], (Vec3{kX0C, kY0C, 0})[i], 1e-4) << i;
    EXPECT_NEAR(fit.orientation_urad[0][i], (Vec3{kA0C, kB0C, 0})[i], 1e-3) << i;
    EXPECT_NEAR(fit.position_um[1][i], (Vec3{0, kY0A, kZ0A})[i], 1e-4) << i;
    EXPECT_NEAR(fit.orientation_urad[1][i], (Vec3{0, kB0A, kC0A})[i], 1e-3) << i;
    EXPECT_NEAR(fit.sphere_mm[i], kSphere[i], 1e-7) << i;
  }
  EXPECT_EQ(fit.dof, 3 * 18 - 11);
  EXPECT_LT(fit.rms_um, 1e-5);
  EXPECT_GT(fit.separability, 1e-2);  // well posed (the refusal threshold is 1e-4)
  const double want = offset_by_hand();
  EXPECT_NEAR(want, 48.5e-3, 0.1e-3);  // the first-order reading of the head comment
  EXPECT_NEAR(line_offset(trunnion(0.0), fit, 0, 1).distance_mm, want, 1e-7);
}

// Gaussian noise of 1 um per coordinate, seeds 1-8. Accepted: every error and the offset within
// 4 u of the truth; and u calibrated against the truth: over the 8 seeds, the 8 errors' and the
// offset's deviations from the truth in units of their u (72 values) have an RMS within 0.7 ..
// 1.3 (1 expected; the RMS of 72 unit normals scatters by about 1 / sqrt(144) = 8 %).
TEST(RotaryPoses, TrunnionBothAxesWithinTheirUncertaintyUnderNoise) {
  const Vec3 truth_pos[2] = {{kX0C, kY0C, 0}, {0, kY0A, kZ0A}};
  const Vec3 truth_ori[2] = {{kA0C, kB0C, 0}, {0, kB0A, kC0A}};
  const double offset = offset_by_hand();
  double sum_z2 = 0, sum_sigma = 0;
  int n = 0;
  for (unsigned seed = 1; seed <= 8; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const auto fit =
        fit_location_errors(trunnion(0.0), kBoth, probe(trunnion(), kC, kA, 1.0, seed));
    sum_sigma += fit.sigma_um;
    const auto check = [&](double got, double want, double u, const char* what) {
      EXPECT_NEAR(got, want, 4 * u) << what;
      sum_z2 += (got - want) * (got - want) / (u * u);
      ++n;
    };
    for (std::size_t a = 0; a < 2; ++a)
      for (std::size_t i = 0; i < 3; ++i) {
        if (fit.position_u_um[a][i] > 0)  // the slot along the axis has none
          check(fit.position_um[a][i], truth_pos[a][i], fit.position_u_um[a][i], "position");
        if (fit.orientation_u_urad[a][i] > 0)
          check(fit.orientation_urad[a][i], truth_ori[a][i], fit.orientation_u_urad[a][i],
                "orientation");
      }
    const auto off = line_offset(trunnion(0.0), fit, 0, 1);
    check(off.distance_mm * 1e3, offset * 1e3, off.u_um, "offset");
  }
  ASSERT_EQ(n, 72);
  // The mean sigma from the residuals within 15 % of the injected 1 um (43 degrees of freedom:
  // one estimate scatters by about 1 / sqrt(86) = 11 %, the mean of 8 by 4 %).
  EXPECT_NEAR(sum_sigma / 8, 1.0, 0.15);
  const double rms = std::sqrt(sum_z2 / n);
  EXPECT_GT(rms, 0.7);
  EXPECT_LT(rms, 1.3);
}

// A C table and a B head (rotary_head_test.cpp's machine) turned together: C at 0, 90, 180, 270
// times B at -60, 0, 60. Both axes' errors come back.
TEST(RotaryPoses, TableAndHeadTogether) {
  const auto machine = [](double k) {
    FiveAxisMachine m;
    m.linear.topology = Topology::fxyz;
    m.linear.tool_offset_mm = {0, 0, -100};
    m.rotary.push_back(cal::test::table_axis(RotaryLetter::c, {0, 0, -400}, {k * 15, k * -10, 0},
                                             {k * 6, k * -4, 0}));
    RotaryAxis b = cal::test::table_axis(RotaryLetter::b, {0, 0, 150}, {k * 20, 0, k * -15},
                                         {k * 12, 0, k * -7});
    b.side = Side::spindle;
    m.rotary.push_back(b);
    return m;
  };
  const auto poses = probe(machine(1), {0, 90, 180, 270}, {-60, 0, 60}, 0.0, 1);
  const auto fit = fit_location_errors(machine(0), kBoth, poses);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(fit.position_um[0][i], (Vec3{15, -10, 0})[i], 1e-4) << i;
    EXPECT_NEAR(fit.orientation_urad[0][i], (Vec3{6, -4, 0})[i], 1e-3) << i;
    EXPECT_NEAR(fit.position_um[1][i], (Vec3{20, 0, -15})[i], 1e-4) << i;
    EXPECT_NEAR(fit.orientation_urad[1][i], (Vec3{12, 0, -7})[i], 1e-3) << i;
  }
}

TEST(RotaryPoses, RefusesWhatItCannotFit) {
  const FiveAxisMachine nominal = trunnion(0.0);
  // A never turns: its errors move nothing, the fit cannot see them.
  const auto c_only = probe(trunnion(), kC, {0.0}, 0.0, 1);
  try {
    fit_location_errors(nominal, kBoth, c_only);
    ADD_FAILURE() << "A's errors fitted from poses at A = 0";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("do not see a location error of the A axis"),
              std::string::npos)
        << e.what();
  }
  const std::vector<std::size_t> c_only_axes{0};
  EXPECT_NO_THROW(fit_location_errors(nominal, c_only_axes, c_only));
  const auto poses = probe(trunnion(), kC, kA, 0.0, 1);
  const std::vector<std::size_t> twice{0, 0}, out_of_range{2};
  EXPECT_THROW(fit_location_errors(nominal, twice, poses), InputError);
  EXPECT_THROW(fit_location_errors(nominal, out_of_range, poses), InputError);
  EXPECT_THROW(fit_location_errors(nominal, kBoth, std::span(poses).first(3)), InputError);
  auto bad = poses;
  bad[2].angles_deg.pop_back();
  EXPECT_THROW(fit_location_errors(nominal, kBoth, bad), InputError);
  bad = poses;
  bad[5].centre_mm[1] = std::nan("");
  EXPECT_THROW(fit_location_errors(nominal, kBoth, bad), InputError);
  EXPECT_THROW(fit_location_errors(nominal, kBoth, poses, -1.0), InputError);
}

}  // namespace
