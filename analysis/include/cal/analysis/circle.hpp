#pragma once
// ISO 230-4 circular tests and ballbar diagnostics (theory, sign conventions and sources:
// docs/circle.md).
//
// Input: the radial deviation of the tool from the nominal radius, as a telescoping ballbar
// measures it (bar length minus its calibrated length), for a clockwise and/or a
// counter-clockwise trace, at known angles. A real ballbar has no angle sensor: angles are
// derived from time, feed and radius (angles_from_time).
//
// Results:
// - ISO 230-4: circular deviation G (bidirectional and per direction; two concentric circles
//   about the least-squares centre), circular hysteresis H (largest radial difference of the
//   two directions at one angle, common centre), radial deviation F max/min (from the nominal
//   radius, about the least-squares centre), the least-squares centre.
// - Diagnostics: a linear least-squares fit of a first-order error model of a two-axis
//   machine (each term derived in circle.cpp): centre offset, radius error, scale mismatch,
//   squareness, servo mismatch (a time lag between the axes), backlash and lateral play per
//   axis, reversal spikes per axis, cyclic error per axis, straightness (a bow of each axis
//   along the other); and from the residual of that model, stick-slip per axis and a vibration
//   (caldaq's own definitions, circle_dynamics.cpp). Each is reported with the peak-to-valley
//   of its fitted contribution and its share of the circularity, ranked.
//
// Units: angles in degrees in the interface, lengths mm (radius) and um (deviations).
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace cal::circle {

enum class Plane { xy, yz, zx };   // first/second axis: X/Y, Y/Z, Z/X (G17, G19, G18)
enum class Direction { cw, ccw };  // seen from the positive third axis

struct Trace {
  Direction direction = Direction::ccw;
  std::vector<double> angle_deg;     // angle of each sample from the first axis towards the second
  std::vector<double> deviation_um;  // measured radius minus the nominal (calibrated) radius
};

struct Setup {
  Plane plane = Plane::xy;
  double radius_mm = 100.0;         // nominal (programmed) radius
  double feed_mm_per_min = 1000.0;  // needed for the servo-mismatch time and time-based angles
  // Cyclic-error period along the axes: fixed, or searched over [min, max] when unset.
  std::optional<double> cyclic_period_mm;
  double cyclic_search_min_mm = 2.0, cyclic_search_max_mm = 40.0;
  double spike_decay_deg = 6.0;  // decay angle of a reversal spike
  // Stick-slip: the window about each reversal of an axis, in degrees (the axis moves slower
  // than feed * sin(window) there); 1 < window <= 45.
  double stick_slip_window_deg = 10.0;
  bool radius_calibrated = true;  // the bar length is known (calibrator): radius error valid
  // The bar length at which deviation_um reads 0 (the calibrated length of the bar); unset: the
  // nominal radius. The deviation from the nominal radius is deviation_um + (this - radius_mm).
  std::optional<double> calibrated_radius_mm;
  // The test program, for angles derived from time (trace_from_time, trace_from_samples):
  double sample_rate_hz = 1000.0;
  double start_deg = 0.0;      // where the ccw arc move starts (the end of the feed-in)
  double arc_deg = 360.0;      // the measured arc, 180..360
  double overshoot_deg = 0.0;  // run before and after the measured arc, trimmed
  // The vibration's spectrum: a trace (resampled to its time step) of at most this many samples
  // is one periodogram; a longer one is cut into segments of this many, half overlapping, whose
  // periodograms are averaged (Welch), so the spectrum's memory does not grow with the run
  // (issue 32). At least 256. The default holds 131 s at 1 kHz, 13 s at 10 kHz.
  std::size_t vibration_segment_samples = 131072;
};

// theta(t) = start + s * (feed / R) * t, s = +1 ccw, -1 cw: the tool moves at the feed along
// the circle (after the feed-in and overshoot arcs have been trimmed).
std::vector<double> angles_from_time(std::span<const double> time_s, double start_deg,
                                     double feed_mm_per_min, double radius_mm, Direction d);

// One arc move of the test program, timed from the start of that move (t = 0 where the arc
// starts, overshoot included). The ccw move starts at setup.start_deg; the cw move starts where
// the ccw one ended, start + arc + 2 overshoot, and runs back. Both measure the same arc
// [start + overshoot, start + overshoot + arc]:
//   theta(t) = theta_move + s (F / R) t,  theta_move = start (ccw), start + arc + 2 os (cw);
// samples in the overshoot arcs (where the axes accelerate) are dropped. Throws InputError for
// mismatched lengths, a bad feed, radius, arc or overshoot, or fewer than 20 samples kept.
Trace trace_from_time(const Setup& setup, Direction d, std::span<const double> time_s,
                      std::span<const double> deviation_um);
// The same with the samples taken at setup.sample_rate_hz from t = 0: t_i = i / rate.
Trace trace_from_samples(const Setup& setup, Direction d, std::span<const double> deviation_um);

struct Iso230_4 {
  double G_bi_um = 0, G_cw_um = 0, G_ccw_um = 0;  // 0 when that direction was not measured
  double H_um = 0;                                // needs both directions
  double F_max_um = 0, F_min_um = 0;
  double centre_u_um = 0, centre_v_um = 0;  // least-squares centre relative to the pivot
  double arc_deg = 360;                     // the smallest arc measured
};

struct Diagnostic {
  std::string key;       // stable id, e.g. "squareness"
  std::string name;      // e.g. "Squareness XY"
  double value = 0;      // in `unit`
  std::string unit;      // "um", "um/m", "ms", "mm"
  double pv_um = 0;      // peak-to-valley of its fitted contribution over the traces
  double share_pct = 0;  // pv_um / G_bi, in % (can exceed 100: contributions partly cancel)
  // G_bi minus the G_bi of the traces with this contribution removed (LSQ circle refitted):
  // what correcting this error alone would gain. Can be negative.
  double g_reduction_um = 0;
  std::optional<double> frequency_hz;  // a vibration's frequency
};

struct Result {
  Iso230_4 iso;
  // Ranked by g_reduction_um, the largest gain first (centre excluded); a negative gain (a
  // term that partly cancels another) comes last.
  std::vector<Diagnostic> diagnostics;
  Diagnostic centre_u, centre_v;           // reported apart: set-up, not machine, errors
  double residual_rms_um = 0;              // what the model leaves unexplained
  std::optional<double> cyclic_period_mm;  // the period used (given or found)
  std::vector<std::string> notes;          // e.g. which terms one direction cannot separate
};

// Throws cal::InputError for no trace, an empty trace, mismatched lengths, fewer than 20
// samples, radius or feed <= 0, non-finite values, an arc below 180 degrees, or two traces in
// one direction.
Result analyse(const Setup& setup, std::span<const Trace> traces);

}  // namespace cal::circle
