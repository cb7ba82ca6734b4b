// The quality gate of a stored run's stops (see run_quality.hpp).
#include "run_quality.hpp"

#include <fmt/format.h>

#include <algorithm>

#include "cal/analysis/error.hpp"
#include "cal/analysis/stop_quality.hpp"

namespace daq {

using nlohmann::json;

cal::storage::RunQuality assess_stops(std::span<const cal::storage::CapturedTarget> stops,
                                      std::string_view unit) {
  std::vector<cal::quality::Stop> in;
  in.reserve(stops.size());
  for (const auto& t : stops)
    in.push_back({.target_index = t.target_index,
                  .run = t.run_number,
                  .direction = t.direction,
                  .nominal_mm = t.nominal_mm,
                  .value = t.deviation_um});
  const auto a = cal::quality::assess(in, unit);
  cal::storage::RunQuality q{.state = !a.checked           ? "not checked"
                                      : a.suspects.empty() ? "ok"
                                                           : "suspect",
                             .summary = a.summary};
  for (const auto& s : a.suspects) {
    const auto& t = stops[s.stop];
    q.suspects.push_back({.run_number = t.run_number,
                          .direction = t.direction,
                          .target_index = t.target_index,
                          .reason = s.reason});
  }
  return q;
}

namespace {
// The run's unit: settings.measure.unit ("um" unless another kind says so).
std::string run_unit(const cal::storage::RunRecord& r) {
  const auto settings = json::parse(r.settings_json, nullptr, false);
  if (settings.is_object() && settings.contains("measure") && settings["measure"].is_object()) {
    const auto& m = settings["measure"];
    if (m.contains("unit") && m["unit"].is_string()) return m["unit"].get<std::string>();
  }
  return "um";
}
}  // namespace

cal::storage::RunQuality run_quality(const cal::storage::RunReader& store, std::int64_t run_id) {
  if (auto q = store.quality(run_id)) return *q;
  const auto run = store.run(run_id);
  if (!run) return {.state = "not checked", .summary = fmt::format("no run {}", run_id)};
  auto q = assess_stops(store.targets(run_id), run_unit(*run));
  q.summary += " (assessed when read: the run was stored without a quality check)";
  return q;
}

std::string quality_text(const cal::storage::RunQuality& q) {
  // An assessment's summary begins with its state ("ok: every stop within ..."); a stored one
  // may not. Printed after a label ("Run quality: ", "stop quality: ") a colon after the state
  // made two in a row ("Run quality: ok: every stop ..."): the state, a comma, the rest.
  std::string_view rest = q.summary;
  if (!q.state.empty() && rest.starts_with(q.state)) {
    rest.remove_prefix(q.state.size());
    while (!rest.empty() && (rest.front() == ':' || rest.front() == ' ')) rest.remove_prefix(1);
  }
  if (q.state.empty()) return std::string(rest);
  if (rest.empty()) return q.state;
  return q.state + ", " + std::string(rest);
}

json quality_json(const cal::storage::RunQuality& q) {
  json stops = json::array();
  for (const auto& s : q.suspects)
    stops.push_back({{"run", s.run_number},
                     {"direction", s.direction == '+' ? "up" : "down"},
                     {"target_index", s.target_index},
                     {"reason", s.reason}});
  return {{"state", q.state}, {"summary", q.summary}, {"suspect_stops", std::move(stops)}};
}

std::vector<std::int64_t> refuse_suspect_runs(const cal::storage::RunReader& store,
                                              std::span<const std::int64_t> runs,
                                              std::span<const std::int64_t> accepted,
                                              std::string_view what) {
  std::vector<std::int64_t> taken;
  std::string refused;
  for (const auto id : runs) {
    const auto q = run_quality(store, id);
    if (q.state != "suspect") continue;
    if (std::find(accepted.begin(), accepted.end(), id) != accepted.end()) {
      taken.push_back(id);
      continue;
    }
    refused += fmt::format("\n  run {}: {}", id, quality_text(q));
    for (const auto& s : q.suspects) refused += fmt::format("\n    {}", s.reason);
  }
  if (!refused.empty())
    throw cal::InputError(
        fmt::format("{} refused: suspect stops (a stop far outside its run's repeatability; "
                    "docs/iso230-2.md, \"Suspect stops\"):{}\nmeasure the run again, or accept it "
                    "knowingly with --accept-suspect RUN (recorded with what is built)",
                    what, refused));
  return taken;
}

}  // namespace daq
