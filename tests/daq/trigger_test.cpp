// The stability trigger on synthetic streams with known stops: a staircase with noise, a
// stop shorter than the dwell, a blocked beam, the approach direction, the manual trigger.
#include "cal/daq/trigger.hpp"

#include <gtest/gtest.h>

#include <cmath>
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

}  // namespace
