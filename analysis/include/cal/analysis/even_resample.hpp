#pragma once
// A series sampled at rising times, resampled to an even step by linear interpolation, handed
// out in consecutive pieces, and cut into overlapping (Welch) segments that keep their overlap
// instead of resampling it again: the ballbar's vibration spectrum (circle_dynamics.cpp,
// issue 32). Header-only: the times and values are read through callables, in the caller's
// order, without a copy.
#include <algorithm>
#include <cstddef>
#include <vector>

namespace cal {

// The values at the times k dt, k = 0, 1, 2, ..., from n >= 1 samples (time(j), value(j)),
// j = 0 .. n - 1, times not falling: at time a, between samples j and j + 1 where j is the last
// sample whose successor is before a (0 at most, n - 2 at least), the fraction
// (a - t_j) / (t_j+1 - t_j) clamped to [0, 1] (0 where the two times are equal). Each sample's
// time and value are read once, when the walk reaches it.
template <class Time, class Value>
class EvenResampler {
 public:
  EvenResampler(std::size_t n, double dt, Time time, Value value)
      : n_(n), dt_(dt), time_(std::move(time)), value_(std::move(value)) {
    if (n_ == 0) return;
    const std::size_t b = std::min<std::size_t>(1, n_ - 1);
    ta_ = time_(0), tb_ = time_(b), va_ = value_(0), vb_ = value_(b);
  }

  // The next `count` values into out[0, count).
  void next(std::size_t count, double* out) {
    for (std::size_t c = 0; c < count; ++c, ++k_) {
      const double at = static_cast<double>(k_) * dt_;
      while (j_ + 2 < n_ && tb_ < at) {  // sample j + 1 is before `at`: on to the next pair
        ++j_;
        ta_ = tb_, va_ = vb_, tb_ = time_(j_ + 1), vb_ = value_(j_ + 1);
      }
      const double f = tb_ > ta_ ? std::clamp((at - ta_) / (tb_ - ta_), 0.0, 1.0) : 0.0;
      out[c] = va_ + f * (vb_ - va_);
    }
  }

 private:
  std::size_t n_;
  double dt_;
  Time time_;
  Value value_;
  std::size_t k_ = 0, j_ = 0;  // the next time step; the pair (j, j + 1)
  double ta_ = 0.0, tb_ = 0.0, va_ = 0.0, vb_ = 0.0;
};

// The resampled series' `count` segments of `len` values, the k-th from value k hop (hop <=
// len), each into `segment` and then given to f(segment): a segment's first len - hop values
// are the last segment's last ones, moved, not resampled again.
template <class Resampler, class F>
void overlapping_segments(Resampler& r, std::size_t count, std::size_t len, std::size_t hop,
                          std::vector<double>& segment, F&& f) {
  segment.resize(len);
  for (std::size_t k = 0; k < count; ++k) {
    if (k == 0) {
      r.next(len, segment.data());
    } else {  // values [k hop, k hop + len): the last segment's from hop on, then hop more
      std::copy(segment.begin() + static_cast<std::ptrdiff_t>(hop), segment.end(), segment.begin());
      r.next(hop, segment.data() + (len - hop));
    }
    f(segment);
  }
}

}  // namespace cal
