#pragma once
// A ballbar trace as the circle analysis reads it, in bounded memory (issue 32): either a view
// of a Trace's vectors, or a trace cut from a test program's sample stream, whose angles are
// computed from the sample's index (the program's timing, as BallbarSegmenter cuts them) and
// whose deviations are read from a paged array of the stream (paged_doubles.hpp). With the
// second, analysing an hour at 10 kHz holds a few pages, not the samples. Apart from circle.hpp
// so that the many users of the analysis do not depend on it.
#include <cstddef>
#include <memory>
#include <span>

#include "cal/analysis/circle.hpp"
#include "cal/analysis/circle_records.hpp"
#include "cal/analysis/paged_doubles.hpp"

namespace cal::circle {

// angle(j) = start_deg + rate_deg_s * ((first + j) / sample_rate_hz - arc_start_s), the rate
// signed by the direction: the same operations, so the same values, as the segmenter's.
struct ProgramAngles {
  double start_deg = 0.0, rate_deg_s = 0.0, arc_start_s = 0.0, sample_rate_hz = 1.0;
  std::size_t first = 0;
  double at(std::size_t j) const {
    const double t_s = static_cast<double>(first + j) / sample_rate_hz;
    return start_deg + rate_deg_s * (t_s - arc_start_s);
  }
};

class TraceSource {
 public:
  // A view of t's vectors (t must outlive the source).
  explicit TraceSource(const Trace& t)
      : direction_(t.direction),
        size_(t.angle_deg.size()),
        deviations_(t.deviation_um.size()),
        angles_(t.angle_deg.data()),
        devs_(t.deviation_um.data()) {}
  // `count` samples: angles from the program, deviation j = values[offset + j] * scale.
  TraceSource(Direction d, std::size_t count, ProgramAngles angles,
              std::shared_ptr<const PagedDoubles> values, std::size_t offset, double scale)
      : direction_(d),
        size_(count),
        deviations_(count),
        program_(angles),
        values_(std::move(values)),
        offset_(offset),
        scale_(scale) {}

  Direction direction() const { return direction_; }
  std::size_t size() const { return size_; }
  std::size_t deviation_count() const { return deviations_; }  // differs only in a bad Trace
  double angle_deg(std::size_t j) const { return angles_ ? angles_[j] : program_.at(j); }
  double deviation_um(std::size_t j) const {
    return devs_ ? devs_[j] : (*values_)[offset_ + j] * scale_;
  }

 private:
  Direction direction_;
  std::size_t size_, deviations_;
  const double* angles_ = nullptr;
  const double* devs_ = nullptr;
  ProgramAngles program_;
  std::shared_ptr<const PagedDoubles> values_;
  std::size_t offset_ = 0;
  double scale_ = 1.0;
};

// analyse() of traces read from their sources. Every per-sample value the analysis derives (the
// residual, the high-passed residual, each found diagnostic's contribution) is a PagedDoubles
// with `pages`, so with program sources its memory does not grow with the run. The results are
// those of analyse(setup, traces) on the same samples, bit for bit.
Result analyse(const Setup& setup, std::span<const TraceSource> traces,
               std::size_t records_held_max_samples = fit_records_held_max_samples,
               PageOptions pages = {});

}  // namespace cal::circle
