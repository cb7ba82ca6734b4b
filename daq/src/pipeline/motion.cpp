// Moving / settling / stable / captured for the operator's display (see motion.hpp).
#include "cal/daq/motion.hpp"

#include <algorithm>
#include <cmath>

#include "cal/analysis/enum_names.hpp"
#include "cal/analysis/error.hpp"

namespace cal::daq {

std::string_view to_string(Motion m) {
  using enum Motion;
  static constexpr EnumName<Motion> kNames[] = {
      {moving, "moving"}, {settling, "settling"}, {stable, "stable"}, {captured, "captured"}};
  static_assert(cal::names_every_value(kNames));
  return name_of(kNames, m, "moving");
}

MotionIndicator::MotionIndicator(MotionSettings s) : s_(s) {
  if (!(s.tolerance_um > 0 && s.dwell_s > 0 && s.window_mm > 0 && s.still_s > 0))
    throw InputError("motion indicator: tolerance, dwell, window and still time must be > 0");
}

void MotionIndicator::add(std::int64_t time_ns, double position_mm, bool valid,
                          std::span<const double> targets_mm) {
  const double tol_mm = s_.tolerance_um * 1e-3;
  // A captured stop stays "captured" until the axis leaves it (the trigger re-arms then too).
  if (captured_mm_ && std::abs(position_mm - *captured_mm_) <= 10 * tol_mm) {
    motion_ = Motion::captured;
    target_mm_ = captured_target_mm_;
    stable_fraction_ = 1.0;
    return;
  }
  captured_mm_.reset();
  // The nearest target whose window holds the position.
  target_mm_.reset();
  const auto it = std::lower_bound(targets_mm.begin(), targets_mm.end(), position_mm);
  double best = s_.window_mm;
  for (auto c : {it, it == targets_mm.begin() ? it : it - 1})
    if (c != targets_mm.end() && std::abs(*c - position_mm) <= best)
      best = std::abs(*c - position_mm), target_mm_ = *c;
  if (!target_mm_) entered_ns_.reset(), stable_ns_.reset();
  if (target_mm_ && !entered_ns_) entered_ns_ = time_ns;
  if (!target_mm_ || !valid) {
    motion_ = target_mm_ ? Motion::settling : Motion::moving;
    reset_stillness();
    stable_fraction_ = 0.0;
    return;
  }
  // Still: the readings since still_since within a band of 2 tolerances, as the trigger's
  // window: a reading outside the band drops the oldest ones until it holds again (so a slow
  // drift within the band is still, as the trigger sees it).
  const Sample sample{seq_++, time_ns, position_mm};
  window_.push_back(sample);
  while (!min_.empty() && min_.back().x_mm >= position_mm) min_.pop_back();
  min_.push_back(sample);
  while (!max_.empty() && max_.back().x_mm <= position_mm) max_.pop_back();
  max_.push_back(sample);
  const auto drop_oldest = [&] {
    if (min_.front().seq == window_.front().seq) min_.pop_front();
    if (max_.front().seq == window_.front().seq) max_.pop_front();
    window_.pop_front();
  };
  bool broke = false;
  while (max_.front().x_mm - min_.front().x_mm > 2 * tol_mm) drop_oldest(), broke = true;
  if (broke || !still_since_ns_) still_since_ns_ = window_.front().time_ns;
  const auto keep_ns = static_cast<std::int64_t>(2 * s_.dwell_s * 1e9);
  while (window_.size() > 1 && time_ns - window_.front().time_ns > keep_ns) drop_oldest();
  const double still_s = static_cast<double>(time_ns - *still_since_ns_) * 1e-9;
  motion_ = still_s >= std::min(s_.still_s, s_.dwell_s) ? Motion::stable : Motion::settling;
  if (motion_ == Motion::stable && (!stable_ns_ || broke)) stable_ns_ = *still_since_ns_;
  if (motion_ != Motion::stable) stable_ns_.reset();
  stable_fraction_ = std::clamp(still_s / s_.dwell_s, 0.0, 1.0);
}

void MotionIndicator::captured(double mean_mm, double target_mm, std::int64_t time_ns) {
  const auto since = [&](std::optional<std::int64_t> from, std::int64_t to) {
    return from ? std::max(0.0, static_cast<double>(to - *from) * 1e-9) : 0.0;
  };
  const auto stable_from = stable_ns_.value_or(time_ns);
  last_stop_ = Timeline{.settling_s = since(entered_ns_, stable_from),
                        .stable_s = since(stable_ns_, time_ns)};
  entered_ns_.reset(), stable_ns_.reset();
  captured_mm_ = mean_mm;
  captured_target_mm_ = target_mm;
  motion_ = Motion::captured;
  target_mm_ = target_mm;
  stable_fraction_ = 1.0;
  reset_stillness();
}

void MotionIndicator::reset_stillness() {
  window_.clear(), min_.clear(), max_.clear();
  still_since_ns_.reset();
}

}  // namespace cal::daq
