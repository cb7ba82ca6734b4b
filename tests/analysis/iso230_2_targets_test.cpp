#include "cal/analysis/iso230_2_targets.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <tuple>

#include "cal/analysis/error.hpp"

namespace {

using namespace cal::iso230_2;

TEST(Targets, UniformByIntervalAndByCount) {
  TargetSpec s{.first_mm = 0, .last_mm = 500, .interval_mm = 100.0};
  EXPECT_EQ(generate_targets(s), (std::vector<double>{0, 100, 200, 300, 400, 500}));
  s.interval_mm.reset();
  s.count = 5;
  EXPECT_EQ(generate_targets(s), (std::vector<double>{0, 125, 250, 375, 500}));
}

TEST(Targets, RandomOffsetsAreReproducibleBoundedAndKeepTheEnds) {
  TargetSpec s{.first_mm = -200,
               .last_mm = 800,
               .interval_mm = 50.0,
               .count = std::nullopt,
               .random_fraction = 0.3,
               .seed = 17};
  const auto a = generate_targets(s);
  const auto b = generate_targets(s);
  EXPECT_EQ(a, b);  // same seed, same targets
  ASSERT_EQ(a.size(), 21u);
  EXPECT_DOUBLE_EQ(a.front(), -200.0);
  EXPECT_DOUBLE_EQ(a.back(), 800.0);
  int moved = 0;
  std::set<double> phases;  // the offsets must not share one phase of a 50 mm period
  for (std::size_t i = 1; i + 1 < a.size(); ++i) {
    const double nominal = -200.0 + 50.0 * static_cast<double>(i);
    EXPECT_LE(std::abs(a[i] - nominal), 0.3 * 50.0 + 0.0005) << i;
    EXPECT_NEAR(a[i] * 1000.0, std::round(a[i] * 1000.0), 1e-6);  // on the 0.001 mm grid
    if (std::abs(a[i] - nominal) > 0.001) ++moved;
    phases.insert(std::round(std::fmod(a[i] + 1000.0, 50.0)));
  }
  EXPECT_GE(moved, 17);
  EXPECT_GE(phases.size(), 10u);
  s.seed = 18;
  EXPECT_NE(generate_targets(s), a);
}

TEST(Targets, BadSpecsAreRefused) {
  EXPECT_THROW(generate_targets({.first_mm = 10, .last_mm = 0, .interval_mm = 1.0}),
               cal::InputError);
  EXPECT_THROW(generate_targets({.first_mm = 0, .last_mm = 100}), cal::InputError);  // neither
  EXPECT_THROW(generate_targets({.first_mm = 0, .last_mm = 100, .interval_mm = 30.0}),
               cal::InputError);  // 30 does not divide 100
  EXPECT_THROW(generate_targets({.first_mm = 0, .last_mm = 100, .interval_mm = -10.0}),
               cal::InputError);
  EXPECT_THROW(
      generate_targets({.first_mm = 0, .last_mm = 100, .interval_mm = std::nullopt, .count = 1}),
      cal::InputError);
  EXPECT_THROW(generate_targets({.first_mm = 0,
                                 .last_mm = 100,
                                 .interval_mm = 10.0,
                                 .count = std::nullopt,
                                 .random_fraction = 0.5}),
               cal::InputError);
}

// Every measure move must be approached from its own side: an up approach comes from a
// lower position, a down approach from a higher one. And each (target, run, direction)
// is measured exactly once.
void check_plan(const Plan& p, const CycleSpec& c) {
  std::set<std::tuple<int, int, Direction>> seen;
  double pos = p.moves.front().position_mm;
  ASSERT_NE(p.moves.front().kind, MoveKind::measure);
  for (std::size_t k = 1; k < p.moves.size(); ++k) {
    const auto& m = p.moves[k];
    if (m.kind == MoveKind::measure) {
      if (m.direction == Direction::up) {
        EXPECT_LT(pos, m.position_mm) << "move " << k;
      } else {
        EXPECT_GT(pos, m.position_mm) << "move " << k;
      }
      EXPECT_DOUBLE_EQ(m.position_mm, p.targets_mm[m.target_index - 1]);
      EXPECT_TRUE(seen.insert({m.target_index, m.run, m.direction}).second) << "move " << k;
    }
    pos = m.position_mm;
  }
  const std::size_t dirs = c.bidirectional ? 2 : 1;
  EXPECT_EQ(seen.size(), p.targets_mm.size() * static_cast<std::size_t>(c.runs) * dirs);
}

TEST(Plan, LinearCycleOrder) {
  const TargetSpec t{.first_mm = 0, .last_mm = 400, .interval_mm = 100.0};
  const CycleSpec c{.cycle = Cycle::linear, .bidirectional = true, .runs = 5, .overrun_mm = 3};
  const auto p = make_plan(t, c);
  check_plan(p, c);
  // 1 reposition + 5 runs x (5 up + overrun + 5 down + overrun)
  ASSERT_EQ(p.moves.size(), 1u + 5u * 12u);
  EXPECT_DOUBLE_EQ(p.moves[0].position_mm, -3.0);
  EXPECT_EQ(p.moves[1].target_index, 1);
  EXPECT_EQ(p.moves[5].target_index, 5);
  EXPECT_EQ(p.moves[6].kind, MoveKind::overrun);
  EXPECT_DOUBLE_EQ(p.moves[6].position_mm, 403.0);
  EXPECT_EQ(p.moves[7].target_index, 5);
  EXPECT_EQ(p.moves[7].direction, Direction::down);
  EXPECT_EQ(p.moves[13].run, 2);
  EXPECT_TRUE(p.warnings.empty());
}

TEST(Plan, EveryCycleApproachesFromTheRightSide) {
  const TargetSpec t{.first_mm = 0,
                     .last_mm = 1000,
                     .interval_mm = 100.0,
                     .count = std::nullopt,
                     .random_fraction = 0.2,
                     .seed = 3};
  for (auto cyc : {Cycle::linear, Cycle::pendulum, Cycle::pilgrim_step}) {
    for (bool bi : {true, false}) {
      if (cyc == Cycle::pilgrim_step && !bi) continue;
      const CycleSpec c{.cycle = cyc, .bidirectional = bi, .runs = 5, .overrun_mm = 2};
      SCOPED_TRACE(std::string(to_string(cyc)) + (bi ? " bidirectional" : " unidirectional"));
      check_plan(make_plan(t, c), c);
    }
  }
}

TEST(Plan, PendulumVisitsOneTargetAtATime) {
  const auto p = make_plan({.first_mm = 0, .last_mm = 400, .interval_mm = 100.0},
                           {.cycle = Cycle::pendulum, .runs = 5});
  // The first 10 measurements are all at target 1, alternating up and down.
  int k = 0;
  for (const auto& m : p.moves) {
    if (m.kind != MoveKind::measure) continue;
    if (k >= 10) break;
    EXPECT_EQ(m.target_index, 1);
    EXPECT_EQ(m.direction, k % 2 == 0 ? Direction::up : Direction::down);
    ++k;
  }
}

TEST(Plan, RecommendationsBecomeWarningsAndBadSpecsErrors) {
  const auto p = make_plan({.first_mm = 0, .last_mm = 2000, .interval_mm = 500.0},
                           {.cycle = Cycle::linear, .runs = 3});
  ASSERT_EQ(p.warnings.size(), 2u);  // 3 runs < 5; 5 targets over 2 m < 5 per metre
  EXPECT_NE(p.warnings[0].find("3 runs"), std::string::npos);
  EXPECT_THROW(make_plan({.first_mm = 0, .last_mm = 10, .interval_mm = 1.0}, {.runs = 0}),
               cal::InputError);
  EXPECT_THROW(make_plan({.first_mm = 0, .last_mm = 10, .interval_mm = 1.0}, {.overrun_mm = -1}),
               cal::InputError);
  EXPECT_THROW(make_plan({.first_mm = 0, .last_mm = 10, .interval_mm = 1.0},
                         {.cycle = Cycle::pilgrim_step, .bidirectional = false}),
               cal::InputError);
  EXPECT_EQ(cycle_from_string("pilgrim-step"), Cycle::pilgrim_step);
  EXPECT_THROW(cycle_from_string("zigzag"), cal::InputError);
}

// ISO 230-2 over 2000 mm: targets an average of 250 mm apart, one run per direction allowed.
// 3000 mm: 3000 / 250 = 12 intervals, 13 targets; 2600 mm: ceil(10.4) = 11 intervals, 12 targets
// (236.4 mm apart); exactly 2000 mm is not a long axis.
TEST(Iso230_2Targets, LongAxisRule) {
  EXPECT_TRUE(is_long_axis(0.0, 2000.001));
  EXPECT_FALSE(is_long_axis(0.0, 2000.0));
  EXPECT_EQ(long_axis_target_count(0.0, 3000.0), 13);
  EXPECT_EQ(long_axis_target_count(100.0, 2700.0), 12);
  const auto t = generate_targets({.first_mm = 0.0, .last_mm = 3000.0});  // neither given
  ASSERT_EQ(t.size(), 13u);
  EXPECT_DOUBLE_EQ(t[1], 250.0);
  EXPECT_DOUBLE_EQ(t.back(), 3000.0);
  EXPECT_THROW(generate_targets({.first_mm = 0.0, .last_mm = 1500.0}), cal::InputError);
  // One run per direction over 3000 mm at 250 mm: no warning, a note naming the rule.
  const auto p = make_plan({.first_mm = 0.0, .last_mm = 3000.0}, {.runs = 1});
  EXPECT_TRUE(p.warnings.empty()) << p.warnings.front();
  ASSERT_EQ(p.notes.size(), 1u);
  EXPECT_NE(p.notes[0].find("6.2"), std::string::npos) << p.notes[0];
  // Targets 500 mm apart on the long axis: a warning with the count that would do.
  const auto sparse =
      make_plan({.first_mm = 0.0, .last_mm = 3000.0, .interval_mm = 500.0}, {.runs = 1});
  ASSERT_EQ(sparse.warnings.size(), 1u);
  EXPECT_NE(sparse.warnings[0].find("average interval of 500.0 mm"), std::string::npos);
  EXPECT_NE(sparse.warnings[0].find("(13 targets)"), std::string::npos);
}

}  // namespace
