// The ISO 230-2 sequencer (see sequencer.hpp).
#include "cal/daq/sequencer.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace cal::daq {

using iso230_2::Direction;

Sequencer::Sequencer(const iso230_2::Plan& plan, double window_mm, AxisUnits units)
    : window_mm_(window_mm), units_(units) {
  for (const auto& m : plan.moves) {
    if (m.kind != iso230_2::MoveKind::measure) continue;
    stops_.push_back({m.target_index, m.run, m.direction, m.position_mm});
    runs_ = std::max(runs_, m.run);
  }
  targets_ = static_cast<int>(plan.targets_mm.size());
}

std::optional<double> Sequencer::next_expected_mm() const {
  if (complete()) return std::nullopt;
  return stops_[next_].position_mm;
}

bool Sequencer::fits(const ExpectedStop& e, const Capture& c) const {
  if (std::abs(c.mean_mm - e.position_mm) > window_mm_) return false;
  // An unknown approach is accepted from the operator's manual capture only (the plan's
  // direction is then assumed, and the event says so). An automatic stop without an
  // approach move is the axis at rest before the program starts: its direction is undefined.
  if (c.approach == Approach::unknown) return c.manual;
  return (c.approach == Approach::from_below) == (e.direction == Direction::up);
}

std::string Sequencer::describe(const ExpectedStop& e) const {
  return fmt::format("target {} ({:.3f} {}) run {} {}", e.target_index, e.position_mm,
                     units_.position, e.run, e.direction == Direction::up ? "up" : "down");
}

std::size_t Sequencer::pass_end(std::size_t i) const {
  std::size_t j = i;
  while (j < stops_.size() && stops_[j].run == stops_[i].run &&
         stops_[j].direction == stops_[i].direction)
    ++j;
  return j;  // the first stop of the next pass (or the end)
}

std::vector<double> Sequencer::acceptable_mm() const {
  std::vector<double> out;
  const std::size_t limit = pass_end(next_) < stops_.size() ? pass_end(next_) + 1 : stops_.size();
  for (std::size_t j = next_; j < limit; ++j) out.push_back(stops_[j].position_mm);
  for (std::size_t j = 0; j < next_; ++j)
    if (stops_[j].missed && !stops_[j].skipped) out.push_back(stops_[j].position_mm);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::vector<SequenceEvent> Sequencer::on_capture(const Capture& c) {
  std::vector<SequenceEvent> events;
  auto take = [&](std::size_t i, SequenceEvent::Kind kind, std::string text) {
    ExpectedStop& e = stops_[i];
    e.captured = true;
    e.missed = false;
    e.deviation_um = units_.deviation_of(c.mean_mm, e.position_mm);
    e.time_ns = c.end_ns;
    if (c.approach == Approach::unknown) text += " (approach direction unknown: plan's assumed)";
    events.push_back({kind, i, std::move(text)});
  };
  // The next expected stop, or a later one of the same pass (run and direction) or the first
  // of the next pass; those skipped are missed. A jump further ahead is not believed: a stop
  // at a position the plan visits again in a later run is then extra or wrong-direction,
  // not the end of a whole run of missed stops.
  const std::size_t limit = pass_end(next_) < stops_.size() ? pass_end(next_) + 1 : stops_.size();
  for (std::size_t j = next_; j < limit; ++j) {
    if (!fits(stops_[j], c)) continue;
    for (std::size_t k = next_; k < j; ++k) {
      stops_[k].missed = true;
      events.push_back({SequenceEvent::Kind::missed, k, "missed " + describe(stops_[k])});
    }
    take(j, SequenceEvent::Kind::captured,
         fmt::format("{}: {:+.3f} {}", describe(stops_[j]),
                     units_.deviation_of(c.mean_mm, stops_[j].position_mm), units_.deviation));
    next_ = j + 1;
    if (complete()) {
      // The end of the plan: "all stops captured" only when it is true.
      const auto missed = std::count_if(stops_.begin(), stops_.end(),
                                        [](const ExpectedStop& e) { return !e.captured; });
      events.push_back({SequenceEvent::Kind::complete, j,
                        missed == 0 ? std::string("all stops captured")
                                    : fmt::format("end of the plan: {} of {} stops missed", missed,
                                                  stops_.size())});
    }
    return events;
  }
  // A stop reported missed earlier, captured late.
  for (std::size_t j = 0; j < next_; ++j) {
    if (stops_[j].missed && !stops_[j].skipped && fits(stops_[j], c)) {
      take(j, SequenceEvent::Kind::out_of_order, "out of order: " + describe(stops_[j]));
      return events;
    }
  }
  if (c.approach == Approach::unknown && !c.manual) {
    events.push_back({SequenceEvent::Kind::extra, next_,
                      fmt::format("stop at {:.4f} {} without an approach move (the axis has not "
                                  "moved yet): ignored",
                                  c.mean_mm, units_.position)});
    return events;
  }
  // Right place, wrong side: not a valid approach for the expected stop.
  if (!complete() && std::abs(c.mean_mm - stops_[next_].position_mm) <= window_mm_) {
    events.push_back(
        {SequenceEvent::Kind::wrong_direction, next_,
         fmt::format("stop at {:.4f} {} approached from {}, but {} expects {}: ignored", c.mean_mm,
                     units_.position, c.approach == Approach::from_below ? "below" : "above",
                     describe(stops_[next_]),
                     stops_[next_].direction == Direction::up ? "up" : "down")});
    return events;
  }
  events.push_back({SequenceEvent::Kind::extra, next_,
                    fmt::format("extra stop at {:.4f} {}: no expected stop within {} {}, ignored",
                                c.mean_mm, units_.position, window_mm_, units_.position)});
  return events;
}

std::optional<std::size_t> Sequencer::skip() {
  if (complete()) return std::nullopt;
  auto& e = stops_[next_];
  e.missed = e.skipped = true;
  return next_++;
}

std::optional<std::size_t> Sequencer::reopen_last() {
  if (next_ == 0) return std::nullopt;
  auto& e = stops_[--next_];
  e.captured = e.missed = e.skipped = false;
  e.deviation_um = 0.0;
  e.time_ns = 0;
  return next_;
}

Progress Sequencer::progress() const {
  Progress p;
  p.runs = runs_;
  p.targets = targets_;
  p.expected = stops_.size();
  p.captured = static_cast<std::size_t>(
      std::count_if(stops_.begin(), stops_.end(), [](const auto& e) { return e.captured; }));
  if (!complete()) {
    const auto& e = stops_[next_];
    p.run = e.run;
    p.target = e.target_index;
    p.direction = e.direction;
    p.next_position_mm = e.position_mm;
  }
  return p;
}

std::vector<std::size_t> Sequencer::missed() const {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < next_ && i < stops_.size(); ++i)
    if (!stops_[i].captured) out.push_back(i);
  return out;
}

std::vector<iso230_2::Measurement> Sequencer::measurements() const {
  std::vector<iso230_2::Measurement> out;
  for (const auto& e : stops_)
    if (e.captured) out.push_back({e.position_mm, e.run, e.direction, e.deviation_um});
  return out;
}

}  // namespace cal::daq
