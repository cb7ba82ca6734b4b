// ISO 230-4 values and ballbar diagnostics against an independent forward model: the tool
// path of a machine with known injected errors is simulated exactly (not through the fit's
// linearised basis), the bar length computed as a distance, and the analysis must recover
// what was injected.
#include "cal/analysis/circle.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>
#include <random>

#include "cal/analysis/error.hpp"

namespace {

using namespace cal::circle;
constexpr double pi = std::numbers::pi;

struct Machine {  // the injected truth; lengths in um unless named
  double cu = 0, cv = 0, radius_error = 0;
  double su_ppm = 0, sv_ppm = 0;  // scale errors
  double square_um_per_m = 0;     // > 0: angle between +u and +v above 90 deg
  double lag_v_ms = 0;            // v lags u
  double backlash_u = 0, backlash_v = 0;
  double lateral_u = 0;  // u shifts by +-lateral_u/2 with the direction of v
  double cyclic_u = 0, cyclic_period_mm = 8.0;
  double bow_u = 0;  // du = bow_u (v/R)^2
  double noise = 0;
};

constexpr double R = 100.0, feed = 1000.0;  // mm, mm/min

// One trace: n samples over 360 degrees starting at 0, direction s.
Trace simulate(const Machine& m, Direction d, std::size_t n, std::uint64_t seed,
               double arc_deg = 360) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, m.noise);
  const double s = d == Direction::ccw ? 1.0 : -1.0;
  const double w = feed / 60.0 / R;  // rad/s
  Trace t{d, {}, {}};
  for (std::size_t i = 0; i < n; ++i) {
    // A full circle: n samples without repeating the start; a partial arc: both ends.
    const double steps = arc_deg < 360 ? static_cast<double>(n - 1) : static_cast<double>(n);
    const double theta = s * (arc_deg * pi / 180) * static_cast<double>(i) / steps;
    // Commanded positions (mm) and velocity signs.
    const double u = R * std::cos(theta);
    const double v_lag = R * std::sin(theta - s * w * m.lag_v_ms * 1e-3);  // exact time lag
    const double du_dt = -s * std::sin(theta), dv_dt = s * std::cos(theta);
    double ua = u * (1 + m.su_ppm * 1e-6) - m.square_um_per_m * 1e-6 * v_lag;
    double va = v_lag * (1 + m.sv_ppm * 1e-6);
    ua += 1e-3 *
          (-(m.backlash_u / 2) * (du_dt > 0 ? 1 : -1) + (m.lateral_u / 2) * (dv_dt > 0 ? 1 : -1) +
           m.cyclic_u * std::sin(2 * pi * u / m.cyclic_period_mm) + m.bow_u * std::pow(va / R, 2));
    va += 1e-3 * (-(m.backlash_v / 2) * (dv_dt > 0 ? 1 : -1));
    // The bar: from the table ball (the pivot at -centre offset) to the tool ball.
    const double length = std::hypot(ua + m.cu * 1e-3, va + m.cv * 1e-3) + m.radius_error * 1e-3;
    t.angle_deg.push_back(theta * 180 / pi);
    t.deviation_um.push_back((length - R) * 1e3 + noise(rng));
  }
  return t;
}

std::map<std::string, double> values(const Result& r) {
  std::map<std::string, double> out;
  for (const auto& d : r.diagnostics) out[d.key] = d.value;
  out[r.centre_u.key] = r.centre_u.value;
  out[r.centre_v.key] = r.centre_v.value;
  return out;
}

Result both(const Machine& m, std::size_t n = 3600) {
  const Trace t[] = {simulate(m, Direction::ccw, n, 1), simulate(m, Direction::cw, n, 2)};
  return analyse({.radius_mm = R, .feed_mm_per_min = feed, .cyclic_period_mm = m.cyclic_period_mm},
                 t);
}

