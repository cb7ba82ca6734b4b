// The profiles of a machine's stored runs (see stored_model.hpp).
#include "stored_model.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <ctime>
#include <map>
#include <nlohmann/json.hpp>

#include "cal/analysis/error.hpp"
#include "cal/analysis/text.hpp"
#include "json_input.hpp"

namespace daq {

using nlohmann::json;

namespace {

std::string utc(std::int64_t unix_ms) {
  return cal::text::utc_text(unix_ms / 1000, "%Y-%m-%dT%H:%M:%SZ");
}

cal::kinematics::Vec3 vec(const json& j, const char* key) {
  cal::kinematics::Vec3 v{};
  if (const auto it = j.find(key); it != j.end() && it->is_array() && it->size() == 3)
    for (std::size_t k = 0; k < 3; ++k) v[k] = (*it)[k].get<double>();
  return v;
}

}  // namespace

StoredProfiles stored_profiles(const cal::storage::RunReader& store, const std::string& machine,
                               std::span<const std::int64_t> only) {
  const auto m = store.machine_by_name(machine);
  if (!m) throw cal::InputError(fmt::format("no machine '{}' in {}", machine, store.name()));
  StoredProfiles out;
  auto runs = store.runs();
  std::sort(runs.begin(), runs.end(), [](const auto& a, const auto& b) { return a.id > b.id; });
  std::map<std::string, std::int64_t> taken;  // component -> run id
  bool any = false;
  for (const auto& r : runs) {
    if (r.machine_id != m->id) continue;
    if (!only.empty() && std::find(only.begin(), only.end(), r.id) == only.end()) continue;
    const json s = cal::daq::parse_stored_json(r.settings_json);
    if (!s.is_object()) continue;
    const auto measure = s.find("measure");
    // Positioning runs stored before the test kinds have no "measure": E_XX of their axis.
    if (measure == s.end() && r.kind != "linear") continue;
    const json me = measure == s.end() ? json::object() : *measure;
    const std::string component =
        me.value("component", r.kind == "linear" ? "E_" + r.axis + r.axis : "");
    if (component.empty()) continue;
    any = true;
    if (!out.topology)
      if (const auto mm = s.find("machine_model"); mm != s.end() && mm->is_object()) {
        const std::string t = mm->value("topology", "");
        if (!t.empty()) {
          out.topology = cal::kinematics::topology_from_string(t);
          out.tool_offset_mm = vec(*mm, "tool_offset_mm");
          out.table_offset_mm = vec(*mm, "table_offset_mm");
        }
      }
    if (r.status != cal::storage::RunStatus::complete) {
      out.skipped.push_back(fmt::format("run {} ({}): {}, not used", r.id, component,
                                        cal::storage::to_string(r.status)));
      continue;
    }
    if (const auto t = taken.find(component); t != taken.end()) {
      out.skipped.push_back(
          fmt::format("run {} ({}): older than run {}, not used", r.id, component, t->second));
      continue;
    }
    // The profile: the mean of each target's stops.
    std::map<int, std::pair<double, std::pair<double, int>>> by_target;  // index -> (q, (sum, n))
    for (const auto& t : store.targets(r.id)) {
      auto& e = by_target[t.target_index];
      e.first = t.nominal_mm;
      e.second.first += t.deviation_um;
      ++e.second.second;
    }
    cal::daq::model::MeasuredProfile p{.run_id = r.id,
                                       .component = component,
                                       .kind = me.value("kind", "positioning"),
                                       .stationary_mm = vec(me, "stationary_mm"),
                                       .probe_offset_mm = vec(me, "probe_offset_mm"),
                                       .square = me.value("square", false),
                                       .started_utc = utc(r.started_unix_ms)};
    for (const auto& [i, e] : by_target) {
      p.position_mm.push_back(e.first);
      p.value.push_back(e.second.first / e.second.second);
    }
    taken[component] = r.id;
    out.profiles.push_back(std::move(p));
  }
  if (!any)
    throw cal::InputError(
        fmt::format("machine '{}' has no stored run of a test kind (positioning, straightness, "
                    "angular, roll)",
                    machine));
  return out;
}

}  // namespace daq
