#include "cal/daq/capture_guard.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "cal/analysis/error.hpp"

namespace cal::daq {

CaptureGuard::CaptureGuard(CaptureGuardSettings s) : s_(s) {
  if (!(s.tolerance_um > 0) || !(s.span_s > 0) || !(s.drift_tolerances > 0) ||
      !(s.force_within_s > 0) || !(s.departure_lag_s > 0) || !(s.departure_lag_s < s.span_s))
    throw cal::InputError(
        "capture guard: tolerance, span, drift and force time must be > 0, the departure's lag "
        "> 0 and shorter than the span");
  span_ns_ = static_cast<std::int64_t>(s.span_s * 1e9);
  lag_ns_ = static_cast<std::int64_t>(s.departure_lag_s * 1e9);
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
  // The axis leaving where it stood: the newest reading more than the trigger's band (2
  // tolerances) beyond every reading of the span up to departure_lag_s before it. The drift
  // above is blind to the first ~10 ms of a motion (the 0.5 s line of readings at 10 kHz tilts
  // by 4 um over the span 10 ms into a start at 2 m/s^2 to 1000 mm/min, ~100 um travelled),
  // while the trigger's window has already shrunk to the departing readings (beyond its band
  // from the rest), so a press then stored them as the stop (+10.4 um, runner_control_tests). A
  // vibration stays within its own range; the lag keeps the departure's first readings out of
  // the reference while the axis keeps moving.
  if (laser_.size() >= 2 && laser_.front().first <= laser_.back().first - lag_ns_) {
    const double x = laser_.back().second;
    double lo = laser_.front().second, hi = lo;
    for (const auto& [t, v] : laser_) {
      if (t > laser_.back().first - lag_ns_) break;  // in time order
      lo = std::min(lo, v);
      hi = std::max(hi, v);
    }
    const double beyond_mm = std::max(x - hi, lo - x);
    if (beyond_mm > 2 * tol_mm)
      return fmt::format("the laser reads it {:.1f} um from where it stood", beyond_mm * 1e3);
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
