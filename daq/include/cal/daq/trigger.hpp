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
// when the fed (commanded or actual) position equals an expected target within the tolerance
// and has not moved by more than the tolerance (velocity zero) for the dwell; the capture is the
// laser's mean over that time.
//
// Cost per reading: O(1) amortised (monotonic min/max deques, running sums); the capture itself
// is O(window) once per stop.
#include <cstdint>
#include <deque>
#include <limits>
#include <optional>
#include <span>
#include <vector>

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
  void expect(std::optional<double> position_mm);
  // Several candidate targets (e.g. all the targets of the plan): a stop counts when its mean
  // lies within window_mm of any of them. Empty: any position.
  void expect_any(std::span<const double> positions_mm);
  // One reading; returns a capture when this reading completes a stop.
  std::optional<Capture> add(std::int64_t time_ns, double position_mm, bool valid = true);
  // Manual trigger: the current window (if it holds any reading), whatever its spread.
  std::optional<Capture> capture_now();
  // Armed again at once with an empty window, wherever the axis is: the stop is measured anew
  // after a fresh dwell (the operator's "measure again", the end of a pause).
  void rearm();
  // Held (a paused run): no automatic capture; the window keeps the newest dwell_s of stable
  // readings for capture_now.
  void hold(bool on) { held_ = on; }
  bool armed() const { return armed_; }

 private:
  Capture make_capture(bool manual) const;
  Approach approach_to(double mean_mm, std::int64_t before_ns) const;

  TriggerSettings s_;
  std::int64_t dwell_ns_, approach_ns_;
  std::vector<double> expected_mm_;                      // sorted; empty: any position
  std::deque<std::pair<std::int64_t, double>> window_;   // the current candidate window
  std::deque<std::pair<std::int64_t, double>> history_;  // approach_s of past positions
  // Monotonic deques of the window's min and max (O(1) per reading at 10 kHz), keyed by the
  // reading's sequence number (timestamps may repeat).
  std::deque<std::pair<std::uint64_t, double>> min_, max_;
  std::uint64_t next_seq_ = 0, front_seq_ = 0;  // sequence numbers of the window's ends
  void clear_window();
  void drop_oldest();  // the window's oldest reading out (sums and min/max deques kept)
  double sum_ = 0.0, sum2_ = 0.0;
  bool armed_ = true, held_ = false;
  double last_capture_mm_ = 0.0;
};

// True when x lies within `window` of one of the sorted positions (all true when empty).
bool near_any(std::span<const double> sorted_mm, double x_mm, double window_mm);

// The approach direction to a stop at `stop_mm` from the positions before `before_ns`: the
// newest one farther than far_mm from the stop. History is time-ordered (oldest first).
Approach approach_from(const std::deque<std::pair<std::int64_t, double>>& history, double stop_mm,
                       std::int64_t before_ns, double far_mm);

// Position-assisted trigger: a machine position feed (LinuxCNC halsampler, MTConnect SHDR)
// says when the axis is at a target and still; the laser readings of that time make the
// capture. Feed and laser carry timestamps of the same clock (the service's).
struct PositionTriggerSettings {
  double tolerance_um = 1.0;      // |fed position - target| and the stillness band of the feed
  double dwell_s = 1.5;           // how long the feed must be still at the target
  double approach_s = 10.0;       // how far back the approach direction is looked for
  double average_fraction = 0.5;  // as TriggerSettings: the newest part of the window only
  // The feed sends a position only when it changes (an MTConnect adapter): its last sample
  // holds until the next, so a machine dwelling at a target is still for as long as the
  // laser reads, not only until the feed's last sample. False for a periodic feed
  // (halsampler), whose newest sample bounds the stop (the axis may move after it).
  bool feed_holds = false;
};

class PositionTrigger {
 public:
  explicit PositionTrigger(PositionTriggerSettings settings);  // throws cal::InputError

  void expect(std::optional<double> position_mm);
  void expect_any(std::span<const double> positions_mm);  // empty: any still position counts
  // A sample of the position feed (machine coordinates, mm); returns a capture when the feed
  // has now been still at a target for the dwell and the laser had valid readings all along.
  std::optional<Capture> add_position(std::int64_t time_ns, double machine_mm);
  // A laser reading (the measured position, mm). A signal-lost reading restarts the dwell.
  std::optional<Capture> add_reading(std::int64_t time_ns, double laser_mm, bool valid = true);
  // Manual trigger: the laser readings of the last dwell_s, whatever the feed says.
  std::optional<Capture> capture_now();
  // Armed again at once: the feed's stillness counts from its next sample (see StabilityTrigger).
  void rearm();
  void hold(bool on) { held_ = on; }  // no automatic capture while held (capture_now works)
  bool armed() const { return armed_; }

 private:
  std::optional<Capture> try_capture(std::int64_t now_ns);
  std::optional<Capture> make_capture(std::int64_t from_ns, std::int64_t to_ns, bool manual,
                                      double at_mm);

  PositionTriggerSettings s_;
  std::int64_t dwell_ns_, approach_ns_;
  std::vector<double> expected_mm_;
  std::deque<std::pair<std::int64_t, double>> feed_;   // approach_s + dwell_s of feed samples
  std::deque<std::pair<std::int64_t, double>> laser_;  // about 2 dwell_s of valid readings
  std::optional<std::int64_t> still_since_ns_;         // the feed has been at a target since
  double still_mm_ = 0.0;                              // the fed position of that stop
  std::int64_t last_invalid_ns_ = std::numeric_limits<std::int64_t>::min();
  bool armed_ = true, held_ = false;
};

}  // namespace cal::daq
