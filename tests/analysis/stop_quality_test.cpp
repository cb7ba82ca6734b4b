// The quality gate of a run's stops (cal::quality::assess; docs/iso230-2.md, "Suspect stops").
#include "cal/analysis/stop_quality.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace {

using cal::quality::Stop;

// One run both ways over 6 targets, repeatable to 0.003 um (the reversal 0.002 um at every
// target but the noise), a straightness profile of a few um.
std::vector<Stop> one_run_both_ways() {
  std::vector<Stop> s;
  const double profile[] = {0.0, 1.2, 2.1, 1.7, 0.4, -0.9};
  const double noise[] = {0.001, -0.002, 0.003, 0.0, -0.001, 0.002};
  for (int k = 0; k < 6; ++k) {
    s.push_back({.target_index = k,
                 .direction = '+',
                 .nominal_mm = 100.0 * k,
                 .value = profile[k] + noise[k]});
    s.push_back({.target_index = k,
                 .direction = '-',
                 .nominal_mm = 100.0 * k,
                 .value = profile[k] - 0.002});
  }
  return s;
}

TEST(StopQuality, ARepeatableRunIsNotSuspect) {
  const auto a = cal::quality::assess(one_run_both_ways());
  EXPECT_TRUE(a.checked);
  EXPECT_EQ(a.basis, "up/down");
  EXPECT_TRUE(a.suspects.empty()) << a.summary;
  EXPECT_DOUBLE_EQ(a.limit, cal::quality::kFloor);  // 5 x ~0.002 is below the floor
  EXPECT_EQ(a.summary.rfind("ok", 0), 0u) << a.summary;
}

// The walkthrough's case: the 300 mm down stop took the 400 mm value (0.44 um off).
TEST(StopQuality, AStopWithAnotherTargetsValueIsSuspectAndNamed) {
  auto s = one_run_both_ways();
  s[7].value += 0.44;  // target 3 (300 mm), down
  const auto a = cal::quality::assess(s);
  ASSERT_EQ(a.suspects.size(), 2u) << a.summary;  // up and down disagree: both named
  EXPECT_EQ(s[a.suspects[0].stop].target_index, 3);
  EXPECT_EQ(s[a.suspects[1].stop].target_index, 3);
  EXPECT_NEAR(std::abs(a.suspects[0].residual), 0.44, 0.01);
  EXPECT_NE(a.summary.find("suspect: 2 stop(s)"), std::string::npos) << a.summary;
  EXPECT_NE(a.summary.find("run 1 down at 300 mm"), std::string::npos) << a.summary;
}

// Below the floor a difference is not suspect, however repeatable the rest (a simulated run's
// indicator digit of 0.01 um).
TEST(StopQuality, ADifferenceBelowTheFloorIsNotSuspect) {
  auto s = one_run_both_ways();
  s[7].value += 0.04;
  EXPECT_TRUE(cal::quality::assess(s).suspects.empty());
}

// Several runs: each stop against its target's other runs in the same direction; the
// reversal (backlash) between directions is not scatter. Five runs with 0.15 um of scatter
// and 4 um of backlash: nothing suspect; one stop 2 um off: that stop alone.
TEST(StopQuality, OverRunsOnlyTheStopOffItsRunsIsSuspect) {
  std::vector<Stop> s;
  const double scatter[5] = {0.1, -0.15, 0.05, 0.12, -0.08};
  for (int run = 1; run <= 5; ++run)
    for (int k = 0; k < 6; ++k)
      for (const char d : {'+', '-'})
        s.push_back({.target_index = k,
                     .run = run,
                     .direction = d,
                     .nominal_mm = 50.0 * k,
                     .value = 0.8 * k + (d == '-' ? 4.0 : 0.0) +
                              scatter[(run + k) % 5] * (d == '+' ? 1 : -1)});
  auto a = cal::quality::assess(s);
  EXPECT_EQ(a.basis, "runs");
  EXPECT_TRUE(a.suspects.empty()) << a.summary;
  s[25].value += 2.0;
  a = cal::quality::assess(s);
  ASSERT_EQ(a.suspects.size(), 1u) << a.summary;
  EXPECT_EQ(a.suspects[0].stop, 25u);
}

TEST(StopQuality, OneRunOneWayCannotBeChecked) {
  std::vector<Stop> s;
  for (int k = 0; k < 6; ++k) s.push_back({.target_index = k, .value = 0.1 * k});
  const auto a = cal::quality::assess(s);
  EXPECT_FALSE(a.checked);
  EXPECT_EQ(a.summary.rfind("not checked", 0), 0u);
}

}  // namespace
