// Ballbar stream segmentation (see ballbar.hpp).
#include "cal/daq/ballbar.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "cal/analysis/enum_names.hpp"
#include "cal/analysis/error.hpp"

namespace cal::daq {

BallbarSegmenter::BallbarSegmenter(BallbarProgram p) : p_(p) {
  if (!(p.radius_mm > 0) || !(p.feed_mm_per_min > 0) || !(p.sample_rate_hz > 0) ||
      !(p.feed_in_mm > 0) || !(p.dwell_s >= 0) || !(p.overshoot_deg >= 0) ||
      !std::isfinite(p.radius_mm + p.feed_mm_per_min + p.sample_rate_hz + p.feed_in_mm + p.dwell_s +
                     p.overshoot_deg + p.start_deg + p.arc_deg))
    throw InputError(fmt::format(
        "ballbar program: radius {} mm, feed {} mm/min, rate {} Hz and feed-in {} mm must be > 0, "
        "dwell {} s and overshoot {} deg >= 0, all finite",
        p.radius_mm, p.feed_mm_per_min, p.sample_rate_hz, p.feed_in_mm, p.dwell_s,
        p.overshoot_deg));
  if (!(p.arc_deg >= 180.0 && p.arc_deg <= 360.0))
    throw InputError(fmt::format("ballbar program: arc {} degrees must be 180..360", p.arc_deg));
}

double BallbarSegmenter::arc_duration_s() const {
  const double sweep_rad = (p_.arc_deg + 2 * p_.overshoot_deg) * std::numbers::pi / 180.0;
  return sweep_rad * p_.radius_mm / (p_.feed_mm_per_min / 60.0);
}

void BallbarSegmenter::add(double v) {
  values_->push_back(v);
  if (feed_in_end_) return;
  // The feed-in: first outside (more than half the feed-in), then settled within 5 % of it
  // around zero for 50 ms: the end of the move is where the settling began.
  if (v > 0.5 * p_.feed_in_mm) saw_out_ = true, settle_count_ = 0;
  if (!saw_out_) return;
  if (std::abs(v) < 0.05 * p_.feed_in_mm) {
    if (++settle_count_ >= static_cast<std::size_t>(0.05 * p_.sample_rate_hz) + 1) {
      feed_in_end_ = values_->size() - settle_count_;
    }
  } else {
    settle_count_ = 0;
  }
}

bool BallbarSegmenter::complete() const {
  if (!feed_in_end_) return false;
  const double needed_s = 2 * p_.dwell_s + 2 * arc_duration_s();
  return static_cast<double>(values_->size() - *feed_in_end_) >= needed_s * p_.sample_rate_hz;
}

std::vector<BallbarSegmenter::Cut> BallbarSegmenter::cuts() const {
  if (!feed_in_end_) throw InputError("ballbar: no feed-in move found in the readings");
  if (!complete())
    throw InputError(fmt::format(
        "ballbar: {} samples after the feed-in, {} needed for both arcs",
        values_->size() - *feed_in_end_,
        static_cast<std::size_t>((2 * p_.dwell_s + 2 * arc_duration_s()) * p_.sample_rate_hz)));
  const double rate_deg_s = p_.feed_mm_per_min / 60.0 / p_.radius_mm * 180.0 / std::numbers::pi;
  std::vector<Cut> out;
  for (int k = 0; k < 2; ++k) {  // ccw, then cw
    const double arc_start_s = p_.dwell_s + k * (arc_duration_s() + p_.dwell_s);
    const double s = k == 0 ? 1.0 : -1.0;
    const double first = arc_start_s + p_.overshoot_deg / rate_deg_s;
    const double last = arc_start_s + (p_.overshoot_deg + p_.arc_deg) / rate_deg_s;
    const auto i0 = static_cast<std::size_t>(std::ceil(first * p_.sample_rate_hz));
    // The samples i >= i0 with i < last * rate: for an integer i, i < ceil(last * rate).
    const auto i1 = static_cast<std::size_t>(std::ceil(last * p_.sample_rate_hz));
    // ccw starts at start_deg; cw starts where ccw ended (start + arc + 2 overshoot). The angle
    // of sample i is start + s rate (i / sample rate - arc_start) (ProgramAngles::at).
    const double start = k == 0 ? p_.start_deg : p_.start_deg + p_.arc_deg + 2 * p_.overshoot_deg;
    out.push_back({k == 0 ? circle::Direction::ccw : circle::Direction::cw, *feed_in_end_ + i0,
                   i1 > i0 ? i1 - i0 : 0,
                   circle::ProgramAngles{.start_deg = start,
                                         .rate_deg_s = s * rate_deg_s,
                                         .arc_start_s = arc_start_s,
                                         .sample_rate_hz = p_.sample_rate_hz,
                                         .first = i0}});
  }
  return out;
}

std::vector<circle::Trace> BallbarSegmenter::traces() const {
  std::vector<circle::Trace> out;
  for (const auto& c : cuts()) {
    // Exactly the samples: no growth slack, which held up to a third more of the trace at the
    // analysis' peak (issue 32).
    circle::Trace t{c.direction, {}, {}};
    t.angle_deg.reserve(c.count);
    t.deviation_um.reserve(c.count);
    for (std::size_t j = 0; j < c.count; ++j) {
      t.angle_deg.push_back(c.angles.at(j));
      t.deviation_um.push_back((*values_)[c.offset + j] * 1e3);
    }
    out.push_back(std::move(t));
  }
  return out;
}

std::vector<circle::TraceSource> BallbarSegmenter::sources() const {
  std::vector<circle::TraceSource> out;
  for (const auto& c : cuts())
    out.emplace_back(c.direction, c.count, c.angles, values_, c.offset, 1e3);
  return out;
}

std::string_view to_string(BallbarPhase p) {
  using enum BallbarPhase;
  // clang-format off
  static constexpr EnumName<BallbarPhase> kNames[] = {
      {feed_in, "waiting for the feed-in"}, {dwell, "dwell"}, {ccw_arc, "ccw arc"},
      {cw_arc, "cw arc"}, {complete, "complete"}};
  // clang-format on
  static_assert(cal::names_every_value(kNames));
  return name_of(kNames, p);
}

BallbarProgress BallbarSegmenter::progress() const {
  if (!feed_in_end_ || values_->empty()) return {};
  const double arc_s = arc_duration_s(), total_s = 2 * p_.dwell_s + 2 * arc_s;
  const double t_s = static_cast<double>(values_->size() - 1 - *feed_in_end_) / p_.sample_rate_hz;
  const double rate_deg_s = p_.feed_mm_per_min / 60.0 / p_.radius_mm * 180.0 / std::numbers::pi;
  BallbarProgress out{.fraction = std::min(1.0, t_s / total_s)};
  if (complete()) {
    out.phase = BallbarPhase::complete;
  } else if (t_s < p_.dwell_s) {
    out.phase = BallbarPhase::dwell;
    out.angle_deg = p_.start_deg;
  } else if (t_s < p_.dwell_s + arc_s) {
    out.phase = BallbarPhase::ccw_arc;
    out.angle_deg = p_.start_deg + rate_deg_s * (t_s - p_.dwell_s);
  } else if (t_s < 2 * p_.dwell_s + arc_s) {
    out.phase = BallbarPhase::dwell;
    out.angle_deg = p_.start_deg + p_.arc_deg + 2 * p_.overshoot_deg;
  } else {
    out.phase = BallbarPhase::cw_arc;
    out.angle_deg = p_.start_deg + p_.arc_deg + 2 * p_.overshoot_deg -
                    rate_deg_s * (t_s - 2 * p_.dwell_s - arc_s);
  }
  return out;
}

}  // namespace cal::daq
