// The sequencer on hand-made captures of a small plan: 3 targets (0, 50, 100 mm), 2 runs,
// the linear bidirectional cycle, whose measure moves are by hand:
//   run 1 up: 0, 50, 100; run 1 down: 100, 50, 0; run 2 up: 0, 50, 100; run 2 down: 100, 50, 0
#include "cal/daq/sequencer.hpp"

#include <gtest/gtest.h>

#include <algorithm>

#include "cal/daq/trigger.hpp"

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

// What the trigger watches (linear_run.cpp: expect_any(acceptable_mm())): the rest of the pass
// and the first stop of the next one, plus stops reported missed.
TEST(Sequencer, AcceptablePositionsCoverThePassAndTheMissed) {
  Sequencer s(plan(), 0.5);
  EXPECT_EQ(s.acceptable_mm(), (std::vector<double>{0, 50, 100}));  // run 1 up + 100 down
  s.on_capture(at(0.0, up));
  s.on_capture(at(100.0, up));  // 50 up missed
  // Now run 1 down (100, 50, 0) and the first of run 2 up (0), and the missed 50.
  EXPECT_EQ(s.acceptable_mm(), (std::vector<double>{0, 50, 100}));
  EXPECT_TRUE(s.stops()[1].missed);
}

// The failure this prevents, seen on a loaded machine: the first stop of a pass was refused
// (approach seen from the wrong side), and a trigger that kept waiting for that one position
// captured nothing for the rest of the pass and the next, until the machine came back to it a
// run later, which was then labelled with the wrong run. With the trigger watching every
// acceptable position, the next stop of the pass is captured and the refused one reported
// missed. Positions come as readings at 100 Hz: dwell 2 s at each stop, 1 s moves.
TEST(Sequencer, ARefusedStopDoesNotBlindTheTrigger) {
  Sequencer seq(plan(), 0.5);
  StabilityTrigger trigger({.tolerance_um = 1.0, .dwell_s = 1.0, .window_mm = 0.5});
  std::int64_t t_ns = 0;
  std::vector<SequenceEvent> events;
  const auto feed = [&](double mm, double seconds) {
    for (int i = 0; i < static_cast<int>(seconds * 100); ++i, t_ns += 10'000'000) {
      trigger.expect_any(seq.acceptable_mm());
      if (const auto c = trigger.add(t_ns, mm)) {
        const auto e = seq.on_capture(*c);
        events.insert(events.end(), e.begin(), e.end());
      }
    }
  };
  const auto move = [&](double from, double to) {
    for (int i = 1; i <= 100; ++i, t_ns += 10'000'000)
      trigger.add(t_ns, from + (to - from) * i / 100);
  };
  // Run 1 up should start at 0 from below; the machine comes down onto 0 from 20 mm instead:
  // the stop is refused as approached from the wrong side.
  feed(20.0, 0.5);
  move(20.0, 0.0);
  feed(0.0, 2.0);
  move(0.0, 50.0);
  feed(50.0, 2.0);  // run 1 up, target 2: captured, target 1 reported missed
  ASSERT_GE(events.size(), 3u);
  EXPECT_EQ(events[0].kind, Kind::wrong_direction) << events[0].message;
  EXPECT_EQ(events[1].kind, Kind::missed) << events[1].message;
  EXPECT_EQ(events[2].kind, Kind::captured) << events[2].message;
  EXPECT_TRUE(seq.stops()[1].captured);
  EXPECT_EQ(seq.stops()[1].run, 1);
}

}  // namespace