// Tolerances. Noise-free single terms: the neglected second-order terms are below
// e^2 / R = (10 um)^2 / 100 mm = 0.001 um, and the fit is exact otherwise, so 1 % of the
// injected value (or 0.02 um) is a strict bound that a wrong sign, factor or basis fails.
TEST(CircleDiagnostics, RecoversEachInjectedErrorAlone) {
  struct Case {
    Machine m;
    std::string key;
    double expected;
  };
  const std::vector<Case> cases = {
      {{.cu = 12, .cv = -7}, "centre_X", 12},
      {{.cu = 12, .cv = -7}, "centre_Y", -7},
      {{.radius_error = 2.5}, "radius_error", 2.5},
      {{.su_ppm = 15, .sv_ppm = -5}, "scale_mismatch", 20},  // su - sv in um/m
      {{.square_um_per_m = 30}, "squareness", 30},
      {{.lag_v_ms = 2.0}, "servo_mismatch", 2.0},
      {{.backlash_u = 6}, "backlash_X", 6},
      {{.backlash_v = 4}, "backlash_Y", 4},
      {{.lateral_u = 3}, "lateral_play_X", 3},
      {{.cyclic_u = 1.5}, "cyclic_X", 1.5},
      {{.bow_u = 4}, "straightness_X", 4},
  };
  for (const auto& c : cases) {
    const auto v = values(both(c.m));
    ASSERT_TRUE(v.count(c.key)) << c.key;
    EXPECT_NEAR(v.at(c.key), c.expected, std::max(0.01 * std::abs(c.expected), 0.02)) << c.key;
  }
}

TEST(CircleDiagnostics, RecoversEverythingTogetherWithNoise) {
  // Noise 0.2 um on 2 x 3600 samples. A coefficient's standard error is about
  // 0.2 um / sqrt(7200 / 2) = 0.0033 um (half the samples' weight for a typical basis), times
  // the conversion (2000 / R = 20 for um/m, 1 / (R w) for the lag) and the inflation of the
  // correlated terms (at most ~3 here): the tolerances below are >= 5 of those.
  Machine m{.cu = 8,
            .cv = 5,
            .radius_error = 1.0,
            .su_ppm = 10,
            .sv_ppm = 0,
            .square_um_per_m = -25,
            .lag_v_ms = 1.5,
            .backlash_u = 5,
            .backlash_v = 3,
            .cyclic_u = 1.0,
            .bow_u = 2,
            .noise = 0.2};
  const auto r = both(m);
  const auto v = values(r);
  EXPECT_NEAR(v.at("centre_X"), 8, 0.05);
  EXPECT_NEAR(v.at("centre_Y"), 5, 0.05);
  EXPECT_NEAR(v.at("radius_error"), 1.0 + 0.5 * 10e-6 * R * 1e3, 0.05);  // + mean scale R(su+sv)/2
  EXPECT_NEAR(v.at("scale_mismatch"), 10, 0.5);
  EXPECT_NEAR(v.at("squareness"), -25, 0.5);
  EXPECT_NEAR(v.at("servo_mismatch"), 1.5, 0.03);
  EXPECT_NEAR(v.at("backlash_X"), 5, 0.1);
  EXPECT_NEAR(v.at("backlash_Y"), 3, 0.1);
  EXPECT_NEAR(v.at("cyclic_X"), 1.0, 0.05);
  EXPECT_NEAR(v.at("straightness_X"), 2, 0.1);
  EXPECT_NEAR(r.residual_rms_um, 0.2, 0.02);  // the model explains all but the noise
  // Ranked by contribution: the largest first; shares are of G.
  for (std::size_t i = 1; i < r.diagnostics.size(); ++i)
    EXPECT_GE(r.diagnostics[i - 1].pv_um, r.diagnostics[i].pv_um);
  EXPECT_GT(r.diagnostics[0].share_pct, 10.0);
}

TEST(CircleDiagnostics, FindsTheCyclicPeriodWhenNotGiven) {
  Machine m{.cyclic_u = 2.0, .cyclic_period_mm = 12.0};
  const Trace t[] = {simulate(m, Direction::ccw, 3600, 1), simulate(m, Direction::cw, 3600, 2)};
  const auto r = analyse({.radius_mm = R, .feed_mm_per_min = feed}, t);
  ASSERT_TRUE(r.cyclic_period_mm);
  // The search grid is geometric, 61 steps over 2..40 mm: 5 % apart; the nearest is within 2.5 %.
  EXPECT_NEAR(*r.cyclic_period_mm, 12.0, 0.3);
  EXPECT_NEAR(values(r).at("cyclic_X"), 2.0, 0.3);
}

