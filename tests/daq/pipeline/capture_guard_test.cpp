// The check before a capture by hand (cal/daq/capture_guard.hpp, issue 29) on a simulated laser
// feed at 100 Hz (the simulated shop's rate): the axis stands at 100 mm, then leaves at
// 1000 mm/min (16.667 mm/s), the late press of the issue. The motion indicator sees the same
// readings, as in a run. Expected verdicts come from the settings, worked out in comments.
#include "cal/daq/capture_guard.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "cal/analysis/error.hpp"
#include "cal/daq/motion.hpp"

namespace {

using cal::daq::CaptureGuard;
using cal::daq::Motion;
using cal::daq::MotionIndicator;

constexpr std::int64_t ms = 1'000'000;  // ns
const std::vector<double> targets{0.0, 100.0, 200.0};

struct Feed {
  CaptureGuard guard{
      {.tolerance_um = 1.0, .span_s = 0.5, .drift_tolerances = 10.0, .force_within_s = 3.0}};
  MotionIndicator motion{{.tolerance_um = 1.0, .dwell_s = 1.5, .window_mm = 0.5}};
  std::int64_t now_ns = 0;
  // Laser readings every `step_ns` (10 ms) up to `until_ms`, at position(t_s) in mm.
  template <typename F>
  void run_until(std::int64_t until_ms, F position_mm, std::int64_t step_ns = 10 * ms) {
    for (; now_ns <= until_ms * ms; now_ns += step_ns) {
      const double t_s = static_cast<double>(now_ns) * 1e-9;
      // +/- 0.15 um of deterministic noise (the simulated laser's)
      const double x = position_mm(t_s) + 0.15e-3 * std::sin(12345.0 * t_s);
      guard.add_reading(now_ns, x, true);
      motion.add(now_ns, x, true, targets);
    }
  }
};

// At rest at 100 mm until 2 s, then leaving up at 16.667 mm/s.
double leaving(double t_s) { return 100.0 + (t_s > 2.0 ? 16.667 * (t_s - 2.0) : 0.0); }

TEST(CaptureGuard, ALatePressWhileTheAxisLeavesIsRefusedThenForcedAndMarked) {
  Feed f;
  f.run_until(2020, leaving);  // newest reading at 2.020 s: 100 + 16.667 * 0.02 = 100.333 mm
  // The indicator: 100.333 mm is within the 0.5 mm
  // window of 100 mm, so it shows settling, not MOVING: the drift must refuse it. The last
  // 0.5 s hold 2 readings of motion (2.01, 2.02 s): the least-squares slope of a ramp of length
  // a at the end of a span T is about 3 v a^2 / T^2, times T: 3 * 16667 * 0.02^2 / 0.5 = 40 um,
  // above the 10 um (10 tolerances) of drift.
  EXPECT_EQ(f.motion.motion(), Motion::settling);
  const auto first = f.guard.press(2020 * ms, f.motion.motion());
  EXPECT_FALSE(first.take);
  EXPECT_NE(first.moving.find("drifting"), std::string::npos) << first.moving;
  const auto text = f.guard.refusal(first.moving);
  EXPECT_NE(text.find("not captured: the axis is moving ("), std::string::npos) << text;
  EXPECT_NE(text.find("press Capture again within 3 s to take it anyway"), std::string::npos);
  // Pressed again 1 s later, still moving: taken, marked as taken while moving.
  f.run_until(3020, leaving);
  const auto forced = f.guard.press(3020 * ms, f.motion.motion());
  EXPECT_TRUE(forced.take);
  EXPECT_TRUE(forced.while_moving);
  EXPECT_FALSE(forced.moving.empty());
  // The force is used up: the next press is refused again.
  EXPECT_FALSE(f.guard.press(3030 * ms, f.motion.motion()).take);
}

TEST(CaptureGuard, ASecondPressAfterTheForceTimeIsRefusedAgain) {
  Feed f;
  f.run_until(3000, leaving);  // 16.7 mm past 100: MOVING on the page
  EXPECT_EQ(f.motion.motion(), Motion::moving);
  const auto first = f.guard.press(3000 * ms, f.motion.motion());
  EXPECT_FALSE(first.take);
  EXPECT_NE(first.moving.find("MOVING"), std::string::npos) << first.moving;
  // 3.5 s later (more than 3 s): a new refusal, not a forced capture.
  EXPECT_FALSE(f.guard.press(6500 * ms, f.motion.motion()).take);
  EXPECT_TRUE(f.guard.press(6600 * ms, f.motion.motion()).take);  // within 3 s of that one
}

TEST(CaptureGuard, AStopAtRestIsTakenEvenWhenItVibratesTooMuchForTheTrigger) {
  Feed f;
  // At rest at 100 mm with a +/- 5 um vibration at 25 Hz: 10 um peak to peak is outside the
  // trigger's +/- 1 um band (it never calls it stable; the indicator shows settling), the
  // case a capture by hand exists for. Over 0.5 s (12.5 periods) its least-squares slope times
  // 0.5 s stays below 10 um: at most about 5 um * 6 / (2 pi 12.5) ~ 0.4 um.
  f.run_until(4000,
              [](double t) { return 100.0 + 5e-3 * std::sin(2 * std::numbers::pi * 25 * t); });
  EXPECT_EQ(f.motion.motion(), Motion::settling);
  const auto v = f.guard.press(4000 * ms, f.motion.motion());
  EXPECT_TRUE(v.take);
  EXPECT_FALSE(v.while_moving);
  EXPECT_TRUE(v.moving.empty()) << v.moving;
}

TEST(CaptureGuard, APositionFeedStillTravellingRefuses) {
  Feed f;
  f.run_until(2000, [](double) { return 100.0; });
  // The machine's feed (every 50 ms) says the axis crept 0.05 mm within the last 0.5 s while
  // the laser saw nothing yet (its beam reads the table): more than the 1 um tolerance.
  for (int k = 0; k <= 10; ++k) f.guard.add_feed((1500 + 50 * k) * ms, 100.0 + 0.005 * k);
  const auto v = f.guard.press(2000 * ms, f.motion.motion());
  EXPECT_FALSE(v.take);
  EXPECT_NE(v.moving.find("position feed moved 50 um"), std::string::npos) << v.moving;
  // The same feed standing still for the span (its last sample held): taken.
  Feed g;
  g.run_until(2000, [](double) { return 100.0; });
  g.guard.add_feed(200 * ms, 100.0);  // sent on change only: held since 0.2 s
  EXPECT_TRUE(g.guard.press(2000 * ms, g.motion.motion()).take);
}

// The axis leaving 100 mm at 2 s, as a machine starts: 2 m/s^2 (the simulated shop's) up to
// 1000 mm/min. After 5 ms it has moved 1/2 * 2000 * 0.005^2 = 0.025 mm.
double starting(double t_s) {
  constexpr double a = 2000.0, v = 16.667, tv = v / a;  // mm/s^2, mm/s, s to full speed
  const double d = std::max(0.0, t_s - 2.0);
  return 100.0 + (d < tv ? 0.5 * a * d * d : 0.5 * a * tv * tv + v * (d - tv));
}

TEST(CaptureGuard, APressInTheFirstMillisecondsOfAMotionIsRefused) {
  // A laser at 10 kHz (the IDS3010's rate). 5 ms into the motion, 25 um from the rest: the
  // indicator still shows the stop (within its 0.5 mm window) and the least-squares line of the
  // 0.5 s tilts by about 0.5 um (a parabola's tail: worked out numerically, 4 um at 10 ms), far
  // below the 10 um of drift; but the newest reading is 25 um beyond every reading up to 50 ms
  // before it (the rest, +/- 0.15 um), more than the 2 um band.
  Feed f;
  f.run_until(2005, starting, ms / 10);
  EXPECT_NE(f.motion.motion(), Motion::moving);
  const auto v = f.guard.press(f.now_ns - ms / 10, f.motion.motion());
  EXPECT_FALSE(v.take);
  EXPECT_NE(v.moving.find("from where it stood"), std::string::npos) << v.moving;
  // 1 ms in (1 um moved, within the band): the newest readings are still the stop's.
  Feed g;
  g.run_until(2001, starting, ms / 10);
  EXPECT_TRUE(g.guard.press(g.now_ns - ms / 10, g.motion.motion()).take);
}

TEST(CaptureGuard, AVibrationAt10kHzIsNoDeparture) {
  // +/- 5 um at 25 Hz read at 10 kHz: every new reading lies within the range of the readings
  // before it (the vibration's own), so it is taken as at rest, as at 100 Hz above.
  Feed f;
  f.run_until(
      1000, [](double t) { return 100.0 + 5e-3 * std::sin(2 * std::numbers::pi * 25 * t); },
      ms / 10);
  const auto v = f.guard.press(f.now_ns - ms / 10, f.motion.motion());
  EXPECT_TRUE(v.take);
  EXPECT_TRUE(v.moving.empty()) << v.moving;
}

TEST(CaptureGuard, NonPositiveSettingsAreRefused) {
  EXPECT_THROW(CaptureGuard({.tolerance_um = 0.0}), cal::InputError);
  EXPECT_THROW(CaptureGuard({.force_within_s = -1.0}), cal::InputError);
  EXPECT_THROW(CaptureGuard({.departure_lag_s = 0.5}), cal::InputError);  // not within the span
}

}  // namespace
