#include "stored_profile.hpp"

#include <fmt/format.h>

#include <cmath>
#include <span>

#include "cal/analysis/error.hpp"
#include "json_input.hpp"
#include "kinds/kind.hpp"

namespace daq {

bool is_profile_kind(std::string_view run_kind) {
  return run_kind == "straightness" || run_kind == "angular" || run_kind == "roll";
}

namespace {

constexpr double kArcsecPerDeg = 3600.0;
using kinds::wrapped_arcsec;

// How a rotary run's stops were stored: as deviations (now), or as the reference's angle
// (before a452795). Only a stop at least 1 deg from 0 deg (modulo a turn) tells them apart: an
// angle there lies nearer its target than 0, a deviation nearer 0 (the deviation is under
// half the target's distance from 0). At 0 deg (and 360 deg) the two agree modulo a turn.
enum class RotaryStorage { deviations, angles };
RotaryStorage rotary_storage(const cal::storage::RunRecord& run,
                             std::span<const cal::storage::CapturedTarget> targets) {
  std::size_t angles = 0, deviations = 0;
  for (const auto& t : targets) {
    const double target_arcsec = t.nominal_mm * kArcsecPerDeg;
    if (std::abs(wrapped_arcsec(target_arcsec)) < kArcsecPerDeg) continue;
    const bool as_angle = std::abs(wrapped_arcsec(t.deviation_um - target_arcsec)) <
                          std::abs(wrapped_arcsec(t.deviation_um));
    ++(as_angle ? angles : deviations);
  }
  if (angles && deviations)
    throw cal::InputError(fmt::format(
        "run {} (rotary): of its stops 1 deg or more from 0 deg, {} hold a value near their "
        "target's angle (a run stored before a452795 held the reference's angle) and {} a "
        "value near 0 (a deviation): it cannot be read either way",
        run.id, angles, deviations));
  return angles ? RotaryStorage::angles : RotaryStorage::deviations;
}

}  // namespace

std::vector<cal::storage::CapturedTarget> stored_targets(const cal::storage::RunReader& store,
                                                         const cal::storage::RunRecord& run,
                                                         std::string* note) {
  auto targets = store.targets(run.id);
  if (run.kind != "rotary" || rotary_storage(run, targets) == RotaryStorage::deviations)
    return targets;
  for (auto& t : targets)
    t.deviation_um = wrapped_arcsec(t.deviation_um - t.nominal_mm * kArcsecPerDeg);
  if (note)
    *note = fmt::format(
        "run {} was stored before a452795 (2026-11-28): its stops hold the angular reference's "
        "angle, not the deviation; read as the angle minus the target, modulo a turn (arcsec)",
        run.id);
  return targets;
}

namespace {
std::vector<kinds::StopValue> stored_stops(const cal::storage::RunReader& store,
                                           const cal::storage::RunRecord& run, std::string* note) {
  std::vector<kinds::StopValue> stops;
  for (const auto& t : stored_targets(store, run, note))  // the kind's unit (um, urad, arcsec)
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
  std::string note;
  const auto stops = stored_stops(store, run, &note);
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
  auto j = kind.evaluate(stops, l).json;
  if (!note.empty()) j["warnings"].push_back(note);  // printed with the values everywhere
  return j;
}

nlohmann::json stored_profile(const cal::storage::RunReader& store,
                              const cal::storage::RunRecord& run) {
  if (!is_profile_kind(run.kind))
    throw cal::InputError(fmt::format(
        "run {} is a {} test; this needs a straightness, angular or roll run", run.id, run.kind));
  const auto& kind = kinds::kind(run.kind);
  const auto stops = stored_stops(store, run, nullptr);
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
