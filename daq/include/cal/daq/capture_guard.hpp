#pragma once
// The check before a capture by hand (issue 29; pipeline stage, plain C++, time comes with each
// reading). A manual capture exists for a stop the trigger cannot call stable (a vibration, a
// noisy beam), so the window's spread alone never refuses it; what refuses it is motion the
// trigger already sees:
// - the page's MOVING state (the motion indicator: farther than the window from every target),
// - the position feed (when there is one) travelling more than the tolerance in the last span_s,
// - the laser's drift: the least-squares slope of the last span_s of valid readings, times
//   span_s, above drift_tolerances tolerances (a vibration averages out of a slope; a late
//   press while the axis leaves the stop does not: 16.7 mm/s at 1000 mm/min),
// - the laser's newest reading more than the trigger's band (2 tolerances) beyond every reading
//   of the span up to departure_lag_s before it: the axis has just left where it stood (the
//   drift needs some 10 ms of motion to see it; a vibration stays within its own range).
// A refused press is forced by a second press within force_within_s (of reading time): that
// capture is taken and said to be taken while moving, so the run's record and report name it.
#include <cstdint>
#include <deque>
#include <optional>
#include <string>
#include <string_view>

#include "cal/daq/motion.hpp"

namespace cal::daq {

struct CaptureGuardSettings {
  double tolerance_um = 1.0;       // the trigger's band
  double span_s = 0.5;             // how far back the feed's travel and the laser's drift look
  double drift_tolerances = 10.0;  // drift over span_s that counts as moving (the re-arm rule)
  double force_within_s = 3.0;     // a second press within this forces the capture
  double departure_lag_s = 0.05;   // the readings a departure is judged against are this old
};

struct CaptureVerdict {
  bool take = false;          // capture now
  bool while_moving = false;  // taken although the axis moves (a forced capture)
  std::string moving;         // what says it moves ("" at rest), e.g. "drifting 8300 um/s"
};

class CaptureGuard {
 public:
  explicit CaptureGuard(CaptureGuardSettings s);  // throws cal::InputError for values <= 0

  void add_reading(std::int64_t time_ns, double position_mm, bool valid);  // the laser
  void add_feed(std::int64_t time_ns, double position_mm);  // the machine's position feed
  // The operator pressed Capture at `now_ns` (the newest reading's time), the indicator showing
  // `shown`. A refusal arms the force for force_within_s; a capture taken disarms it.
  CaptureVerdict press(std::int64_t now_ns, Motion shown);
  // Why the axis counts as moving now ("" when it does not).
  std::string moving_reason(std::int64_t now_ns, Motion shown) const;
  // The message of a refusal, with the way to force it (`key`: the page's Capture, the CLI's
  // Enter).
  std::string refusal(const std::string& moving, std::string_view key = "Capture") const;
  double force_within_s() const { return s_.force_within_s; }

 private:
  CaptureGuardSettings s_;
  std::int64_t span_ns_, lag_ns_;
  std::deque<std::pair<std::int64_t, double>> laser_, feed_;
  std::optional<std::int64_t> refused_ns_;
  static void trim(std::deque<std::pair<std::int64_t, double>>& d, std::int64_t keep_ns);
};

}  // namespace cal::daq
