#pragma once
// Stop detection for ISO 230-2 (pipeline stage; plain C++, time comes with each reading).
//
// Stability trigger: the machine is stopped at a target when every valid reading of the last
// `dwell_s` lies within a band of +/- tolerance_um around their mean, the window really
// spans dwell_s, and the mean lies within window_mm of the expected target (when one is
// given). The capture is that window: mean, standard deviation, count, start and end. The
// trigger then disarms until the position leaves the band by 10 tolerances, so one stop gives
// one capture however long the dwell. The capture's mean and standard deviation are over the
// newest `average_fraction` of the window (see TriggerSettings). Signal-lost readings never count
// as stable (they break the window).
//
// The approach direction is taken from where the axis was before the stop: the last reading
// more than 10 tolerances away from the stop, within the preceding `approach_s`.
//
// A manual trigger ("capture now", from the keyboard) captures the last window as it is; a
// position-assisted trigger (PositionTrigger) uses a machine position feed instead: stopped
// when the fed position has not changed by more than the tolerance for the dwell.
#include <cstdint>
#include <deque>
#include <optional>

namespace cal::daq {

struct TriggerSettings {
  double tolerance_um = 1.0;
  double dwell_s = 1.5;
  double window_mm = 0.5;
  double approach_s = 10.0;
  // The capture averages the newest part of the stable window only: the first readings of a
  // stop still carry the end of the servo's settling (an exponential approach from the side
  // of travel), which would bias up and down stops apart by a few hundredths of a um.
  double average_fraction = 0.5;
};

enum class Approach { from_below, from_above, unknown };

struct Capture {
  std::int64_t start_ns = 0, end_ns = 0;
  double mean_mm = 0.0;
  double std_um = 0.0;
  std::size_t count = 0;
  Approach approach = Approach::unknown;
  bool manual = false;
};

class StabilityTrigger {
 public:
  explicit StabilityTrigger(TriggerSettings settings);  // throws cal::InputError if <= 0

  // The target the machine is expected to stop at next (nullopt: any position).
  void expect(std::optional<double> position_mm) { expected_mm_ = position_mm; }
  // One reading; returns a capture when this reading completes a stop.
  std::optional<Capture> add(std::int64_t time_ns, double position_mm, bool valid = true);
  // Manual trigger: the current window (if it holds any reading), whatever its spread.
  std::optional<Capture> capture_now();
  bool armed() const { return armed_; }

 private:
  Capture make_capture(bool manual) const;
  Approach approach_to(double mean_mm, std::int64_t before_ns) const;

  TriggerSettings s_;
  std::int64_t dwell_ns_, approach_ns_;
  std::optional<double> expected_mm_;
  std::deque<std::pair<std::int64_t, double>> window_;   // the current candidate window
  std::deque<std::pair<std::int64_t, double>> history_;  // approach_s of past positions
  // Monotonic deques of the window's min and max (O(1) per reading at 10 kHz), keyed by the
  // reading's sequence number (timestamps may repeat).
  std::deque<std::pair<std::uint64_t, double>> min_, max_;
  std::uint64_t next_seq_ = 0, front_seq_ = 0;  // sequence numbers of the window's ends
  void clear_window();
  double sum_ = 0.0, sum2_ = 0.0;
  bool armed_ = true;
  double last_capture_mm_ = 0.0;
};

}  // namespace cal::daq
