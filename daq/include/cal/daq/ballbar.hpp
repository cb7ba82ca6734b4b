#pragma once
// Ballbar acquisition (pipeline stage; plain C++): turns the stream of bar readings into the
// clockwise and counter-clockwise traces of a circular test.
//
// A ballbar has no angle sensor, so the test program's timing is the reference, as in the
// usual ballbar procedure: the machine starts `feed_in_mm` outside the radius, moves in along
// the radius (the bar shortens by feed_in_mm), dwells `dwell_s`, runs the counter-clockwise
// arc (overshoot + arc + overshoot degrees; the arc is 360 for a full circle, e.g. 220 for the
// partial arcs of the vertical planes) at the feed, dwells again, runs the clockwise arc back,
// and moves out. The stage finds the end of the feed-in (the reading settles near zero
// after having been near +feed_in), then every later sample's angle follows from the sample
// rate, the dwell, the feed and the radius; the overshoot arcs (acceleration, reversal) are
// trimmed. Samples are timed by their index at the gauge's fixed rate, not by the arrival of
// USB chunks.
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cal/analysis/circle.hpp"
#include "cal/analysis/circle_source.hpp"
#include "cal/analysis/paged_doubles.hpp"

namespace cal::daq {

struct BallbarProgram {
  double radius_mm = 100.0;
  double feed_mm_per_min = 1000.0;
  double sample_rate_hz = 1000.0;
  double feed_in_mm = 1.5;
  double dwell_s = 1.0;
  double overshoot_deg = 45.0;
  double start_deg = 0.0;  // angle of the start point (the ccw move's start), from the first axis
  double arc_deg = 360.0;  // the measured arc, 180..360; the moves add the overshoot both sides
};

// Where the stream is in the program, for the operator's display.
enum class BallbarPhase { feed_in, dwell, ccw_arc, cw_arc, complete };
std::string_view to_string(BallbarPhase p);  // "waiting for the feed-in", "ccw arc", ...

struct BallbarProgress {
  BallbarPhase phase = BallbarPhase::feed_in;
  double angle_deg = 0.0;  // programmed angle of the latest sample (in an arc)
  double fraction = 0.0;   // of the whole test after the feed-in, 0..1
};

class BallbarSegmenter {
 public:
  explicit BallbarSegmenter(BallbarProgram p);  // throws cal::InputError for bad values
  BallbarSegmenter(BallbarSegmenter&&) noexcept = default;
  BallbarSegmenter& operator=(BallbarSegmenter&&) noexcept = default;
  // One bar reading: the deviation of the bar from its calibrated length, in mm.
  void add(double deviation_mm);
  std::optional<std::size_t> feed_in_end() const { return feed_in_end_; }
  // True once both arcs (and their overshoot) have been sampled.
  bool complete() const;
  // The trimmed traces (ccw, cw); throws cal::InputError if not complete, naming what is
  // missing (no feed-in found, or how many samples short).
  std::vector<circle::Trace> traces() const;
  // The same traces read in place (circle_source.hpp): the angles from the program, the
  // deviations from the segmenter's samples, which the sources share (so they outlive the
  // segmenter). The samples are paged (paged_doubles.hpp): a run of any length holds a few
  // pages of them (issue 32). Same errors as traces().
  std::vector<circle::TraceSource> sources() const;
  double arc_duration_s() const;  // of one arc with its overshoots
  std::size_t samples() const { return values_->size(); }
  BallbarProgress progress() const;

 private:
  struct Cut {  // one trace's samples, values_[offset, offset + count), and their angles
    circle::Direction direction;
    std::size_t offset, count;
    circle::ProgramAngles angles;
  };
  std::vector<Cut> cuts() const;

  BallbarProgram p_;
  std::shared_ptr<PagedDoubles> values_ = std::make_shared<PagedDoubles>();
  bool saw_out_ = false;
  std::optional<std::size_t> feed_in_end_;
  std::size_t settle_count_ = 0;
};

}  // namespace cal::daq
