#include "cal/daq/capture_guard.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "cal/analysis/error.hpp"

namespace cal::daq {

CaptureGuard::CaptureGuard(CaptureGuardSettings s) : s_(s) {
  if (!(s.tolerance_um > 0) || !(s.span_s > 0) || !(s.drift_tolerances > 0) ||
      !(s.force_within_s > 0))
    throw cal::InputError("capture guard: tolerance, span, drift and force time must be > 0");
  span_ns_ = static_cast<std::int64_t>(s.span_s * 1e9);
}

void CaptureGuard::trim(std::deque<std::pair<std::int64_t, double>>& d, std::int64_t keep_ns) {
  while (d.size() > 1 && d.back().first - d.front().first > keep_ns) d.pop_front();
}

void CaptureGuard::add_reading(std::int64_t time_ns, double position_mm, bool valid) {
  if (!valid || !std::isfinite(position_mm)) return;
  laser_.emplace_back(time_ns, position_mm);
  trim(laser_, span_ns_);
}

void CaptureGuard::add_feed(std::int64_t time_ns, double position_mm) {
  if (!std::isfinite(position_mm)) return;
  feed_.emplace_back(time_ns, position_mm);
  // One sample older than the span is kept: a feed that sends on change holds its last value.
  while (feed_.size() > 2 && feed_.back().first - feed_[1].first > span_ns_) feed_.pop_front();
}

std::string CaptureGuard::moving_reason(std::int64_t now_ns, Motion shown) const {
  if (shown == Motion::moving) return "the page shows MOVING: no target's window holds it";
  const double tol_mm = s_.tolerance_um * 1e-3;
  // The feed's travel over the span: its samples in it, and the one held into it.
  if (feed_.size() > 1) {
    const std::int64_t from_ns = now_ns - span_ns_;
    double lo = feed_.back().second, hi = lo;
    for (std::size_t i = 0; i + 1 < feed_.size(); ++i)
      if (feed_[i + 1].first > from_ns)
        lo = std::min(lo, feed_[i].second), hi = std::max(hi, feed_[i].second);
    if (hi - lo > tol_mm)
      return fmt::format("the position feed moved {:.0f} um in the last {:g} s", (hi - lo) * 1e3,
                         s_.span_s);
  }
  // The laser's drift: least-squares slope over the span (times relative to the first reading).
  if (laser_.size() >= 3) {
    const auto t0 = laser_.front().first;
    double st = 0, sx = 0, stt = 0, stx = 0;
    for (const auto& [t, x] : laser_) {
      const double ts = static_cast<double>(t - t0) * 1e-9;
      st += ts, sx += x, stt += ts * ts, stx += ts * x;
    }
    const double n = static_cast<double>(laser_.size());
    const double den = n * stt - st * st;
    if (den > 0) {
      const double slope_um_per_s = (n * stx - st * sx) / den * 1e3;
      if (std::abs(slope_um_per_s) * s_.span_s > s_.drift_tolerances * s_.tolerance_um)
        return fmt::format("the laser reads it drifting {:.0f} um/s", slope_um_per_s);
    }
  }
  return {};
}

std::string CaptureGuard::refusal(const std::string& moving, std::string_view key) const {
  return fmt::format(
      "not captured: the axis is moving ({}); capture when it has stopped, or press {} "
      "again within {:g} s to take it anyway",
      moving, key, s_.force_within_s);
}

CaptureVerdict CaptureGuard::press(std::int64_t now_ns, Motion shown) {
  CaptureVerdict v;
  v.moving = moving_reason(now_ns, shown);
  const bool forced = refused_ns_ && now_ns - *refused_ns_ >= 0 &&
                      static_cast<double>(now_ns - *refused_ns_) <= s_.force_within_s * 1e9;
  if (v.moving.empty() || forced) {
    v.take = true;
    v.while_moving = !v.moving.empty();
    refused_ns_.reset();
  } else {
    refused_ns_ = now_ns;
  }
  return v;
}

}  // namespace cal::daq
