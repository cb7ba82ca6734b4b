// The sequencer on hand-made captures of a small plan: 3 targets (0, 50, 100 mm), 2 runs,
// the linear bidirectional cycle, whose measure moves are by hand:
//   run 1 up: 0, 50, 100; run 1 down: 100, 50, 0; run 2 up: 0, 50, 100; run 2 down: 100, 50, 0
#include "cal/daq/sequencer.hpp"

#include <gtest/gtest.h>

namespace {

using namespace cal::daq;
using Kind = SequenceEvent::Kind;

cal::iso230_2::Plan plan() {
  return cal::iso230_2::make_plan({.first_mm = 0, .last_mm = 100, .count = 3},
                                  {.runs = 2, .overrun_mm = 5});
}

Capture at(double mm, Approach a) { return Capture{.mean_mm = mm, .approach = a}; }
constexpr auto up = Approach::from_below;
constexpr auto down = Approach::from_above;

TEST(Sequencer, LabelsAFullSequenceAndProducesTheMeasurements) {
  Sequencer s(plan(), 0.5);
  ASSERT_EQ(s.stops().size(), 12u);
  const double xs[] = {0, 50, 100, 100, 50, 0, 0, 50, 100, 100, 50, 0};
  for (int i = 0; i < 12; ++i) {
    const auto& e = s.stops()[static_cast<std::size_t>(i)];
    const auto events =
        s.on_capture(at(xs[i] + 0.002, e.direction == cal::iso230_2::Direction::up ? up : down));
    ASSERT_GE(events.size(), 1u);
    EXPECT_EQ(events[0].kind, Kind::captured) << events[0].message;
  }
  EXPECT_TRUE(s.complete());
  const auto m = s.measurements();
  ASSERT_EQ(m.size(), 12u);
  for (const auto& x : m) EXPECT_NEAR(x.deviation_um, 2.0, 1e-9);  // 0.002 mm = 2 um
  EXPECT_EQ(m[3].run, 1);
  EXPECT_EQ(m[3].direction, cal::iso230_2::Direction::down);
  EXPECT_EQ(m[3].target_mm, 100.0);
}

// The axis at rest on the first target before the program starts looks like a stop with no
// approach: it must not become run 1 up, target 1 (whose approach is from the overrun).
// The operator's manual capture is taken at face value, the plan's direction assumed.
TEST(Sequencer, AStopWithoutApproachIsIgnoredUnlessCapturedByHand) {
  Sequencer s(plan(), 0.5);
  auto events = s.on_capture(at(0.0, Approach::unknown));
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, Kind::extra);
  EXPECT_NE(events[0].message.find("without an approach move"), std::string::npos);
  EXPECT_FALSE(s.stops()[0].captured);
  Capture manual = at(0.001, Approach::unknown);
  manual.manual = true;
  events = s.on_capture(manual);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].kind, Kind::captured);
  EXPECT_NE(events[0].message.find("approach direction unknown"), std::string::npos);
  EXPECT_TRUE(s.stops()[0].captured);
}

TEST(Sequencer, ReportsMissedExtraWrongDirectionAndOutOfOrder) {
  Sequencer s(plan(), 0.5);
  EXPECT_EQ(s.on_capture(at(0.0, up))[0].kind, Kind::captured);  // run 1 up, target 1
  // 100 mm arrives while 50 mm is expected: target 2 run 1 up is missed.
  auto ev = s.on_capture(at(100.0, up));
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].kind, Kind::missed);
  EXPECT_EQ(ev[0].message, "missed target 2 (50.000 mm) run 1 up");
  EXPECT_EQ(ev[1].kind, Kind::captured);
  // A stop at 73 mm: nothing expected there.
  ev = s.on_capture(at(73.0, up));
  ASSERT_EQ(ev.size(), 1u);
  EXPECT_EQ(ev[0].kind, Kind::extra);
  EXPECT_EQ(ev[0].message, "extra stop at 73.0000 mm: no expected stop within 0.5 mm, ignored");
  // Expected next: 100 mm run 1 down, approached from above; from below it is not valid.
  ev = s.on_capture(at(100.0, up));
  EXPECT_EQ(ev[0].kind, Kind::wrong_direction) << ev[0].message;
  EXPECT_EQ(s.progress().run, 1);
  EXPECT_EQ(s.progress().target, 3);
  EXPECT_EQ(s.progress().direction, cal::iso230_2::Direction::down);
  EXPECT_EQ(s.on_capture(at(100.0, down))[0].kind, Kind::captured);
  // The missed 50 mm up is made good later (the operator jogged back): out of order.
  ev = s.on_capture(at(50.0, up));
  EXPECT_EQ(ev[0].kind, Kind::out_of_order);
  EXPECT_EQ(ev[0].message, "out of order: target 2 (50.000 mm) run 1 up");
  EXPECT_TRUE(s.stops()[1].captured);
  EXPECT_EQ(s.progress().captured, 4u);
}

}  // namespace
