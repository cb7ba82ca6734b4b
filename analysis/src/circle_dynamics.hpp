#pragma once
// Stick-slip and vibration from the residual of the circle's geometric model (circle.cpp):
// caldaq's own definitions, since no public source says how ballbar software detects them
// (docs/circle.md, "Stick-slip and vibration"). Private to the analysis library.
//
// Time along a trace: the tool runs at the feed F along the circle of radius R, so a sample at
// angle theta is t = s (theta - theta_first) R / F after the first one (s = +1 ccw, -1 cw). One
// revolution lasts 2 pi R / F; its frequency f0 = F / (2 pi R) is "the frequency of the feed":
// the geometric terms sit at 1 and 2 f0 (and a few more harmonics), so only the band above
// 10 f0 is searched for a vibration.
#include <numbers>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "cal/analysis/circle_source.hpp"
#include "cal/analysis/paged_doubles.hpp"

namespace cal::circle::dynamics {

struct TraceResidual {
  double s = 1.0;                      // +1 ccw, -1 cw
  const TraceSource* trace = nullptr;  // the trace's own angles (read in place: no copy)
  PagedDoubles r_um;                   // what the geometric model left
  double theta_rad(std::size_t j) const { return trace->angle_deg(j) * (std::numbers::pi / 180.0); }
};

struct Settings {
  double radius_mm = 100.0;
  double feed_mm_per_min = 1000.0;
  double window_deg = 10.0;  // stick-slip: the low-speed window about each reversal of an axis
  // Vibration: the spectrum is averaged over segments of at most this many samples (Welch), so
  // its memory does not grow with the run; a trace no longer than this is one segment.
  std::size_t segment_samples = 131072;
  PageOptions pages;      // of every per-sample array made (issue 32)
  char u = 'X', v = 'Y';  // the plane's axes, for the names
};

struct Found {
  std::string key, name, unit;
  double value = 0.0;
  std::optional<double> frequency_hz;
  PagedDoubles contribution;  // every sample of every trace, traces in the given order
};

struct Dynamics {
  // The strongest narrow-band component above 10 f0 when it stands out of the residual's noise
  // in every trace; its fitted contribution is subtracted from the traces. Notes say what was
  // searched and why nothing was reported when a candidate was refused.
  std::optional<Found> vibration;
  // Per axis, the high-frequency residual concentrated where that axis moves slowly (about its
  // reversals), in excess of the rest of the circle: found in what the vibration leaves.
  std::vector<Found> stick_slip;
};

// Both, each trace's time base (its travel order and median step) made once for the two.
Dynamics vibration_and_stick_slip(const Settings& s, std::vector<TraceResidual>& traces,
                                  std::vector<std::string>& notes);

}  // namespace cal::circle::dynamics
