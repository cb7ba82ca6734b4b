#include "provenance.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <chrono>
#include <ctime>

#include "cal/analysis/text.hpp"
#include "config_json.hpp"
#include "json_input.hpp"

namespace daq {

using nlohmann::json;

json run_tolerances(const cal::daq::Config& c, std::string_view kind, std::string_view where) {
  const std::string key(where);
  if (kind == "linear") {
    if (const auto it = c.axis_tolerances.find(key); it != c.axis_tolerances.end()) {
      json t = limits_json(it->second.limits);
      t["by_length"] = json::array();
      for (const auto& [up_to, l] : it->second.by_length) {
        json e = limits_json(l);
        e["up_to_mm"] = up_to;
        t["by_length"].push_back(e);
      }
      t["source"] = "tolerances." + key;
      return t;
    }
  } else if (kind == "ballbar5x") {
    // Each rotary axis tested (`where`: "CA"), its location limits alone.
    json t = json::object();
    std::vector<std::string> sources;
    for (const char letter : where) {
      const std::string axis(1, letter);
      const auto it = c.axis_tolerances.find(axis);
      if (it == c.axis_tolerances.end()) continue;
      const auto& l = it->second.limits;
      json own = json::object();
      if (l.location_um) own["location_um"] = *l.location_um;
      if (l.location_urad) own["location_urad"] = *l.location_urad;
      if (own.empty()) continue;
      t[axis] = own;
      sources.push_back("tolerances." + axis);
    }
    if (t.empty()) return nullptr;
    t["source"] = fmt::format("{}", fmt::join(sources, ", "));
    return t;
  } else if (kind == "circle") {
    if (const auto it = c.plane_tolerances.find(key); it != c.plane_tolerances.end()) {
      json t = json::object();
      if (it->second.G_um) t["G_um"] = *it->second.G_um;
      t["diagnostics"] = it->second.diagnostics;
      t["source"] = "tolerances." + key;
      return t;
    }
  }
  return nullptr;
}

json run_context(const cal::daq::Config& c, std::string_view kind, std::string_view where,
                 std::span<const std::string> roles) {
  json j{{"customer",
          {{"name", c.customer.name}, {"site", c.customer.site}, {"contact", c.customer.contact}}},
         {"machine",
          {{"name", c.machine_name},
           {"description", c.machine_description},
           {"make", c.machine_make},
           {"model", c.machine_model},
           {"serial_number", c.machine_serial}}},
         {"operator", c.operator_name},
         {"conditions",
          {{"controller_compensation", c.conditions.controller_compensation
                                           ? json(*c.conditions.controller_compensation)
                                           : json(nullptr)},
           {"warm_up", c.conditions.warm_up},
           {"load", c.conditions.load},
           {"state", c.conditions.state},
           {"notes", c.conditions.notes}}},
         {"configuration", c.source.empty() ? "" : c.source.string()}};
  j["instruments"] = json::array();
  for (const auto& d : c.devices) {
    if (d.role.empty() || std::find(roles.begin(), roles.end(), d.role) == roles.end()) continue;
    j["instruments"].push_back({{"id", d.id},
                                {"role", d.role},
                                {"driver", d.driver},
                                {"transport", d.transport},
                                {"serial_number", d.serial_number},
                                {"certificate", d.certificate},
                                {"calibration_due", d.calibration_due}});
  }
  j["tolerances"] = run_tolerances(c, kind, where);
  return j;
}

json compensation_json(const cal::daq::EnvironmentConfig& e) {
  return {{"equation", e.equation},
          {"expansion_ppm_per_k", e.expansion_ppm_per_k},
          {"co2_umol_per_mol", e.co2_umol_per_mol},
          {"wavelength_nm", e.wavelength_nm}};
}

json to_json(const SensorOffsets& o) {
  return {{"material_k", o.material_k},
          {"air_temperature_k", o.air_temperature_k},
          {"pressure_pa", o.pressure_pa},
          {"humidity_pct", o.humidity_pct}};
}

SensorOffsets sensor_offsets_from_json(const json& j) {
  SensorOffsets o;
  if (!j.is_object()) return o;
  o.material_k = j.value("material_k", 0.0);
  o.air_temperature_k = j.value("air_temperature_k", 0.0);
  o.pressure_pa = j.value("pressure_pa", 0.0);
  o.humidity_pct = j.value("humidity_pct", 0.0);
  return o;
}

json provenance(std::string_view how, std::string_view software) {
  return {{"schema", "caldaq.provenance.v1"},
          {"how", how},
          {"software", software},
          {"created_utc", utc_now_iso()}};
}

std::optional<cal::storage::ResultRecord> current_result(
    const std::vector<cal::storage::ResultRecord>& results, std::string_view schema) {
  // Any version of the schema ("caldaq.circle.v1" results stored before issue 18 count).
  const auto family = [](std::string_view s) { return s.substr(0, s.rfind('.')); };
  for (auto it = results.rbegin(); it != results.rend(); ++it) {
    if (!it->current()) continue;
    const json doc = cal::daq::parse_stored_json(it->json);
    if (doc.is_object() && family(doc.value("schema", "")) == family(schema)) return *it;
  }
  return std::nullopt;
}

CompensationUsed compensation_used(const json& settings,
                                   const std::vector<cal::storage::ResultRecord>& results) {
  CompensationUsed u;
  const json env =
      settings.is_object() ? settings.value("environment", json::object()) : json::object();
  u.coefficients = {{"equation", env.value("equation", "ciddor")},
                    {"expansion_ppm_per_k", env.value("expansion_ppm_per_k", 11.5)},
                    {"co2_umol_per_mol", env.value("co2_umol_per_mol", 450.0)},
                    {"wavelength_nm", env.value("wavelength_nm", 632.991)}};
  const auto current = current_result(results, "caldaq.iso230-2.v1");
  if (!current) return u;
  u.result_id = current->id;
  const json doc = cal::daq::parse_stored_json(current->json);
  const json prov = cal::daq::parse_stored_json(current->provenance_json);
  if (prov.is_object() && prov.contains("coefficients")) {
    for (const auto& [k, v] : prov["coefficients"].items()) u.coefficients[k] = v;
    u.offsets = sensor_offsets_from_json(prov.value("sensor_offsets", json::object()));
    u.recompensated = prov.value("how", "") == "recompensated";
    u.changed = prov.value("changed", json::array());
  } else if (doc.is_object() && doc.contains("recompensation")) {
    // Re-compensated before provenance was recorded: its own note says what it used.
    const auto& r = doc["recompensation"];
    u.coefficients["equation"] = r.value("equation", u.coefficients["equation"].get<std::string>());
    u.coefficients["expansion_ppm_per_k"] =
        r.value("expansion_ppm_per_k", u.coefficients["expansion_ppm_per_k"].get<double>());
    u.offsets = {.material_k = r.value("material_offset_k", 0.0),
                 .air_temperature_k = r.value("air_temperature_offset_k", 0.0),
                 .pressure_pa = r.value("pressure_offset_pa", 0.0),
                 .humidity_pct = r.value("humidity_offset_pct", 0.0)};
    u.recompensated = true;
  }
  return u;
}

std::string utc_iso(std::int64_t unix_ms) {
  const std::int64_t s = unix_ms >= 0 ? unix_ms / 1000 : (unix_ms - 999) / 1000;
  return fmt::format("{}.{:03d}Z", cal::text::utc_text(s, "%Y-%m-%dT%H:%M:%S"),
                     static_cast<int>(unix_ms - s * 1000));
}

json bar_calibration_json(const cal::storage::BarCalibration& c) {
  return {{"id", c.id},
          {"bar", c.bar},
          {"nominal_mm", c.nominal_mm},
          {"extensions", c.extensions},
          {"calibrator", c.calibrator},
          {"calibrator_length_mm", c.calibrator_length_mm},
          {"reading_mm", c.reading_mm},
          {"zero_length_mm", c.zero_length_mm},
          {"temperature_degc", c.temperature_degc ? json(*c.temperature_degc) : json(nullptr)},
          {"calibrated_utc", utc_iso(c.calibrated_unix_ms)},
          {"note", c.note}};
}

std::string utc_now_iso() {
  return utc_iso(std::chrono::duration_cast<std::chrono::milliseconds>(
                     std::chrono::system_clock::now().time_since_epoch())
                     .count());
}

std::string RunOrigin::label() const {
  std::string l;
  const auto add = [&](std::string_view w) { l += (l.empty() ? "" : ", ") + std::string(w); };
  if (simulated) add("SIMULATED");
  if (replayed) add("REPLAYED");
  if (imported) add("IMPORTED");
  return l;
}

RunOrigin run_origin(const cal::storage::RunRecord& run,
                     const std::vector<cal::storage::InstrumentRecord>& instruments,
                     std::string_view machine_name) {
  RunOrigin o;
  const auto by_name = [](std::string_view s) {
    return s.find("SIMULATED") != std::string_view::npos ||
           s.find("simulated") != std::string_view::npos;
  };
  // Instruments of the same origin and detail said once, named together ("laser, air and
  // material simulated (a twin of ...)"): a run of four twins repeated the detail four times,
  // five lines above the fold of the operator's page.
  struct Group {
    std::string origin, detail;
    std::vector<std::string> drivers;
  };
  std::vector<Group> groups;
  for (const auto& i : instruments) {
    if (i.origin.empty()) {
      o.unrecorded = true;
      o.simulated = o.simulated || by_name(i.driver) || by_name(i.transport);
      continue;
    }
    o.simulated = o.simulated || i.origin == "simulated" ||
                  (i.origin == "replay" && i.origin_detail.find("simulated") != std::string::npos);
    o.replayed = o.replayed || i.origin == "replay";
    o.imported = o.imported || i.origin == "imported";
    const auto g = std::find_if(groups.begin(), groups.end(), [&](const Group& x) {
      return x.origin == i.origin && x.detail == i.origin_detail;
    });
    if (g == groups.end())
      groups.push_back({i.origin, i.origin_detail, {i.driver}});
    else
      g->drivers.push_back(i.driver);
  }
  std::vector<std::string> parts;
  for (const auto& g : groups) {
    std::string names = g.drivers.front();
    for (std::size_t k = 1; k < g.drivers.size(); ++k)
      names += (k + 1 == g.drivers.size() ? " and " : ", ") + g.drivers[k];
    parts.push_back(
        fmt::format("{} {}{}", names, g.origin, g.detail.empty() ? "" : " (" + g.detail + ")"));
  }
  if (instruments.empty()) o.unrecorded = true;
  if (o.unrecorded) o.simulated = o.simulated || by_name(machine_name) || by_name(run.campaign);
  o.text = parts.empty() ? std::string(
                               "the origin of the readings was not recorded (stored "
                               "before caldaq recorded it)")
                         : fmt::format("{}", fmt::join(parts, "; "));
  if (o.unrecorded && !parts.empty()) o.text += "; the other instruments' origin was not recorded";
  return o;
}

namespace {

// Printable ASCII on one line: a control's comment ends at the line, and some controls refuse
// bytes outside ASCII even in comments.
std::string comment_text(std::string_view s) {
  std::string out;
  for (const char c : s) out += c >= ' ' && c <= '~' ? c : '?';
  return out;
}

}  // namespace

std::vector<std::string> table_origin_lines(std::string_view label, std::string_view source,
                                            const std::map<std::string, std::string>& parts) {
  if (label.empty()) return {};
  std::vector<std::string> lines;
  if (parts.empty() || label != "MIXED") {
    lines.push_back(comment_text(label) + " data: do not load into a real control");
  } else {
    lines.push_back(comment_text(label) +
                    " data: do not load into a real control: some errors were not measured on "
                    "the machine");
    // Per origin, the errors it gave, a few names a line (controls limit the line length).
    std::map<std::string, std::vector<std::string>> by_label;
    for (const auto& [name, of] : parts) by_label[comment_text(of)].push_back(comment_text(name));
    for (const auto& [of, names] : by_label)
      for (std::size_t i = 0; i < names.size(); i += 7) {
        const auto end = names.begin() + static_cast<std::ptrdiff_t>(std::min(i + 7, names.size()));
        lines.push_back(fmt::format(
            "  {}: {}", of, fmt::join(names.begin() + static_cast<std::ptrdiff_t>(i), end, ", ")));
      }
  }
  if (!source.empty()) lines.push_back(comment_text(source));
  return lines;
}

nlohmann::json to_json(const RunOrigin& o) {
  return {{"label", o.label()},     {"simulated", o.simulated},  {"replayed", o.replayed},
          {"imported", o.imported}, {"recorded", !o.unrecorded}, {"text", o.text}};
}

}  // namespace daq
