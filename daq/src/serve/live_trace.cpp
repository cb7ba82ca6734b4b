#include "serve/live_trace.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace daq::serve {

using nlohmann::json;

namespace {

// To 0.01 (° and µm): the live plot's rings are 1 µm or more apart and it is 560 px wide at
// most, and 0.30000000000000004 is 19 characters where 0.3 is 3. (The stored run and its
// results keep the bar's readings as they came: this is the live picture only.)
double rounded(double v) { return std::round(v * 100.0) / 100.0; }

json points(const std::vector<std::pair<double, double>>& arc, std::size_t from) {
  json a = json::array();
  for (std::size_t i = from; i < arc.size(); ++i)
    a.push_back({rounded(arc[i].first), rounded(arc[i].second)});
  return a;
}

}  // namespace

void LiveTraceFeed::update(const CircleLive& s, std::int64_t run_id) {
  if (!have_ || run_id != run_id_ || s.ccw.size() < live_.ccw.size() ||
      s.cw.size() < live_.cw.size()) {
    ++epoch_;
    sent_.clear();
  }
  live_ = s;
  run_id_ = run_id;
  have_ = true;
}

void LiveTraceFeed::clear() {
  have_ = false;
  sent_.clear();
  live_ = {};
}

json LiveTraceFeed::page_json(Clock::time_point now) {
  while (sent_.size() > 1 && now - sent_[1].at >= repeat_for) sent_.pop_front();
  // From the arcs' sizes at the oldest message of the last second (the whole arc at first).
  const std::size_t ccw_from = sent_.empty() ? 0 : std::min(sent_.front().ccw, live_.ccw.size());
  const std::size_t cw_from = sent_.empty() ? 0 : std::min(sent_.front().cw, live_.cw.size());
  // The state as `daq run circle --json` prints it, less its trace (~200 bytes parsed again, at
  // 10 Hz: nothing beside the trace's own points).
  CircleLive head = live_;
  head.ccw.clear();
  head.cw.clear();
  json j = json::parse(to_json_text(head));
  j["trace"] = {
      {"epoch", epoch_},
      {"ccw",
       {{"n", live_.ccw.size()}, {"from", ccw_from}, {"points", points(live_.ccw, ccw_from)}}},
      {"cw", {{"n", live_.cw.size()}, {"from", cw_from}, {"points", points(live_.cw, cw_from)}}}};
  sent_.push_back({now, live_.ccw.size(), live_.cw.size()});
  return j;
}

json LiveTraceFeed::whole() const {
  return {{"epoch", epoch_}, {"ccw", points(live_.ccw, 0)}, {"cw", points(live_.cw, 0)}};
}

}  // namespace daq::serve
