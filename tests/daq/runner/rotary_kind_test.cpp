// Issue 36 (c): the angular positioning of a rotary axis per ISO 230-2. A SIMULATED rotary
// axis with a known error (linear plus cyclic, in arcsec, over 0 .. 360 deg) and a known
// backlash follows an ISO 230-2 plan; its angular reference streams the axis's angle modulo a
// turn (0 .. 360 deg, in rad as the gauge codec gives an arcsec gauge's value) while it moves
// and while it stands; each stop's value is the mean of the kind's samples in its window (as
// the runner takes it), and the rotary kind's evaluation recovers the injected error.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>

#include "cal/analysis/error.hpp"
#include "kinds/kind.hpp"
#include "linear_run.hpp"
#include "sim_shop.hpp"

namespace {

using daq::kinds::Source;
using daq::kinds::StopValue;
namespace iso = cal::iso230_2;

constexpr double kPi = std::numbers::pi;

// The injected truth, arcsec: 10" over the turn (a scale error of the encoder), a cyclic 4"
// four times a turn (a worm or an encoder's eccentricity harmonics), and 6" of backlash:
// approached from below the axis stops 3" beyond the target, from above 3" short of it; the
// reference zeroed 3" off the axis's 0, so that the stops at 0 deg approached from below read
// on both sides of 0 (359.9999.. and 0.0000..) and must be averaged across the wrap.
constexpr double kLinearArcsecPerTurn = 10.0, kCyclicArcsec = 4.0, kBacklashArcsec = 6.0;
constexpr double kZeroArcsec = -3.0;
double injected_arcsec(double target_deg) {
  return kZeroArcsec + kLinearArcsecPerTurn * target_deg / 360.0 +
         kCyclicArcsec * std::sin(2 * kPi * target_deg / 90.0);
}

// The simulated shop's rotary test (sim_shop.hpp) every 30 deg: 13 targets.
cal::daq::LinearTestConfig rotary_test() {
  auto l = daq::simulated_rotary_test(5);
  l.interval_mm = 30.0;  // deg; overrun 3 deg: the approach to 0 comes from 357 deg
  return l;
}

// The reference's reading of an angle: modulo a turn, 0 .. 360 deg, in rad.
double reading_rad(double angle_deg) {
  return std::fmod(std::fmod(angle_deg, 360.0) + 360.0, 360.0) * kPi / 180.0;
}

// The plan run on the simulated axis: every 0.5 deg of the motion streamed, and 20 readings at
// each stop with `noise_arcsec` of noise; each stop's value the mean of its readings' samples.
std::vector<StopValue> acquire(const cal::daq::LinearTestConfig& l, double noise_arcsec) {
  const auto plan = daq::linear_plan(l);
  const auto reader = daq::kinds::kind("rotary").reader(l);
  std::mt19937 rng(36);
  std::normal_distribution<double> noise(0.0, noise_arcsec);
  std::int64_t t_ns = 0;
  const auto sample = [&](double angle_deg) {
    t_ns += 1'000'000;
    return *reader->add(Source::probe, 0, t_ns, reading_rad(angle_deg));
  };
  std::vector<StopValue> stops;
  double at_deg = plan.moves.front().position_mm;
  for (const auto& mv : plan.moves) {
    const int steps = static_cast<int>(std::ceil(std::abs(mv.position_mm - at_deg) / 0.5));
    for (int k = 1; k <= steps; ++k) sample(at_deg + (mv.position_mm - at_deg) * k / steps);
    at_deg = mv.position_mm;
    if (mv.kind != iso::MoveKind::measure) continue;
    const bool up = mv.direction == iso::Direction::up;
    const double stand_deg =
        mv.position_mm +
        (injected_arcsec(mv.position_mm) + (up ? 0.5 : -0.5) * kBacklashArcsec) / 3600.0;
    double sum = 0;
    for (int k = 0; k < 20; ++k) sum += sample(stand_deg + noise(rng) / 3600.0);
    stops.push_back({.position_mm = mv.position_mm,
                     .target_index = mv.target_index - 1,
                     .run = mv.run,
                     .direction = up ? '+' : '-',
                     // stored and evaluated as the runner does: the deviation
                     .value = daq::kinds::kind("rotary").stop_value(mv.position_mm, sum / 20)});
  }
  return stops;
}

TEST(RotaryKind, NamesAndUnits) {
  const auto& k = daq::kinds::kind("rotary");
  EXPECT_EQ(k.component(rotary_test()), "E_CC");
  EXPECT_EQ(k.unit(), "arcsec");
  EXPECT_EQ(k.probe_role(), "angle");
}

// The reader follows the turns: readings on both sides of 0 deg stay within arcseconds of each
// other, so a stop at 0 or 360 deg is not averaged to 180 deg.
TEST(RotaryKind, ReaderFollowsTheTurnAcrossZero) {
  const auto r = daq::kinds::kind("rotary").reader(rotary_test());
  const double a = *r->add(Source::probe, 0, 1, reading_rad(359.999));
  const double b = *r->add(Source::probe, 0, 2, reading_rad(0.001));
  EXPECT_NEAR(b - a, 7.2, 1e-6);  // 0.002 deg
  EXPECT_NEAR(*r->add(Source::probe, 0, 3, reading_rad(359.998)) - a, -3.6, 1e-6);
  EXPECT_FALSE(r->add(Source::laser, 0, 4, 0.1));  // not the reference's
}

// The injected error recovered through the kind's evaluation (ISO 230-2:2014), 13 targets 30 deg
// apart, 5 runs each way, 0.3" of noise per reading (20 readings a stop: 0.07" a stop, 0.03" a
// mean of 5). Tolerances: the means per target and direction within 0.15" of the truth, the
// reversal of each target within 0.15" of the 6" injected, B within 0.15" of 6".
TEST(RotaryKind, RecoversInjectedErrorAndBacklashOverAFullTurn) {
  const auto l = rotary_test();
  const auto stops = acquire(l, 0.3);
  ASSERT_EQ(stops.size(), 13u * 5 * 2);
  const auto e = daq::kinds::kind("rotary").evaluate(stops, l);
  EXPECT_EQ(e.json["schema"], "caldaq.rotary.v1");
  EXPECT_EQ(e.json["unit"], "arcsec");
  EXPECT_EQ(e.json["target_unit"], "deg");
  EXPECT_EQ(e.json["component"], "E_CC");
  EXPECT_EQ(e.title, "ISO 230-2:2014 rotary C (E_CC)");
  const auto& targets = e.json["targets"];
  ASSERT_EQ(targets.size(), 13u);
  double worst = 0;
  for (const auto& t : targets) {
    const double q = t["position_deg"];
    const double truth = injected_arcsec(q);
    worst = std::max({worst, std::abs(t["mean"].get<double>() - truth),
                      std::abs(t["reversal"].get<double>() - kBacklashArcsec)});
    EXPECT_NEAR(t["mean_up"].get<double>(), truth + kBacklashArcsec / 2, 0.15) << q << " deg";
    EXPECT_NEAR(t["mean_down"].get<double>(), truth - kBacklashArcsec / 2, 0.15) << q << " deg";
    EXPECT_NEAR(t["reversal"].get<double>(), kBacklashArcsec, 0.15) << q << " deg";
    EXPECT_LT(t["s_up"].get<double>(), 0.2) << q << " deg";
  }
  EXPECT_NEAR(e.json["axis"]["B"]["value"].get<double>(), kBacklashArcsec, 0.15);
  // 360 deg reads as 0 deg on the reference: its deviation is 7" (the turn's 10" from the
  // zero's -3"), not -1296000".
  EXPECT_NEAR(targets.back()["mean"].get<double>(), kZeroArcsec + kLinearArcsecPerTurn, 0.15);
  // M: the range of the bidirectional means, from the truth at the targets.
  double lo = 1e9, hi = -1e9;
  for (int i = 0; i <= 12; ++i)
    lo = std::min(lo, injected_arcsec(30.0 * i)), hi = std::max(hi, injected_arcsec(30.0 * i));
  EXPECT_NEAR(e.json["axis"]["M"]["value"].get<double>(), hi - lo, 0.15);
  std::printf(
      "rotary: worst |recovered - injected| over the targets (means, reversals): %.3f\"; "
      "B %.3f\" (injected %.3f\"), M %.3f\" (injected %.3f\"), 360 deg %.3f\" (injected %.3f\")\n",
      worst, e.json["axis"]["B"]["value"].get<double>(), kBacklashArcsec,
      e.json["axis"]["M"]["value"].get<double>(), hi - lo, targets.back()["mean"].get<double>(),
      injected_arcsec(360.0));
}

// A reference that reads -180 .. 180 deg instead of 0 .. 360 deg gives the same evaluation.
TEST(RotaryKind, AnyRepresentativeOfTheTurn) {
  const auto l = rotary_test();
  auto stops = acquire(l, 0.0);
  auto shifted = stops;
  for (auto& s : shifted) s.value -= 360.0 * 3600.0;
  const auto a = daq::kinds::kind("rotary").evaluate(stops, l).json["targets"];
  const auto b = daq::kinds::kind("rotary").evaluate(shifted, l).json["targets"];
  for (std::size_t i = 0; i < a.size(); ++i)
    EXPECT_NEAR(a[i]["mean"].get<double>(), b[i]["mean"].get<double>(), 1e-6);
}

// A linear axis is refused; a rotary axis is acquired, its stops recognised from its angular
// reference (tests/e2e/rotary_e2e_test.cpp), not from a laser.
TEST(RotaryKind, RefusesALinearAxisAndRecognisesStopsFromItsReference) {
  auto l = rotary_test();
  l.axis = "X";
  try {
    daq::kinds::kind("rotary").validate(l);
    FAIL() << "a linear axis accepted";
  } catch (const cal::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("rotary axis (A, B, C)"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(daq::kinds::kind("rotary").validate(rotary_test()));
  EXPECT_TRUE(daq::kinds::kind("rotary").stops_from_probe());
  EXPECT_FALSE(daq::kinds::kind("roll").stops_from_probe());
  EXPECT_THROW(daq::kinds::kind("rotary").evaluate({}, rotary_test()), cal::InputError);
}

}  // namespace
