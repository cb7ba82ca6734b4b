#include "session_spec.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <ctime>

#include "cal/analysis/error.hpp"

namespace daq {

using nlohmann::json;
namespace codec = cal::drivers::codec;

std::unique_ptr<cal::drivers::Instrument> make_instrument(
    boost::asio::io_context& io, const InstrumentSpec& spec,
    std::unique_ptr<cal::drivers::transport::Transport> transport,
    cal::drivers::InstrumentOptions options) {
  options.device = spec.device;
  return cal::drivers::driver(spec.driver)
      .make_instrument(io, std::move(transport), std::move(options), spec.options, spec.context());
}

namespace {

using cal::drivers::OptionType;
using cal::drivers::OptionValue;

json option_json(const OptionValue& v) {
  return std::visit(
      [](const auto& x) -> json {
        if constexpr (std::is_same_v<std::decay_t<decltype(x)>, std::monostate>)
          return nullptr;
        else
          return x;
      },
      v);
}

// A JSON value as an option value of the spec's type; the table's check follows.
OptionValue option_value(const json& v, const cal::drivers::OptionSpec& spec) {
  switch (spec.type) {
    case OptionType::boolean:
      if (v.is_boolean()) return v.get<bool>();
      break;
    case OptionType::integer:
      if (v.is_number_integer()) return v.get<std::int64_t>();
      break;
    case OptionType::number:
      if (v.is_number()) return v.get<double>();
      break;
    case OptionType::string:
    case OptionType::choice:
      if (v.is_string()) return v.get<std::string>();
      break;
    case OptionType::integer_list:
      if (v.is_array() &&
          std::all_of(v.begin(), v.end(), [](const json& e) { return e.is_number_integer(); }))
        return v.get<std::vector<std::int64_t>>();
      break;
  }
  return std::monostate{};
}

void set_option(cal::drivers::Options& options, const cal::drivers::OptionSpec& spec, const json& v,
                const InstrumentSpec& s) {
  if (v.is_null()) return;  // no value: the table's derived default
  auto checked = cal::drivers::check_option(spec, option_value(v, spec));
  if (!checked.error.empty())
    throw cal::InputError(fmt::format("capture header: instrument {} ({}): option '{}' = {}: {}",
                                      s.device, s.driver, spec.name, v.dump(), checked.error));
  options.set(spec.name, std::move(checked.value));
}

// Entries written before the option tables: each driver says where its settings were.
void read_legacy_options(const json& j, const cal::drivers::DeviceDriver& d, InstrumentSpec& s) {
  for (const auto& key : d.legacy_keys()) {
    const auto* spec = cal::drivers::find_option(d.options(), key.option);
    if (!spec) continue;
    if (key.pointer.empty()) {
      s.options.set(spec->name, cal::drivers::parse_option_text(*spec, key.literal));
      continue;
    }
    const json::json_pointer ptr{std::string(key.pointer)};
    if (!j.contains(ptr)) continue;
    json v = j.at(ptr);
    if (key.form == cal::drivers::LegacyKey::Form::bool_mask_to_indices && v.is_array()) {
      json indices = json::array();
      for (std::size_t i = 0; i < v.size(); ++i)
        if (v[i].is_boolean() && v[i].get<bool>()) indices.push_back(i);
      v = indices;
    }
    set_option(s.options, *spec, v, s);
  }
  if (const auto f = j.find("feed"); f != j.end()) s.test_axis = f->value("axis", 0);
}

}  // namespace

json to_json(const InstrumentSpec& s) {
  json options = json::object();
  for (const auto& [name, value] : s.options.values())
    if (!std::holds_alternative<std::monostate>(value)) options[name] = option_json(value);
  json j{{"device", s.device},       {"driver", s.driver},       {"role", s.role},
         {"transport", s.transport}, {"test_axis", s.test_axis}, {"options", options}};
  if (!s.serial_number.empty()) j["serial_number"] = s.serial_number;
  if (!s.certificate.empty()) j["certificate"] = s.certificate;
  if (!s.calibration_due.empty()) j["calibration_due"] = s.calibration_due;
  return j;
}

InstrumentSpec instrument_spec_from_json(const json& j) {
  InstrumentSpec s;
  s.device = j.at("device").get<std::uint16_t>();
  s.driver = j.at("driver").get<std::string>();
  const auto* d = cal::drivers::find_driver(s.driver);
  if (!d)
    throw cal::InputError(
        fmt::format("capture header: instrument {}: driver '{}' is not in this build (it has: {})",
                    s.device, s.driver, fmt::join(cal::drivers::driver_names(), ", ")));
  s.role = j.value("role", "");
  s.transport = j.value("transport", "");
  s.serial_number = j.value("serial_number", "");
  s.certificate = j.value("certificate", "");
  s.calibration_due = j.value("calibration_due", "");
  s.options = cal::drivers::Options(d->options());
  if (const auto o = j.find("options"); o != j.end() && o->is_object()) {
    s.test_axis = j.value("test_axis", 0);
    for (const auto& [name, v] : o->items()) {
      const auto* spec = cal::drivers::find_option(d->options(), name);
      if (!spec)
        throw cal::InputError(fmt::format(
            "capture header: instrument {} ({}): option '{}' is not known to this build", s.device,
            s.driver, name));
      set_option(s.options, *spec, v, s);
    }
  } else {
    read_legacy_options(j, *d, s);
  }
  d->validate(s.options);
  return s;
}

json to_json(const cal::daq::Config& c) {
  json j{{"machine", c.machine_name},
         {"description", c.machine_description},
         {"topology", c.machine_topology},
         {"tool_offset_mm", c.machine_tool_offset_mm},
         {"table_offset_mm", c.machine_table_offset_mm},
         {"campaign", c.campaign}};
  const auto& e = c.environment;
  j["environment"] = {{"equation", e.equation},
                      {"stale_after_s", e.stale_after_s},
                      {"on_stale", e.on_stale == cal::daq::StalePolicy::stop ? "stop" : "fallback"},
                      {"fallback_temperature_degc", e.fallback_temperature_degc},
                      {"fallback_pressure_pa", e.fallback_pressure_pa},
                      {"fallback_humidity_pct", e.fallback_humidity_pct},
                      {"fallback_material_degc", e.fallback_material_degc},
                      {"co2_umol_per_mol", e.co2_umol_per_mol},
                      {"wavelength_nm", e.wavelength_nm},
                      {"expansion_ppm_per_k", e.expansion_ppm_per_k}};
  j["trigger"] = {{"tolerance_um", c.trigger.tolerance_um},
                  {"dwell_s", c.trigger.dwell_s},
                  {"window_mm", c.trigger.window_mm}};
  if (c.linear) {
    const auto& l = *c.linear;
    j["linear"] = {{"axis", l.axis},
                   {"first_mm", l.first_mm},
                   {"last_mm", l.last_mm},
                   {"random_fraction", l.random_fraction},
                   {"cycle", l.cycle},
                   {"runs", l.runs},
                   {"bidirectional", l.bidirectional},
                   {"overrun_mm", l.overrun_mm},
                   {"feed_mm_per_min", l.feed_mm_per_min},
                   {"dwell_s", l.dwell_s},
                   {"dead_path_mm", l.dead_path_mm},
                   {"standard", l.standard}};
    if (l.interval_mm) j["linear"]["interval_mm"] = *l.interval_mm;
    if (l.count) j["linear"]["count"] = *l.count;
    j["linear"]["measure"] = measure_json(l.measure);
  }
  if (c.circle) {
    const auto& ci = *c.circle;
    j["circle"] = {{"plane", ci.plane},
                   {"radius_mm", ci.radius_mm},
                   {"feed_mm_per_min", ci.feed_mm_per_min},
                   {"sample_rate_hz", ci.sample_rate_hz},
                   {"overshoot_deg", ci.overshoot_deg},
                   {"centre_mm", ci.centre_mm},
                   {"calibrated_radius_mm", ci.calibrated_radius_mm},
                   {"standard", ci.standard},
                   {"planes", ci.planes},
                   {"feeds_mm_per_min", ci.feeds_mm_per_min},
                   {"radii_mm", ci.radii_mm},
                   {"partial_arc_deg", ci.partial_arc_deg},
                   {"partial_overshoot_deg", ci.partial_overshoot_deg},
                   {"feed_in_mm", ci.feed_in_mm},
                   {"dwell_s", ci.dwell_s},
                   {"bar", ci.bar}};
  }
  return j;
}

json measure_json(const cal::daq::MeasureConfig& m) {
  return {{"kind", m.kind},
          {"direction", m.direction},
          {"stationary_mm", m.stationary_mm},
          {"probe_offset_mm", m.probe_offset_mm},
          {"beams", m.beams},
          {"separation_mm", m.separation_mm},
          {"sign", m.sign},
          {"square", m.square}};
}

cal::daq::MeasureConfig measure_from_json(const json& j) {
  cal::daq::MeasureConfig m;
  if (!j.is_object()) return m;
  m.kind = j.value("kind", m.kind);
  m.direction = j.value("direction", m.direction);
  m.stationary_mm = j.value("stationary_mm", m.stationary_mm);
  m.probe_offset_mm = j.value("probe_offset_mm", m.probe_offset_mm);
  m.beams = j.value("beams", m.beams);
  m.separation_mm = j.value("separation_mm", m.separation_mm);
  m.sign = j.value("sign", m.sign);
  m.square = j.value("square", m.square);
  return m;
}

cal::daq::Config config_from_json(const json& j) {
  cal::daq::Config c;
  c.machine_name = j.value("machine", "machine");
  c.machine_description = j.value("description", "");
  c.machine_topology = j.value("topology", "");
  c.machine_tool_offset_mm = j.value("tool_offset_mm", c.machine_tool_offset_mm);
  c.machine_table_offset_mm = j.value("table_offset_mm", c.machine_table_offset_mm);
  c.campaign = j.value("campaign", "");
  if (const auto e = j.find("environment"); e != j.end()) {
    auto& x = c.environment;
    x.equation = e->value("equation", x.equation);
    x.stale_after_s = e->value("stale_after_s", x.stale_after_s);
    x.on_stale = e->value("on_stale", "stop") == "stop" ? cal::daq::StalePolicy::stop
                                                        : cal::daq::StalePolicy::fallback;
    x.fallback_temperature_degc =
        e->value("fallback_temperature_degc", x.fallback_temperature_degc);
    x.fallback_pressure_pa = e->value("fallback_pressure_pa", x.fallback_pressure_pa);
    x.fallback_humidity_pct = e->value("fallback_humidity_pct", x.fallback_humidity_pct);
    x.fallback_material_degc = e->value("fallback_material_degc", x.fallback_material_degc);
    x.co2_umol_per_mol = e->value("co2_umol_per_mol", x.co2_umol_per_mol);
    x.wavelength_nm = e->value("wavelength_nm", x.wavelength_nm);
    x.expansion_ppm_per_k = e->value("expansion_ppm_per_k", x.expansion_ppm_per_k);
  }
  if (const auto t = j.find("trigger"); t != j.end()) {
    c.trigger.tolerance_um = t->value("tolerance_um", c.trigger.tolerance_um);
    c.trigger.dwell_s = t->value("dwell_s", c.trigger.dwell_s);
    c.trigger.window_mm = t->value("window_mm", c.trigger.window_mm);
  }
  if (const auto l = j.find("linear"); l != j.end()) {
    cal::daq::LinearTestConfig x;
    x.axis = l->value("axis", x.axis);
    x.first_mm = l->value("first_mm", x.first_mm);
    x.last_mm = l->value("last_mm", x.last_mm);
    if (l->contains("interval_mm")) x.interval_mm = (*l)["interval_mm"].get<double>();
    if (l->contains("count")) x.count = (*l)["count"].get<int>();
    x.random_fraction = l->value("random_fraction", x.random_fraction);
    x.cycle = l->value("cycle", x.cycle);
    x.runs = l->value("runs", x.runs);
    x.bidirectional = l->value("bidirectional", x.bidirectional);
    x.overrun_mm = l->value("overrun_mm", x.overrun_mm);
    x.feed_mm_per_min = l->value("feed_mm_per_min", x.feed_mm_per_min);
    x.dwell_s = l->value("dwell_s", x.dwell_s);
    x.dead_path_mm = l->value("dead_path_mm", x.dead_path_mm);
    x.standard = l->value("standard", x.standard);
    if (const auto m = l->find("measure"); m != l->end()) x.measure = measure_from_json(*m);
    c.linear = x;
  }
  if (const auto ci = j.find("circle"); ci != j.end()) {
    cal::daq::CircleTestConfig x;
    x.plane = ci->value("plane", x.plane);
    x.radius_mm = ci->value("radius_mm", x.radius_mm);
    x.feed_mm_per_min = ci->value("feed_mm_per_min", x.feed_mm_per_min);
    x.sample_rate_hz = ci->value("sample_rate_hz", x.sample_rate_hz);
    x.overshoot_deg = ci->value("overshoot_deg", x.overshoot_deg);
    x.centre_mm = ci->value("centre_mm", x.centre_mm);
    x.calibrated_radius_mm = ci->value("calibrated_radius_mm", x.calibrated_radius_mm);
    // The ballbar set and the program's feed-in and dwell (captures since issue 18; older ones
    // have the defaults their runs used).
    x.standard = ci->value("standard", x.standard);
    x.planes = ci->value("planes", x.planes);
    x.feeds_mm_per_min = ci->value("feeds_mm_per_min", x.feeds_mm_per_min);
    x.radii_mm = ci->value("radii_mm", x.radii_mm);
    x.partial_arc_deg = ci->value("partial_arc_deg", x.partial_arc_deg);
    x.partial_overshoot_deg = ci->value("partial_overshoot_deg", x.partial_overshoot_deg);
    x.feed_in_mm = ci->value("feed_in_mm", x.feed_in_mm);
    x.dwell_s = ci->value("dwell_s", x.dwell_s);
    x.bar = ci->value("bar", x.bar);
    c.circle = x;
  }
  return c;
}

std::string capture_header(const cal::daq::Config& c, const std::vector<InstrumentSpec>& specs,
                           const std::string& software) {
  json j{{"format", "caldaq.capture-header.v1"}, {"software", software}, {"config", to_json(c)}};
  const std::time_t now = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&now, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  j["started_utc"] = buf;
  j["instruments"] = json::array();
  for (const auto& s : specs) j["instruments"].push_back(to_json(s));
  return j.dump(1);
}

}  // namespace daq
