#pragma once
// What the operator sees of the axis at the machine (pipeline stage; plain C++, time comes with
// each reading): moving, settling, stable or captured, and the target the axis is at.
//
// - moving: the position is farther than the trigger's window from every target a stop could
//   be labelled at now (the sequencer's acceptable positions): the page shows a position.
// - settling: within the window of a target, but not yet still: the readings of the last
//   `still_s` are not within +/- tolerance of each other (the servo's approach, a vibration).
// - stable: within the window and still; `stable_fraction` is how much of the trigger's dwell
//   the stillness has lasted (the trigger captures when its own window of dwell_s is stable).
// - captured: the trigger captured this stop; held until the axis leaves the capture by 10
//   tolerances (the trigger's own re-arming rule), so one stop shows captured once.
// While within a window the page shows the deviation from that target. A signal-lost reading
// breaks the stillness (as it breaks the trigger's window).
//
// The indicator only describes; the StabilityTrigger alone decides what is captured.
#include <cstdint>
#include <deque>
#include <optional>
#include <span>
#include <string_view>

namespace cal::daq {

enum class Motion { moving, settling, stable, captured };
std::string_view to_string(Motion m);  // "moving", "settling", "stable", "captured"

struct MotionSettings {
  double tolerance_um = 1.0;  // the trigger's band
  double dwell_s = 1.5;       // the trigger's dwell
  double window_mm = 0.5;     // the trigger's window
  // Stillness shorter than this is still settling: a servo's approach crosses the band
  // (a few readings within tolerance) before it stops.
  double still_s = 0.2;
};

class MotionIndicator {
 public:
  explicit MotionIndicator(MotionSettings s);  // throws cal::InputError for values <= 0

  // One reading of the measured position; `targets_mm` (sorted) are the positions a stop could
  // be at now (empty: the plan is done, nothing to stop at).
  void add(std::int64_t time_ns, double position_mm, bool valid,
           std::span<const double> targets_mm);
  // The trigger captured a stop whose mean is `mean_mm` (at `target_mm`) at `time_ns`.
  void captured(double mean_mm, double target_mm, std::int64_t time_ns);

  Motion motion() const { return motion_; }
  // The target whose window holds the position (or the captured stop's target).
  std::optional<double> target_mm() const { return target_mm_; }
  double stable_fraction() const { return stable_fraction_; }

  // How the last captured stop went: from entering the window to stable (settling), and from
  // stable to the capture. The states can be shorter than the page's update period; this says
  // they happened and for how long.
  struct Timeline {
    double settling_s = 0.0, stable_s = 0.0;
  };
  std::optional<Timeline> last_stop() const { return last_stop_; }

 private:
  MotionSettings s_;
  Motion motion_ = Motion::moving;
  std::optional<double> target_mm_;
  double stable_fraction_ = 0.0;
  std::optional<double> captured_mm_, captured_target_mm_;
  // This stop's times: entering the window, and first stable.
  std::optional<std::int64_t> entered_ns_, stable_ns_;
  std::optional<Timeline> last_stop_;
  // The current stillness as the trigger judges it: a sliding window of the readings within
  // +/- tolerance of each other (the oldest dropped while the band is exceeded), with
  // monotonic deques of its minimum and maximum (O(1) per reading at 10 kHz). Readings older
  // than twice the dwell are dropped too (memory stays bounded while the axis rests);
  // `still_since_ns_` keeps the start of the stillness across that.
  struct Sample {
    std::uint64_t seq;
    std::int64_t time_ns;
    double x_mm;
  };
  std::deque<Sample> window_, min_, max_;
  std::uint64_t seq_ = 0;
  std::optional<std::int64_t> still_since_ns_;
  void reset_stillness();
};

}  // namespace cal::daq
