// Stop detection (see trigger.hpp).
#include "cal/daq/trigger.hpp"

#include <fmt/format.h>

#include <algorithm>
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

bool near_any(std::span<const double> sorted_mm, double x_mm, double window_mm) {
  if (sorted_mm.empty()) return true;
  // The nearest target is the first at or above x or the one before it.
  const auto it = std::lower_bound(sorted_mm.begin(), sorted_mm.end(), x_mm);
  if (it != sorted_mm.end() && *it - x_mm <= window_mm) return true;
  return it != sorted_mm.begin() && x_mm - *std::prev(it) <= window_mm;
}

Approach approach_from(const std::deque<std::pair<std::int64_t, double>>& history, double stop_mm,
                       std::int64_t before_ns, double far_mm) {
  for (auto it = history.rbegin(); it != history.rend(); ++it) {
    if (it->first >= before_ns) continue;
    if (std::abs(it->second - stop_mm) > far_mm)
      return it->second < stop_mm ? Approach::from_below : Approach::from_above;
  }
  return Approach::unknown;
}

namespace {
std::vector<double> sorted(std::span<const double> positions_mm) {
  std::vector<double> v(positions_mm.begin(), positions_mm.end());
  std::sort(v.begin(), v.end());
  return v;
}
}  // namespace

void StabilityTrigger::expect(std::optional<double> position_mm) {
  expected_mm_.clear();
  if (position_mm) expected_mm_.push_back(*position_mm);
}

void StabilityTrigger::expect_any(std::span<const double> positions_mm) {
  expected_mm_ = sorted(positions_mm);
}

