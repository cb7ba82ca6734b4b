// The stability trigger on synthetic streams with known stops: a staircase with noise, a
// stop shorter than the dwell, a blocked beam, the approach direction, the manual trigger.
#include "cal/daq/trigger.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "cal/analysis/error.hpp"

namespace {

using namespace cal::daq;
constexpr std::int64_t ms = 1'000'000;

// A 1 kHz stream: moves between stops at 100 mm/s, each stop held for its dwell, with
// Gaussian noise of sigma_um. Returns the captures.
struct Stream {
  StabilityTrigger trigger;
  std::mt19937_64 rng{7};
  std::normal_distribution<double> noise;
  std::int64_t t = 0;
  double x = 0.0;
  std::vector<Capture> captures;
  Stream(TriggerSettings s, double sigma_um) : trigger(s), noise(0.0, sigma_um * 1e-3) {}
  void feed(double x_mm, bool valid = true) {
    if (auto c = trigger.add(t, x_mm + noise(rng), valid)) captures.push_back(*c);
    t += ms;
  }
  void move_to(double target) {
    const double step = 0.1 * (target > x ? 1 : -1);  // 100 mm/s at 1 kHz
    while (std::abs(target - x) > 0.1) feed(x += step);
    x = target;
  }
  void dwell(double seconds, bool valid = true) {
    for (int i = 0; i < static_cast<int>(seconds * 1000); ++i) feed(x, valid);
  }
};

TEST(StabilityTrigger, CapturesEachStopOnceWithItsMeanAndApproach) {
  // Noise 0.2 um: the band +-1 um is 5 sigma, so a 1.5 s window of 1500 readings is not
  // broken (P(|n| > 2 um spread) is negligible). The capture averages the newest half: >= 750
  // readings, standard error 0.2 / sqrt(750) = 0.007 um: 0.05 um is 7 standard errors.
  Stream s({.tolerance_um = 1.0, .dwell_s = 1.5, .window_mm = 0.5}, 0.2);
  const std::vector<double> stops = {0.0, 50.0, 100.0, 50.0, 0.0};
  for (double target : stops) {
    s.move_to(target);
    s.dwell(4.0);  // one stop, however long: one capture
  }
  ASSERT_EQ(s.captures.size(), stops.size());
  for (std::size_t i = 0; i < stops.size(); ++i) {
    EXPECT_NEAR(s.captures[i].mean_mm, stops[i], 0.05e-3) << i;
    EXPECT_NEAR(s.captures[i].std_um, 0.2, 0.02) << i;
    EXPECT_GE(s.captures[i].count, 750u);
  }
  EXPECT_EQ(s.captures[0].approach, Approach::unknown);  // the stream starts there
  EXPECT_EQ(s.captures[1].approach, Approach::from_below);
  EXPECT_EQ(s.captures[2].approach, Approach::from_below);
  EXPECT_EQ(s.captures[3].approach, Approach::from_above);
  EXPECT_EQ(s.captures[4].approach, Approach::from_above);
}

TEST(StabilityTrigger, IgnoresShortPausesStopsAwayFromTheTargetAndABlockedBeam) {
  Stream s({.tolerance_um = 1.0, .dwell_s = 1.5, .window_mm = 0.5}, 0.1);
  s.trigger.expect(100.0);
  s.move_to(30.0);
  s.dwell(1.0);  // shorter than the dwell: no stop
  s.move_to(60.0);
  s.dwell(3.0);  // long, but 40 mm from the expected target: no stop
  s.move_to(100.0);
  s.dwell(1.0);
  s.dwell(0.01, false);  // beam blocked for 10 ms: the window restarts
  s.dwell(1.0);          // 1 s since: still not a stop
  EXPECT_TRUE(s.captures.empty());
  s.dwell(1.0);  // now 2 s of valid readings
  ASSERT_EQ(s.captures.size(), 1u);
  EXPECT_NEAR(s.captures[0].mean_mm, 100.0, 0.05e-3);
}

TEST(StabilityTrigger, ManualCaptureTakesTheCurrentWindow) {
  Stream s({.tolerance_um = 1.0, .dwell_s = 1.5, .window_mm = 0.5}, 0.1);
  s.move_to(20.0);
  s.dwell(0.5);
  const auto c = s.trigger.capture_now();
  ASSERT_TRUE(c);
  EXPECT_TRUE(c->manual);
  EXPECT_NEAR(c->mean_mm, 20.0, 0.05e-3);
  EXPECT_FALSE(s.trigger.armed());  // the same stop is not captured again
  s.dwell(3.0);
  EXPECT_TRUE(s.captures.empty());
}

TEST(StabilityTrigger, RefusesNonPositiveSettings) {
  EXPECT_THROW(StabilityTrigger({.tolerance_um = 0}), cal::InputError);
  EXPECT_THROW(StabilityTrigger({.dwell_s = -1}), cal::InputError);
}

TEST(StabilityTrigger, WithAllTargetsExpectedAStopBetweenThemIsNotCaptured) {
  // Targets 0, 50, 100; the machine also pauses 4 s at 73 mm (23 mm from the nearest target,
  // far outside the 0.5 mm window) and passes 50 mm without stopping on the way down.
  Stream s({.tolerance_um = 1.0, .dwell_s = 1.5, .window_mm = 0.5}, 0.2);
  const std::vector<double> targets = {100.0, 0.0, 50.0};  // any order: sorted inside
  s.trigger.expect_any(targets);
  s.dwell(4.0);  // at 0
  s.move_to(50.0);
  s.dwell(4.0);
  s.move_to(73.0);
  s.dwell(4.0);  // extra pause: not at a target
  s.move_to(100.0);
  s.dwell(4.0);
  s.move_to(0.0);  // through 50 without a stop
  s.dwell(4.0);
  ASSERT_EQ(s.captures.size(), 4u);
  const double expected[] = {0.0, 50.0, 100.0, 0.0};
  for (std::size_t i = 0; i < 4; ++i) EXPECT_NEAR(s.captures[i].mean_mm, expected[i], 0.05e-3);
  EXPECT_EQ(s.captures[3].approach, Approach::from_above);
}

TEST(StabilityTrigger, NoisierThanTheBandIsNeverAStop) {
  // Noise sigma 1 um against a +-1 um band (2 um wide): in 1.5 s of 1 kHz readings the spread
  // exceeds 2 um almost surely (the range of 1500 normal samples is about 6.5 sigma), so the
  // window never reaches the dwell: no capture, as a stop that is not stable must not count.
  Stream s({.tolerance_um = 1.0, .dwell_s = 1.5, .window_mm = 0.5}, 1.0);
  s.dwell(5.0);
  EXPECT_TRUE(s.captures.empty());
}

TEST(StabilityTrigger, NaNReadingsBreakTheWindowLikeALostBeam) {
  StabilityTrigger t({.tolerance_um = 1.0, .dwell_s = 1.0, .window_mm = 0.5});
  std::int64_t now = 0;
  for (int i = 0; i < 900; ++i) EXPECT_FALSE(t.add(now += ms, 10.0));
  EXPECT_FALSE(t.add(now += ms, std::nan("")));                             // a NaN marked valid
  for (int i = 0; i < 900; ++i) EXPECT_FALSE(t.add(now += ms, 10.0)) << i;  // 0.9 s since
  std::optional<Capture> c;
  for (int i = 0; i < 200 && !c; ++i) c = t.add(now += ms, 10.0);
  ASSERT_TRUE(c);
  EXPECT_EQ(c->mean_mm, 10.0);
}

// A machine with a position feed (the commanded position, 100 Hz) and a laser (1 kHz) that
// reads the actual position: the commanded one plus a known positioning error per target and
// Gaussian noise.
struct FedMachine {
  PositionTrigger trigger;
  std::mt19937_64 rng{11};
  std::normal_distribution<double> noise{0.0, 0.2e-3};  // 0.2 um
  std::int64_t t = 0;
  double x = 0.0, error_mm = 0.0;
  std::vector<Capture> captures;
  bool on_change = false;  // an MTConnect adapter: a sample only when the position changed
  double last_sent = std::numeric_limits<double>::quiet_NaN();
  explicit FedMachine(PositionTriggerSettings s, bool changes_only = false)
      : trigger(s), on_change(changes_only) {}
  void tick(bool laser_valid = true) {  // 1 ms
    if (t % (10 * ms) == 0 && (!on_change || x != last_sent)) {
      last_sent = x;
      if (auto c = trigger.add_position(t, x)) captures.push_back(*c);
    }
    if (auto c = trigger.add_reading(t, x + error_mm + noise(rng), laser_valid))
      captures.push_back(*c);
    t += ms;
  }
  void move_to(double target, double error_at_target_mm) {
    const double step = 0.1 * (target > x ? 1 : -1);  // 100 mm/s
    while (std::abs(target - x) > 0.1) x += step, tick();
    x = target;
    error_mm = error_at_target_mm;
  }
  void dwell(double seconds, bool laser_valid = true) {
    for (int i = 0; i < static_cast<int>(seconds * 1000); ++i) tick(laser_valid);
  }
};

TEST(PositionTrigger, CapturesTheLaserWhileTheFeedIsStillAtATarget) {
  // Injected errors +3, -2, +1 um at 0, 50, 100 mm. The capture averages the newest half of the
  // 1.5 s still window: >= 740 readings of sigma 0.2 um, standard error 0.007 um; 0.05 um is
  // 7 standard errors.
  FedMachine m({.tolerance_um = 1.0, .dwell_s = 1.5});
  const std::vector<double> targets = {0.0, 50.0, 100.0};
  m.trigger.expect_any(targets);
  m.error_mm = 3e-3;
  m.dwell(4.0);
  m.move_to(50.0, -2e-3);
  m.dwell(4.0);
  m.move_to(73.0, 0.0);
  m.dwell(4.0);  // still, but not at a target: no capture
  m.move_to(100.0, 1e-3);
  m.dwell(1.0);  // too short ...
  m.move_to(50.0, -2e-3);
  m.move_to(100.0, 1e-3);
  m.dwell(4.0);  // ... the second visit is the stop
  ASSERT_EQ(m.captures.size(), 3u);
  EXPECT_NEAR(m.captures[0].mean_mm, 0.003, 0.05e-3);
  EXPECT_NEAR(m.captures[1].mean_mm, 50.0 - 0.002, 0.05e-3);
  EXPECT_NEAR(m.captures[2].mean_mm, 100.0 + 0.001, 0.05e-3);
  EXPECT_EQ(m.captures[0].approach, Approach::unknown);
  EXPECT_EQ(m.captures[1].approach, Approach::from_below);
  EXPECT_EQ(m.captures[2].approach, Approach::from_below);  // came back up from 50
  for (const auto& c : m.captures) {
    EXPECT_NEAR(c.std_um, 0.2, 0.02);
    EXPECT_GE(c.count, 740u);
    EXPECT_GE(c.end_ns - c.start_ns, 1'500 * ms);
    EXPECT_LE(c.end_ns - c.start_ns, 1'510 * ms);  // one feed period at most beyond the dwell
  }
}

TEST(PositionTrigger, AFeedThatSendsOnlyOnChangeHoldsItsLastPosition) {
  // An MTConnect adapter is silent while the machine dwells: its last sample holds. With
  // feed_holds the stop lasts as long as the laser reads; the same silent feed taken as a
  // periodic one never sees the dwell (its newest sample is where the axis arrived).
  for (const bool holds : {true, false}) {
    FedMachine m({.tolerance_um = 1.0, .dwell_s = 1.5, .feed_holds = holds}, true);
    m.trigger.expect_any(std::vector<double>{50.0, 100.0});
    m.move_to(50.0, -2e-3);
    m.dwell(4.0);
    m.move_to(100.0, 1e-3);
    m.dwell(4.0);
    if (!holds) {
      EXPECT_TRUE(m.captures.empty());
      continue;
    }
    ASSERT_EQ(m.captures.size(), 2u);
    EXPECT_NEAR(m.captures[0].mean_mm, 50.0 - 0.002, 0.05e-3);
    EXPECT_NEAR(m.captures[1].mean_mm, 100.0 + 0.001, 0.05e-3);
    for (const auto& c : m.captures) {
      EXPECT_GE(c.end_ns - c.start_ns, 1'500 * ms);  // the dwell, measured on the laser
      EXPECT_LE(c.end_ns - c.start_ns, 1'501 * ms);
      EXPECT_EQ(c.approach, Approach::from_below);
    }
  }
}

TEST(PositionTrigger, ALostBeamRestartsTheDwellAndNoLaserMeansNoCapture) {
  FedMachine m({.tolerance_um = 1.0, .dwell_s = 1.5});
  m.trigger.expect(20.0);
  m.move_to(20.0, 0.0);
  const std::int64_t arrived = m.t;
  m.dwell(1.0);
  m.dwell(0.05, false);  // beam blocked for 50 ms
  const std::int64_t beam_back = m.t;
  m.dwell(1.0);  // 1 s of valid laser since: not yet
  EXPECT_TRUE(m.captures.empty());
  m.dwell(1.0);
  ASSERT_EQ(m.captures.size(), 1u);
  EXPECT_GE(m.captures[0].start_ns, beam_back - ms);  // the window starts after the loss
  EXPECT_GT(m.captures[0].start_ns, arrived + 1'000 * ms);
  // A stop where the beam stays lost is never captured.
  m.trigger.expect(40.0);
  m.move_to(40.0, 0.0);
  m.dwell(4.0, false);
  EXPECT_EQ(m.captures.size(), 1u);
}

TEST(PositionTrigger, OneCapturePerStopAndManualCapture) {
  FedMachine m({.tolerance_um = 1.0, .dwell_s = 1.5});
  m.move_to(10.0, 0.0);
  m.dwell(10.0);  // any still position counts (nothing expected); 10 s give one capture
  EXPECT_EQ(m.captures.size(), 1u);
  EXPECT_FALSE(m.trigger.armed());
  m.move_to(30.0, 0.0);
  m.dwell(0.5);
  const auto c = m.trigger.capture_now();  // the operator presses the key
  ASSERT_TRUE(c);
  EXPECT_TRUE(c->manual);
  EXPECT_NEAR(c->mean_mm, 30.0, 0.05e-3);
  EXPECT_EQ(c->approach, Approach::from_below);
  m.dwell(3.0);  // the same stop is not captured again
  EXPECT_EQ(m.captures.size(), 1u);
}

TEST(PositionTrigger, RefusesBadSettings) {
  EXPECT_THROW(PositionTrigger({.tolerance_um = -1}), cal::InputError);
  EXPECT_THROW(PositionTrigger({.dwell_s = 0}), cal::InputError);
  EXPECT_THROW(PositionTrigger({.average_fraction = 1.5}), cal::InputError);
}

}  // namespace

// Issue 29: a held trigger (a paused run) captures nothing by itself, however long the stop,
// and keeps only the newest dwell for a capture by hand; rearm() measures a stop anew.
TEST(StabilityTrigger, HeldCapturesNothingButByHandAndRearmMeasuresAgain) {
  Stream s({.tolerance_um = 1.0, .dwell_s = 1.5, .window_mm = 0.5}, 0.1);
  s.trigger.hold(true);
  s.move_to(20.0);
  s.dwell(10.0);
  EXPECT_TRUE(s.captures.empty());
  const auto c = s.trigger.capture_now();
  ASSERT_TRUE(c);
  EXPECT_TRUE(c->manual);
  EXPECT_NEAR(c->mean_mm, 20.0, 0.05e-3);
  EXPECT_NEAR(static_cast<double>(c->end_ns - c->start_ns) * 1e-9, 1.5, 0.01);  // the last dwell
  s.trigger.hold(false);
  s.dwell(3.0);
  EXPECT_TRUE(s.captures.empty());  // captured by hand: this stop is not taken again...
  s.trigger.rearm();                // ...unless the operator measures it again
  s.dwell(3.0);
  ASSERT_EQ(s.captures.size(), 1u);
  EXPECT_FALSE(s.captures[0].manual);
  EXPECT_NEAR(s.captures[0].mean_mm, 20.0, 0.05e-3);
}

TEST(PositionTrigger, HeldCapturesNothingButByHand) {
  FedMachine m({.tolerance_um = 1.0, .dwell_s = 1.5});
  m.trigger.hold(true);
  m.move_to(10.0, 0.0);
  m.dwell(10.0);
  EXPECT_TRUE(m.captures.empty());
  ASSERT_TRUE(m.trigger.capture_now());
  m.trigger.hold(false);
  m.trigger.rearm();
  m.dwell(3.0);
  EXPECT_EQ(m.captures.size(), 1u);
}