namespace {

// A dropped stop (run 2 up, 50 mm) and the plan's end: the sequencer must not say "all stops
// captured" (it did), and must list the one missed stop.
TEST(Sequencer, ADroppedStopIsListedAndTheEndDoesNotClaimEveryStop) {
  Sequencer s(plan(), 0.5);
  std::vector<SequenceEvent> last;
  for (std::size_t i = 0; i < s.stops().size(); ++i) {
    if (i == 7) continue;  // run 2 up, target 2 (50 mm): never stopped at
    const auto& e = s.stops()[i];
    last = s.on_capture(at(e.position_mm, e.direction == cal::iso230_2::Direction::up ? up : down));
  }
  EXPECT_TRUE(s.complete());
  ASSERT_FALSE(last.empty());
  EXPECT_EQ(last.back().kind, Kind::complete);
  EXPECT_EQ(last.back().message, "end of the plan: 1 of 12 stops missed");
  ASSERT_EQ(s.missed().size(), 1u);
  EXPECT_EQ(s.missed()[0], 7u);
  EXPECT_EQ(s.stops()[7].run, 2);
  EXPECT_EQ(s.stops()[7].position_mm, 50.0);
  EXPECT_EQ(s.measurements().size(), 11u);
}

}  // namespace

namespace {

// Issue 29: the operator skips a target (missed, never taken late) and measures the last stop
// again (its value dropped, expected anew).
TEST(Sequencer, ASkippedStopIsNeverTakenAndTheLastStopCanBeMeasuredAgain) {
  Sequencer s(plan(), 0.5);
  EXPECT_FALSE(s.reopen_last());  // nothing passed yet
  ASSERT_EQ(s.on_capture(at(0.001, up))[0].kind, Kind::captured);
  const auto skipped = s.skip();  // 50 mm run 1 up
  ASSERT_TRUE(skipped);
  EXPECT_EQ(*skipped, 1u);
  EXPECT_TRUE(s.stops()[1].skipped && s.stops()[1].missed);
  // The machine stops at the skipped target anyway: not taken, not even out of order.
  const auto there = s.on_capture(at(50.0, up));
  EXPECT_NE(there[0].kind, Kind::captured);
  EXPECT_NE(there[0].kind, Kind::out_of_order);
  const auto acceptable = s.acceptable_mm();
  EXPECT_EQ(std::count(acceptable.begin(), acceptable.end(), 50.0), 0) << "only the skipped one";
  ASSERT_EQ(s.on_capture(at(100.002, up))[0].kind, Kind::captured);
  EXPECT_EQ(s.next_index(), 3u);
  // Measured again: 100 mm run 1 up is expected anew, its value dropped.
  const auto again = s.reopen_last();
  ASSERT_TRUE(again);
  EXPECT_EQ(*again, 2u);
  EXPECT_FALSE(s.stops()[2].captured);
  EXPECT_EQ(s.next_expected_mm(), 100.0);
  EXPECT_EQ(s.measurements().size(), 1u);
  const auto anew = s.on_capture(at(100.004, up));
  ASSERT_EQ(anew[0].kind, Kind::captured);
  EXPECT_NEAR(s.stops()[2].deviation_um, 4.0, 1e-9);
  EXPECT_EQ(s.missed(), std::vector<std::size_t>{1});
}

}  // namespace

// A rotary axis's plan carries degrees in its *_mm fields: its events name degrees and arcsec
// (they said "target 2 (50.000 mm) ... +7.200 um" for 50 deg and 7.2").
TEST(Sequencer, ARotaryAxisEventsInDegreesAndArcsec) {
  Sequencer s(plan(), 0.5, rotary_units);
  EXPECT_EQ(s.on_capture(at(0.0, up))[0].message, "target 1 (0.000 deg) run 1 up: +0.000 arcsec");
  auto ev = s.on_capture(at(100.002, up));
  ASSERT_EQ(ev.size(), 2u);
  EXPECT_EQ(ev[0].message, "missed target 2 (50.000 deg) run 1 up");
  EXPECT_EQ(ev[1].message, "target 3 (100.000 deg) run 1 up: +7.200 arcsec");
  EXPECT_NEAR(s.stops()[2].deviation_um, 7.2, 1e-9);  // in the run's unit, arcsec
  EXPECT_EQ(s.on_capture(at(73.0, up))[0].message,
            "extra stop at 73.0000 deg: no expected stop within 0.5 deg, ignored");
}
