// Stop detection (see trigger.hpp).
#include "cal/daq/trigger.hpp"

#include <fmt/format.h>

#include <cmath>

#include "cal/analysis/error.hpp"

namespace cal::daq {

StabilityTrigger::StabilityTrigger(TriggerSettings settings)
    : s_(settings),
      dwell_ns_(static_cast<std::int64_t>(settings.dwell_s * 1e9)),
      approach_ns_(static_cast<std::int64_t>(settings.approach_s * 1e9)) {
  if (!(s_.tolerance_um > 0) || !(s_.dwell_s > 0) || !(s_.window_mm > 0) || !(s_.approach_s > 0) ||
      !(s_.average_fraction > 0 && s_.average_fraction <= 1))
    throw InputError(fmt::format(
        "trigger: tolerance {} um, dwell {} s, window {} mm and approach {} s must all be > 0, "
        "and the averaged fraction {} in (0, 1]",
        s_.tolerance_um, s_.dwell_s, s_.window_mm, s_.approach_s, s_.average_fraction));
}

std::optional<Capture> StabilityTrigger::add(std::int64_t t, double x_mm, bool valid) {
  history_.emplace_back(t, x_mm);
  while (!history_.empty() && t - history_.front().first > approach_ns_ + dwell_ns_)
    history_.pop_front();
  const double tol_mm = s_.tolerance_um * 1e-3;
  if (!armed_) {
    // Re-arm once the axis has clearly left the last stop.
    if (valid && std::abs(x_mm - last_capture_mm_) > 10 * tol_mm)
      armed_ = true;
    else
      return std::nullopt;
  }
  if (!valid) {  // a blocked beam breaks the window
    clear_window();
    return std::nullopt;
  }
  window_.emplace_back(t, x_mm);
  const std::uint64_t seq = next_seq_++;
  sum_ += x_mm;
  sum2_ += x_mm * x_mm;
  while (!min_.empty() && min_.back().second >= x_mm) min_.pop_back();
  min_.emplace_back(seq, x_mm);
  while (!max_.empty() && max_.back().second <= x_mm) max_.pop_back();
  max_.emplace_back(seq, x_mm);
  // Shrink from the front until the window is within the band: a moving axis keeps only its
  // newest readings, a stopped one accumulates.
  while (max_.front().second - min_.front().second > 2 * tol_mm) {
    const double x0 = window_.front().second;
    window_.pop_front();
    sum_ -= x0;
    sum2_ -= x0 * x0;
    if (min_.front().first == front_seq_) min_.pop_front();
    if (max_.front().first == front_seq_) max_.pop_front();
    ++front_seq_;
  }
  if (window_.back().first - window_.front().first < dwell_ns_) return std::nullopt;
  const double mean = sum_ / static_cast<double>(window_.size());
  if (expected_mm_ && std::abs(mean - *expected_mm_) > s_.window_mm) return std::nullopt;
  Capture c = make_capture(false);
  armed_ = false;
  last_capture_mm_ = c.mean_mm;
  clear_window();
  return c;
}

std::optional<Capture> StabilityTrigger::capture_now() {
  if (window_.empty()) return std::nullopt;
  Capture c = make_capture(true);
  armed_ = false;
  last_capture_mm_ = c.mean_mm;
  clear_window();
  return c;
}

void StabilityTrigger::clear_window() {
  window_.clear();
  min_.clear();
  max_.clear();
  sum_ = sum2_ = 0.0;
  front_seq_ = next_seq_;
}

Capture StabilityTrigger::make_capture(bool manual) const {
  Capture c;
  c.manual = manual;
  c.count = window_.size();
  c.start_ns = window_.front().first;
  c.end_ns = window_.back().first;
  // The newest part of the window (a manual capture takes it all).
  const double fraction = manual ? 1.0 : s_.average_fraction;
  const auto from =
      c.end_ns - static_cast<std::int64_t>(fraction * static_cast<double>(c.end_ns - c.start_ns));
  double sum = 0.0;
  std::size_t n = 0;
  for (const auto& [t, x] : window_)
    if (t >= from) sum += x, ++n;
  c.count = n;
  c.mean_mm = sum / static_cast<double>(n);
  // Sample standard deviation, around the mean (positions of order 1 m, spreads of um).
  double ss = 0.0;
  for (const auto& [t, x] : window_)
    if (t >= from) ss += (x - c.mean_mm) * (x - c.mean_mm);
  c.std_um = n > 1 ? std::sqrt(ss / static_cast<double>(n - 1)) * 1e3 : 0.0;
  c.approach = approach_to(c.mean_mm, c.start_ns);
  return c;
}

Approach StabilityTrigger::approach_to(double mean_mm, std::int64_t before_ns) const {
  const double far_mm = 10 * s_.tolerance_um * 1e-3;
  for (auto it = history_.rbegin(); it != history_.rend(); ++it) {
    if (it->first >= before_ns) continue;
    if (std::abs(it->second - mean_mm) > far_mm)
      return it->second < mean_mm ? Approach::from_below : Approach::from_above;
  }
  return Approach::unknown;
}

}  // namespace cal::daq
