// The machine model on the operator's page (see model_view.hpp).
#include "serve/model_view.hpp"

#include <fmt/format.h>

#include <map>

#include "cal/analysis/error.hpp"
#include "cal/storage/store.hpp"
#include "model/model_map.hpp"
#include "model_from_runs.hpp"

namespace daq::serve {

namespace mdl = cal::daq::model;
using nlohmann::json;

namespace {

// The 21 errors with the runs each came from and what it adds to the map (0 without a map).
json error_rows(const ModelFromRuns& b, const std::optional<mdl::ModelMap>& map) {
  std::map<std::string, std::vector<std::int64_t>> used(b.report.used.begin(), b.report.used.end());
  std::map<std::string, const cal::kinematics::Contribution*> added;
  if (map)
    for (const auto& c : map->contributions) added[c.name] = &c;
  json rows = json::array();
  const auto row = [&](const std::string& name) {
    const auto u = used.find(name);
    const auto c = added.find(name);
    rows.push_back(
        {{"error", name},
         {"runs", u == used.end() ? json::array() : json(u->second)},
         {"measured", u != used.end()},
         {"max_norm_um", c == added.end() ? json(nullptr) : json(c->second->max_norm_um)},
         {"rms_um", c == added.end() ? json(nullptr) : json(c->second->rms_um)}});
  };
  // The map's order (largest contribution first) when there is a map, else the build's.
  if (map) {
    for (const auto& c : map->contributions) row(c.name);
  } else {
    for (const auto& [name, ids] : b.report.used) row(name);
    for (const auto& name : b.report.missing) row(name);
  }
  return rows;
}

}  // namespace

json model_view(const cal::storage::RunReader* store, const std::string& machine) {
  json j{{"schema", "caldaq.model-view.v1"}, {"machine", machine}, {"build", nullptr},
         {"errors", json::array()},          {"map", nullptr},     {"map_why", ""}};
  if (!store) {
    j["state"] = "none", j["why"] = "no run is stored yet";
    return j;
  }
  ModelFromRuns b;
  try {
    b = model_from_runs(
        *store, {.machine = machine, .allow_missing = true, .what = "the model on the page"});
  } catch (const cal::InputError& e) {
    // No run of the machine yet, or the build's own refusal (a suspect run, no topology).
    const bool none = !store->machine_by_name(machine);
    j["state"] = none ? "none" : "refused", j["why"] = e.what();
    return j;
  }
  j["state"] = b.report.missing.empty() ? "complete" : "partial";
  j["build"] = model_build_json(b, machine, "");
  std::optional<mdl::ModelMap> map;
  if (!b.report.model.travel_mm) {
    j["map_why"] =
        "the map is over the model's travel, known once every axis (X, Y and Z) has a run";
  } else {
    try {
      map = mdl::model_map(b.report.model, mdl::travel_grid(b.report.model, {5, 5, 5}),
                           cal::kinematics::Method::htm);
      j["map"] = mdl::model_map_json(*map, true);
    } catch (const cal::InputError& e) {
      j["map_why"] = e.what();
    }
  }
  j["errors"] = error_rows(b, map);
  return j;
}

}  // namespace daq::serve