TEST(Iso230_4, CircularDeviationHysteresisAndRadialDeviationByHand) {
  // ccw: dr = 2 cos 2t (an ellipse: LSQ centre at 0, G = 4, F = +2 / -2);
  // cw: the same + 1.5 um: G_cw = 4, the common G = 4 + 1.5, H = 1.5, F max = 3.5.
  Trace ccw{Direction::ccw, {}, {}}, cw{Direction::cw, {}, {}};
  for (int i = 0; i < 720; ++i) {
    const double a = i * 0.5;
    ccw.angle_deg.push_back(a);
    ccw.deviation_um.push_back(2 * std::cos(2 * a * pi / 180));
    cw.angle_deg.push_back(-a);
    cw.deviation_um.push_back(2 * std::cos(2 * a * pi / 180) + 1.5);
  }
  const Trace t[] = {ccw, cw};
  const auto r = analyse({.radius_mm = R}, t);
  EXPECT_NEAR(r.iso.G_ccw_um, 4.0, 1e-9);
  EXPECT_NEAR(r.iso.G_cw_um, 4.0, 1e-9);
  EXPECT_NEAR(r.iso.G_bi_um, 5.5, 1e-9);
  EXPECT_NEAR(r.iso.H_um, 1.5, 1e-9);
  EXPECT_NEAR(r.iso.F_max_um, 3.5, 1e-9);
  EXPECT_NEAR(r.iso.F_min_um, -2.0, 1e-9);
  EXPECT_NEAR(r.iso.centre_u_um, 0.0, 1e-9);
}

TEST(Iso230_4, HalfCircleRecoversTheCentre) {
  // Over 0..180 degrees only, a pure centre offset (7, -4) um: the LSQ circle finds it.
  Machine m{.cu = 7, .cv = -4};
  const Trace t[] = {simulate(m, Direction::ccw, 1800, 1, 180.0)};
  const auto r = analyse({.radius_mm = R}, t);
  EXPECT_NEAR(r.iso.centre_u_um, 7, 0.01);
  EXPECT_NEAR(r.iso.centre_v_um, -4, 0.01);
  EXPECT_LT(r.iso.G_ccw_um, 0.01);
  EXPECT_NEAR(r.iso.arc_deg, 180.0, 0.2);
  EXPECT_FALSE(r.notes.empty());
}

TEST(Iso230_4, AnglesFromTimeFollowFeedOverRadius) {
  // 1000 mm/min = 16.6667 mm/s on R = 100 mm: 0.166667 rad/s = 9.549297 deg/s, clockwise.
  const double t[] = {0.0, 1.0, 36.0};
  const auto a = angles_from_time(t, 90.0, 1000.0, 100.0, Direction::cw);
  EXPECT_DOUBLE_EQ(a[0], 90.0);
  EXPECT_NEAR(a[1], 90.0 - 9.549297, 1e-6);
  EXPECT_NEAR(a[2], 90.0 - 36 * 9.549297, 1e-4);
}

TEST(Iso230_4, RefusesBadInput) {
  Trace ok = simulate({}, Direction::ccw, 100, 1);
  Trace short_arc = simulate({}, Direction::ccw, 100, 1, 170.0);
  Trace mismatched = ok;
  mismatched.deviation_um.pop_back();
  Trace nan = ok;
  nan.deviation_um[3] = std::nan("");
  EXPECT_THROW(analyse({}, std::span<const Trace>{}), cal::InputError);
  EXPECT_THROW(analyse({}, std::span(&short_arc, 1)), cal::InputError);
  EXPECT_THROW(analyse({}, std::span(&mismatched, 1)), cal::InputError);
  EXPECT_THROW(analyse({}, std::span(&nan, 1)), cal::InputError);
  EXPECT_THROW(analyse({.radius_mm = 0}, std::span(&ok, 1)), cal::InputError);
  const Trace same[] = {ok, ok};
  EXPECT_THROW(analyse({}, same), cal::InputError);
  try {
    analyse({}, std::span(&short_arc, 1));
  } catch (const cal::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("covers 170.0 degrees, at least 180 needed"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
