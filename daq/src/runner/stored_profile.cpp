#include "stored_profile.hpp"

#include <fmt/format.h>

#include "cal/analysis/error.hpp"
#include "json_input.hpp"
#include "kinds/kind.hpp"

namespace daq {

bool is_profile_kind(std::string_view run_kind) {
  return run_kind == "straightness" || run_kind == "angular" || run_kind == "roll";
}

namespace {
std::vector<kinds::StopValue> stored_stops(const cal::storage::RunReader& store,
                                           const cal::storage::RunRecord& run) {
  std::vector<kinds::StopValue> stops;
  for (const auto& t : store.targets(run.id))  // the value in the kind's unit (um, urad, arcsec)
    stops.push_back({.position_mm = t.nominal_mm,
                     .target_index = t.target_index,
                     .run = t.run_number,
                     .direction = t.direction,
                     .value = t.deviation_um});
  if (stops.empty())
    throw cal::InputError(fmt::format("run {} has no captured stops to evaluate", run.id));
  return stops;
}
}  // namespace

nlohmann::json stored_rotary(const cal::storage::RunReader& store,
                             const cal::storage::RunRecord& run, std::string_view standard) {
  if (run.kind != "rotary")
    throw cal::InputError(
        fmt::format("run {} is a {} test; this needs a rotary run", run.id, run.kind));
  const auto stops = stored_stops(store, run);
  const auto settings = cal::daq::parse_stored_json(run.settings_json);
  cal::daq::LinearTestConfig l;
  l.axis = run.axis;
  l.measure.kind = "rotary";
  l.standard =
      !standard.empty() ? std::string(standard)
      : settings.is_object() && settings.contains("standard") && settings["standard"].is_string()
          ? settings["standard"].get<std::string>()
          : l.standard;
  const auto& kind = kinds::kind("rotary");
  kind.validate(l);
  return kind.evaluate(stops, l).json;
}

nlohmann::json stored_profile(const cal::storage::RunReader& store,
                              const cal::storage::RunRecord& run) {
  if (!is_profile_kind(run.kind))
    throw cal::InputError(fmt::format(
        "run {} is a {} test; this needs a straightness, angular or roll run", run.id, run.kind));
  const auto& kind = kinds::kind(run.kind);
  const auto stops = stored_stops(store, run);
  // The component and unit as the run stored them (its settings' measure), else the kind's.
  const auto settings = cal::daq::parse_stored_json(run.settings_json);
  const auto measure = settings.is_object() ? settings.value("measure", nlohmann::json::object())
                                            : nlohmann::json::object();
  const auto text = [&](const char* key, std::string_view fallback) {
    return measure.is_object() && measure.contains(key) && measure[key].is_string()
               ? measure[key].get<std::string>()
               : std::string(fallback);
  };
  return kinds::profile_json(stops, kind.name(), text("component", run.kind),
                             text("unit", kind.unit()));
}

}  // namespace daq
