#pragma once
// The ISO 230-2 sequencer (pipeline stage): it knows the expected stops of the plan (its
// measure moves, in order) and labels each captured stop with its target, run and direction.
// It never guesses: a stop that matches a later expected stop of the same pass (or the first
// of the next pass) marks the ones between as missed; a stop near no expected target, or approached
// from the wrong side, is extra and ignored; a stop matching a target reported missed earlier is
// taken as out of order, with that said. Every such event is reported with the positions involved.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "cal/analysis/iso230_2.hpp"
#include "cal/analysis/iso230_2_targets.hpp"
#include "cal/daq/trigger.hpp"

namespace cal::daq {

// How a run's positions and deviations read in its events and live line: a linear axis in mm
// and µm; a rotary axis, whose positions the runner carries in the *_mm fields as degrees
// (kinds/rotary.cpp), in deg and arcsec.
struct AxisUnits {
  const char* position = "mm";
  const char* deviation = "um";
  double deviation_per_position = 1e3;  // um per mm
  double deviation_of(double at, double target) const {
    return (at - target) * deviation_per_position;
  }
};
inline constexpr AxisUnits linear_units{};
inline constexpr AxisUnits rotary_units{
    .position = "deg", .deviation = "arcsec", .deviation_per_position = 3600.0};

struct ExpectedStop {
  int target_index = 0;  // 1-based
  int run = 1;
  iso230_2::Direction direction = iso230_2::Direction::up;
  double position_mm = 0.0;
  bool captured = false;
  bool missed = false;
  bool skipped = false;       // given up by the operator: missed, and never taken late
  double deviation_um = 0.0;  // in the run's AxisUnits::deviation (arcsec on a rotary axis)
  std::int64_t time_ns = 0;
};

struct SequenceEvent {
  enum class Kind { captured, missed, extra, wrong_direction, out_of_order, complete };
  Kind kind = Kind::captured;
  std::size_t stop = 0;  // index into stops() (not meaningful for extra)
  std::string message;
};

struct Progress {
  int run = 0, runs = 0;        // run k of n (of the next expected stop)
  int target = 0, targets = 0;  // target i of m
  iso230_2::Direction direction = iso230_2::Direction::up;
  std::size_t captured = 0, expected = 0;
  std::optional<double> next_position_mm;
};

class Sequencer {
 public:
  // window_mm: how far a stop may be from its target (the trigger's window); `units`: how its
  // events name positions and deviations.
  Sequencer(const iso230_2::Plan& plan, double window_mm, AxisUnits units = linear_units);

  std::optional<double> next_expected_mm() const;
  // Every position a capture could be labelled at now: the rest of the current pass, the first
  // stop of the next pass, and the stops reported missed (sorted, no repeats). The trigger
  // must watch all of them, not just the next one: a trigger that waits for a stop the machine
  // has already passed sees nothing until the machine comes back there, in a later run, which
  // would then be labelled as this one.
  std::vector<double> acceptable_mm() const;
  std::vector<SequenceEvent> on_capture(const Capture& c);
  bool complete() const { return next_ >= stops_.size(); }
  // The index into stops() of the next expected stop (stops().size() when complete): the
  // operator's "stop k of N" is next_index() + 1 of stops().size().
  std::size_t next_index() const { return next_; }
  Progress progress() const;
  // The operator's actions (issue 29). skip(): the next expected stop is given up (missed, and
  // not taken if the machine stops there later); nullopt when the plan is complete.
  // reopen_last(): the last stop passed in plan order is expected again (its value, if it was
  // captured, is dropped; a skipped or missed one is expected again); nullopt before the first.
  // Both return the index of the stop acted on.
  std::optional<std::size_t> skip();
  std::optional<std::size_t> reopen_last();
  const std::vector<ExpectedStop>& stops() const { return stops_; }
  // The stops passed without a capture (marked missed and not captured late), in plan order.
  std::vector<std::size_t> missed() const;
  // "target 2 (45.000 deg) run 1 up".
  std::string describe(const ExpectedStop& e) const;
  const AxisUnits& units() const { return units_; }
  // The captured stops as the ISO 230-2 evaluation wants them.
  std::vector<iso230_2::Measurement> measurements() const;

 private:
  bool fits(const ExpectedStop& e, const Capture& c) const;
  std::size_t pass_end(std::size_t i) const;

  std::vector<ExpectedStop> stops_;
  double window_mm_;
  AxisUnits units_;
  int runs_ = 0, targets_ = 0;
  std::size_t next_ = 0;
};

}  // namespace cal::daq
