// The operator's indicator (cal/daq/motion.hpp) on hand-made position sequences: what it must
// say at each reading is worked out in the comments from the settings, not taken from its own
// output.
#include "cal/daq/motion.hpp"

#include <gtest/gtest.h>

#include <vector>

#include "cal/analysis/error.hpp"

namespace {

using cal::daq::Motion;
using cal::daq::MotionIndicator;

constexpr std::int64_t ms = 1'000'000;  // ns

// tolerance 1 um, dwell 1.5 s, window 0.5 mm, still after 0.2 s.
MotionIndicator indicator() {
  return MotionIndicator({.tolerance_um = 1.0, .dwell_s = 1.5, .window_mm = 0.5, .still_s = 0.2});
}

const std::vector<double> targets{0.0, 50.0, 100.0};

TEST(MotionIndicator, FarFromEveryTargetIsMoving) {
  auto m = indicator();
  m.add(0, 25.0, true, targets);  // 25 mm from 0 and 50
  EXPECT_EQ(m.motion(), Motion::moving);
  EXPECT_FALSE(m.target_mm());
  m.add(10 * ms, 49.4, true, targets);  // 0.6 mm short of 50: outside the 0.5 mm window
  EXPECT_EQ(m.motion(), Motion::moving);
  EXPECT_EQ(to_string(m.motion()), "moving");
}

TEST(MotionIndicator, InTheWindowSettlesThenIsStable) {
  auto m = indicator();
  // Entering the window of 50 mm while still moving: readings 2 um and more apart.
  m.add(0, 49.6, true, targets);
  EXPECT_EQ(m.motion(), Motion::settling);
  ASSERT_TRUE(m.target_mm());
  EXPECT_DOUBLE_EQ(*m.target_mm(), 50.0);
  m.add(10 * ms, 49.9, true, targets);
  EXPECT_EQ(m.motion(), Motion::settling);
  // From 20 ms on, every reading within +-0.5 um of 50.0003: the band (max - min = 1 um) stays
  // within 2 tolerances. Still for 0.19 s: settling; for 0.2 s: stable.
  for (int k = 2; k <= 21; ++k) m.add(k * 10 * ms, 50.0003 + (k % 2 ? 5e-4 : -5e-4), true, targets);
  EXPECT_EQ(m.motion(), Motion::settling) << "still for 0.19 s only";
  m.add(220 * ms, 50.0003, true, targets);
  EXPECT_EQ(m.motion(), Motion::stable) << "still for 0.2 s";
  // 0.2 s of the trigger's 1.5 s dwell.
  EXPECT_NEAR(m.stable_fraction(), 0.2 / 1.5, 1e-9);
  m.add(770 * ms, 50.0003, true, targets);  // still for 0.75 s: half the dwell
  EXPECT_NEAR(m.stable_fraction(), 0.5, 1e-9);
}

TEST(MotionIndicator, AStepOfMoreThanTwoTolerancesRestartsTheStillness) {
  auto m = indicator();
  for (int k = 0; k <= 30; ++k) m.add(k * 10 * ms, 100.0, true, targets);
  EXPECT_EQ(m.motion(), Motion::stable);
  m.add(310 * ms, 100.0021, true, targets);  // 2.1 um away: more than the 2 um band
  EXPECT_EQ(m.motion(), Motion::settling);
  EXPECT_DOUBLE_EQ(m.stable_fraction(), 0.0);
}

// A slow drift within the band is still for as long as the band holds, as the trigger's sliding
// window judges it: 1 um/s for 3 s at 1 kHz with a band of 2 um (tolerance 1 um). At 3 s the
// readings from 1 s on (1.0 .. 3.0 um) are within 2 um: still for 2.0 s, 2/3 of a 3 s dwell (a
// band restarted at the newest reading when exceeded, at 2 s, would say 1.0 s).
TEST(MotionIndicator, ASlowDriftWithinTheBandIsStillAsTheTriggerSeesIt) {
  MotionIndicator m({.tolerance_um = 1.0, .dwell_s = 3.0, .window_mm = 0.5, .still_s = 0.2});
  for (int i = 0; i <= 3000; ++i) m.add(i * ms, 50.0 + i * 1e-6, true, targets);
  EXPECT_EQ(m.motion(), Motion::stable);
  EXPECT_NEAR(m.stable_fraction(), 2.0 / 3.0, 0.002);
  // Captured at 3 s: stable from 1 s (where the band that holds now begins) to 3 s.
  m.captured(50.002, 50.0, 3000 * ms);
  ASSERT_TRUE(m.last_stop());
  EXPECT_NEAR(m.last_stop()->stable_s, 2.0, 0.002);
}

TEST(MotionIndicator, SignalLostBreaksTheStillness) {
  auto m = indicator();
  for (int k = 0; k <= 30; ++k) m.add(k * 10 * ms, 0.0001, true, targets);
  EXPECT_EQ(m.motion(), Motion::stable);
  m.add(310 * ms, 0.0001, false, targets);
  EXPECT_EQ(m.motion(), Motion::settling);
  EXPECT_DOUBLE_EQ(m.stable_fraction(), 0.0);
}

TEST(MotionIndicator, CapturedIsHeldUntilTheAxisLeavesTheStop) {
  auto m = indicator();
  m.add(1000 * ms, 49.7, true, targets);                                       // enters at 1.0 s
  for (int k = 130; k <= 280; ++k) m.add(k * 10 * ms, 50.001, true, targets);  // still from 1.3 s
  m.captured(50.001, 50.0, 2800 * ms);
  EXPECT_EQ(m.motion(), Motion::captured);
  // Settling from 1.0 s (entering) to 1.3 s (still), stable from 1.3 s to the capture at 2.8 s.
  ASSERT_TRUE(m.last_stop());
  EXPECT_NEAR(m.last_stop()->settling_s, 0.3, 1e-9);
  EXPECT_NEAR(m.last_stop()->stable_s, 1.5, 1e-9);
  // Within 10 tolerances (10 um) of the capture: still captured, at its target.
  m.add(2900 * ms, 50.0099, true, targets);
  EXPECT_EQ(m.motion(), Motion::captured);
  EXPECT_DOUBLE_EQ(*m.target_mm(), 50.0);
  // 11 um away: the axis leaves; in the window still, so settling.
  m.add(3000 * ms, 50.012, true, targets);
  EXPECT_EQ(m.motion(), Motion::settling);
  m.add(3100 * ms, 52.0, true, targets);
  EXPECT_EQ(m.motion(), Motion::moving);
}

TEST(MotionIndicator, TheNearestTargetWithinTheWindow) {
  auto m = indicator();
  const std::vector<double> close{10.0, 10.6};  // 0.6 mm apart
  m.add(0, 10.35, true, close);                 // 0.35 from 10.0, 0.25 from 10.6
  ASSERT_TRUE(m.target_mm());
  EXPECT_DOUBLE_EQ(*m.target_mm(), 10.6);
  m.add(10 * ms, 10.2, true, close);  // 0.2 from 10.0
  EXPECT_DOUBLE_EQ(*m.target_mm(), 10.0);
  m.add(20 * ms, 10.0, true, {});  // nothing left to stop at
  EXPECT_EQ(m.motion(), Motion::moving);
}

TEST(MotionIndicator, RefusesSettingsThatAreNotPositive) {
  EXPECT_THROW(MotionIndicator({.tolerance_um = 0}), cal::InputError);
  EXPECT_THROW(MotionIndicator({.dwell_s = -1}), cal::InputError);
  EXPECT_THROW(MotionIndicator({.window_mm = 0}), cal::InputError);
}

}  // namespace