std::optional<Capture> StabilityTrigger::add(std::int64_t t, double x_mm, bool valid) {
  valid = valid && std::isfinite(x_mm);  // a NaN is no position
  // Only valid positions tell where the axis came from (a lost beam's value is meaningless).
  if (valid) history_.emplace_back(t, x_mm);
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
  while (max_.front().second - min_.front().second > 2 * tol_mm) drop_oldest();
  if (held_) {  // paused: the newest dwell only, for a capture by hand; none of its own
    while (window_.back().first - window_.front().first > dwell_ns_) drop_oldest();
    return std::nullopt;
  }
  if (window_.back().first - window_.front().first < dwell_ns_) return std::nullopt;
  const double mean = sum_ / static_cast<double>(window_.size());
  if (!near_any(expected_mm_, mean, s_.window_mm)) return std::nullopt;
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

void StabilityTrigger::drop_oldest() {
  const double x0 = window_.front().second;
  window_.pop_front();
  sum_ -= x0;
  sum2_ -= x0 * x0;
  if (min_.front().first == front_seq_) min_.pop_front();
  if (max_.front().first == front_seq_) max_.pop_front();
  ++front_seq_;
}

void StabilityTrigger::rearm() {
  armed_ = true;
  clear_window();
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
  return approach_from(history_, mean_mm, before_ns, 10 * s_.tolerance_um * 1e-3);
}

// ---- PositionTrigger ----

PositionTrigger::PositionTrigger(PositionTriggerSettings settings)
    : s_(settings),
      dwell_ns_(static_cast<std::int64_t>(settings.dwell_s * 1e9)),
      approach_ns_(static_cast<std::int64_t>(settings.approach_s * 1e9)) {
  if (!(s_.tolerance_um > 0) || !(s_.dwell_s > 0) || !(s_.approach_s > 0) ||
      !(s_.average_fraction > 0 && s_.average_fraction <= 1))
    throw InputError(fmt::format(
        "position trigger: tolerance {} um, dwell {} s and approach {} s must all be > 0, and "
        "the averaged fraction {} in (0, 1]",
        s_.tolerance_um, s_.dwell_s, s_.approach_s, s_.average_fraction));
}

void PositionTrigger::expect(std::optional<double> position_mm) {
  expected_mm_.clear();
  if (position_mm) expected_mm_.push_back(*position_mm);
}

void PositionTrigger::expect_any(std::span<const double> positions_mm) {
  expected_mm_ = sorted(positions_mm);
}

std::optional<Capture> PositionTrigger::add_position(std::int64_t t, double p_mm) {
  const double tol_mm = s_.tolerance_um * 1e-3;
  if (!std::isfinite(p_mm)) {  // no position: no stillness either
    still_since_ns_.reset();
    return std::nullopt;
  }
  feed_.emplace_back(t, p_mm);
  while (t - feed_.front().first > approach_ns_ + dwell_ns_) feed_.pop_front();
  if (!armed_) {
    if (std::abs(p_mm - still_mm_) <= tol_mm) return std::nullopt;  // still at the last stop
    armed_ = true;
    still_since_ns_.reset();
  }
  // Still = within the band around the first sample of the stop ("velocity zero"), and that
  // sample at an expected target ("equals a target").
  if (!still_since_ns_ || std::abs(p_mm - still_mm_) > tol_mm) {
    still_since_ns_.reset();
    if (near_any(expected_mm_, p_mm, tol_mm)) {
      still_since_ns_ = t;
      still_mm_ = p_mm;
    }
    return std::nullopt;
  }
  return try_capture(t);
}

std::optional<Capture> PositionTrigger::add_reading(std::int64_t t, double x_mm, bool valid) {
  if (!valid || !std::isfinite(x_mm)) {
    last_invalid_ns_ = std::max(last_invalid_ns_, t);
    return std::nullopt;
  }
  laser_.emplace_back(t, x_mm);
  // A capture spans at most dwell_s plus one feed period; 2 dwell_s are kept for capture_now
  // and a lagging feed.
  while (t - laser_.front().first > 2 * dwell_ns_) laser_.pop_front();
  // The feed says how long the axis has been still: the stop ends at its newest sample (the
  // laser may be ahead of a slower feed, and the axis may start moving after that sample).
  if (!armed_ || !still_since_ns_ || feed_.empty()) return std::nullopt;
  return try_capture(s_.feed_holds ? std::max(t, feed_.back().first) : feed_.back().first);
}

std::optional<Capture> PositionTrigger::try_capture(std::int64_t now_ns) {
  if (held_) return std::nullopt;
  const std::int64_t from = std::max(*still_since_ns_, last_invalid_ns_ + 1);
  if (now_ns - from < dwell_ns_) return std::nullopt;
  // Wait until the laser has caught up with the feed, so the window is not cut short.
  if (laser_.empty() || laser_.back().first < now_ns) return std::nullopt;
  auto c = make_capture(from, now_ns, false, still_mm_);
  if (c) {
    armed_ = false;
    still_since_ns_.reset();
  }
  return c;
}

void PositionTrigger::rearm() {
  armed_ = true;
  still_since_ns_.reset();
}

std::optional<Capture> PositionTrigger::capture_now() {
  if (laser_.empty()) return std::nullopt;
  const std::int64_t to = laser_.back().first;
  // The last window: the laser readings of the last dwell_s, since the beam came back, and
  // since the feed came to where it is now (when there is a feed), so a capture taken a moment
  // after the axis stopped does not average in the motion.
  std::int64_t from = std::max(to - dwell_ns_, last_invalid_ns_ + 1);
  double at_mm = laser_.back().second;
  if (!feed_.empty()) {
    at_mm = feed_.back().second;
    const double tol_mm = s_.tolerance_um * 1e-3;
    auto it = feed_.rbegin();
    while (std::next(it) != feed_.rend() && std::abs(std::next(it)->second - at_mm) <= tol_mm) ++it;
    from = std::max(from, it->first);
  }
  auto c = make_capture(from, to, true, at_mm);
  if (c && !feed_.empty()) {  // re-armed when the feed leaves this position
    armed_ = false;
    still_mm_ = at_mm;
    still_since_ns_.reset();
  }
  return c;
}

std::optional<Capture> PositionTrigger::make_capture(std::int64_t from_ns, std::int64_t to_ns,
                                                     bool manual, double at_mm) {
  // The newest average_fraction of the still window (see TriggerSettings::average_fraction).
  const double fraction = manual ? 1.0 : s_.average_fraction;
  const auto mean_from =
      to_ns - static_cast<std::int64_t>(fraction * static_cast<double>(to_ns - from_ns));
  double sum = 0.0;
  std::size_t n = 0;
  for (const auto& [t, x] : laser_)
    if (t >= mean_from && t <= to_ns) sum += x, ++n;
  if (n == 0) return std::nullopt;
  Capture c;
  c.manual = manual;
  c.start_ns = from_ns;
  c.end_ns = to_ns;
  c.count = n;
  c.mean_mm = sum / static_cast<double>(n);
  double ss = 0.0;  // sample standard deviation, two-pass (positions ~1 m, spreads ~1 um)
  for (const auto& [t, x] : laser_)
    if (t >= mean_from && t <= to_ns) ss += (x - c.mean_mm) * (x - c.mean_mm);
  c.std_um = n > 1 ? std::sqrt(ss / static_cast<double>(n - 1)) * 1e3 : 0.0;
  // The approach is judged on the feed (machine coordinates), around the fed stop position.
  c.approach = approach_from(feed_, at_mm, from_ns, 10 * s_.tolerance_um * 1e-3);
  return c;
}

}  // namespace cal::daq
