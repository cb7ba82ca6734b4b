// The set-up of the operator's page (see setup_form.hpp).
#include "serve/setup_form.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <regex>
#include <sstream>
#include <type_traits>
#include <variant>

#include "cal/analysis/error.hpp"
#include "cal/daq/config_fields.hpp"
#include "cal/drivers/registry.hpp"
#include "config_json.hpp"
#include "run_setup.hpp"

namespace daq::serve {

using nlohmann::json;

namespace {

// Adds key = value when the value differs from the default (the file's own choices).
template <class T>
void put(json& j, const char* key, const T& value, const T& default_value) {
  if (!(value == default_value)) j[key] = value;
}
void put_text(json& j, const char* key, const std::string& value) {
  if (!value.empty()) j[key] = value;
}

json device_json(const cal::daq::DeviceConfig& d) {
  const cal::daq::DeviceConfig def;
  json j{{"driver", d.driver}, {"transport", d.transport}};
  put_text(j, "role", d.role);
  // A simulated twin's origin goes through the form (a run records it: docs/storage.md "Origin").
  put(j, "origin", d.origin, def.origin);
  put(j, "poll_s", d.poll_s, def.poll_s);
  // The driver's own options as the file gave them (the others keep the table's defaults).
  for (const auto& [name, value] : d.options.values())
    if (d.options.is_set(name)) j[name] = option_json(value);
  put_text(j, "serial_number", d.serial_number);
  put_text(j, "certificate", d.certificate);
  put_text(j, "calibration_due", d.calibration_due);
  return j;
}

// A section's keys as a file would write them (config_fields.hpp): those the form always shows
// and those not at their default.
template <class S>
json section_json(const S& s, std::span<const cal::daq::fields::Field<S>> fields) {
  return fields_json(s, fields, FieldKeys::file, FieldValues::set);
}

json linear_json(const cal::daq::LinearTestConfig& l) {
  json j = section_json(l, cal::daq::fields::linear());
  j.update(section_json(l.measure, cal::daq::fields::measure()));  // flat in [test.linear]
  return j;
}

json circle_json(const cal::daq::CircleTestConfig& c) {
  json j = section_json(c, cal::daq::fields::circle());
  if (!c.planes.empty()) j.erase("plane");  // a set names its planes; the loader takes one
  return j;
}

json tolerances_json(const cal::daq::Config& c) {
  json j = json::object();
  for (const auto& [axis, t] : c.axis_tolerances) {
    json a = limits_json(t.limits);
    for (const auto& [up_to, limits] : t.by_length) {
      json b = limits_json(limits);
      b["up_to_mm"] = up_to;
      a["by_length"].push_back(b);
    }
    j[axis] = a;
  }
  for (const auto& [plane, t] : c.plane_tolerances) {
    json p = json::object();
    if (t.G_um) p["G_um"] = *t.G_um;
    if (!t.diagnostics.empty()) p["diagnostics"] = t.diagnostics;
    j[plane] = p;
  }
  return j;
}

// A TOML basic string: quotes, backslashes and control characters escaped (any text the
// operator types stays one string).
std::string toml_string(const std::string& text) {
  std::string out = "\"";
  for (unsigned char c : text) {
    switch (c) {
      case '"':
        out += "\\\"";
        break;
      case '\\':
        out += "\\\\";
        break;
      case '\n':
        out += "\\n";
        break;
      case '\t':
        out += "\\t";
        break;
      case '\r':
        out += "\\r";
        break;
      default:
        if (c < 0x20 || c == 0x7f)
          out += fmt::format("\\u{:04X}", c);
        else
          out += static_cast<char>(c);
    }
  }
  return out + "\"";
}

// --- JSON -> TOML -------------------------------------------------------------------------------
// Written here rather than by toml++'s formatter: numbers in their shortest exact form (0.05,
// not 0.050000000000000003) and keys in the order docs/config.md gives them. Whatever is
// written is read back by the loader before it is used or offered, so a mistake here shows as
// a problem, never as a wrong file.

[[noreturn]] void cannot(const std::string& path, const std::string& what) {
  throw cal::InputError(fmt::format("set-up: '{}': {}", path.empty() ? "(top)" : path, what));
}

// The keys of a table in the order of docs/config.md; others follow in alphabetical order.
// (The sections with a field table, and devices, are in their table's order: own_key_order.)
const std::vector<std::string_view>& key_order() {
  static const std::vector<std::string_view> order{"schema",
                                                   "campaign",
                                                   "operator",
                                                   "name",
                                                   "driver",
                                                   "transport",
                                                   "role",
                                                   "site",
                                                   "contact",
                                                   "description",
                                                   "make",
                                                   "model",
                                                   "serial_number",
                                                   "topology",
                                                   "tool_offset_mm",
                                                   "table_offset_mm",
                                                   "certificate",
                                                   "calibration_due",
                                                   "controller_compensation",
                                                   "warm_up",
                                                   "load",
                                                   "state",
                                                   "notes",
                                                   "poll_s",
                                                   "up_to_mm",
                                                   "E_um",
                                                   "R_um",
                                                   "B_um",
                                                   "A_um",
                                                   "M_um",
                                                   "P_um",
                                                   "Pa_um",
                                                   "Ps_um",
                                                   "U_um",
                                                   "straightness_um",
                                                   "angular_urad",
                                                   "E_arcsec",
                                                   "R_arcsec",
                                                   "B_arcsec",
                                                   "A_arcsec",
                                                   "M_arcsec",
                                                   "P_arcsec",
                                                   "Pa_arcsec",
                                                   "Ps_arcsec",
                                                   "U_arcsec",
                                                   "G_um",
                                                   "machine",
                                                   "customer",
                                                   "conditions",
                                                   "devices",
                                                   "environment",
                                                   "trigger",
                                                   "test",
                                                   "linear",
                                                   "circle",
                                                   "tolerances",
                                                   "X",
                                                   "Y",
                                                   "Z",
                                                   "A",
                                                   "B",
                                                   "C",
                                                   "XY",
                                                   "YZ",
                                                   "ZX"};
  return order;
}

// A device's keys: the common ones, then its driver's options in the order of its table.
std::vector<std::string> device_key_order(const json& device) {
  std::vector<std::string> order(cal::drivers::common_device_keys().begin(),
                                 cal::drivers::common_device_keys().end());
  const auto driver = device.find("driver");
  if (driver != device.end() && driver->is_string())
    if (const auto* d = cal::drivers::find_driver(driver->get<std::string>()))
      for (const auto& o : d->options()) order.push_back(o.name);
  return order;
}

template <class S>
void append_keys(std::vector<std::string>& order,
                 std::span<const cal::daq::fields::Field<S>> fields) {
  for (const auto& f : fields) order.emplace_back(f.key);
}

// The order of a table's own keys where a table says it (a device's driver, a section's
// fields), else none.
std::vector<std::string> own_key_order(const json& j, const std::string& path) {
  namespace fd = cal::daq::fields;
  std::vector<std::string> order;
  if (path.starts_with("devices.")) return device_key_order(j);
  if (path == "environment") append_keys(order, fd::environment());
  if (path == "trigger") append_keys(order, fd::trigger());
  if (path == "test.linear") append_keys(order, fd::linear()), append_keys(order, fd::measure());
  if (path == "test.circle") append_keys(order, fd::circle());
  return order;
}

std::vector<std::string> ordered_keys(const json& j, const std::string& path = "") {
  std::vector<std::string> keys;
  for (const auto& [k, v] : j.items()) keys.push_back(k);
  const auto own = own_key_order(j, path);
  const auto rank = [&](const std::string& k) {
    const auto at = std::find(own.begin(), own.end(), k);
    if (at != own.end()) return static_cast<std::size_t>(at - own.begin());
    const auto& o = key_order();
    return own.size() + static_cast<std::size_t>(std::find(o.begin(), o.end(), k) - o.begin());
  };
  std::stable_sort(keys.begin(), keys.end(),
                   [&](const auto& a, const auto& b) { return rank(a) < rank(b); });
  return keys;
}

std::string toml_key(const std::string& k) {
  const bool bare = !k.empty() && std::all_of(k.begin(), k.end(), [](unsigned char c) {
    return std::isalnum(c) || c == '_' || c == '-';
  });
  return bare ? k : toml_string(k);
}

std::string toml_value(const json& v, const std::string& path) {
  if (v.is_boolean()) return v.get<bool>() ? "true" : "false";
  if (v.is_number_integer()) return fmt::format("{}", v.get<std::int64_t>());
  if (v.is_number_unsigned()) return fmt::format("{}", v.get<std::uint64_t>());
  if (v.is_number()) {
    auto s = fmt::format("{}", v.get<double>());  // the shortest text that reads back exactly
    if (s.find_first_of(".en") == std::string::npos) s += ".0";
    return s;
  }
  if (v.is_string()) return toml_string(v.get<std::string>());
  if (v.is_array()) {
    std::string out = "[";
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (v[i].is_object() || v[i].is_array() || v[i].is_null())
        cannot(path, "a list may hold only numbers, text and true/false here");
      out += (i ? ", " : "") + toml_value(v[i], path);
    }
    return out + "]";
  }
  cannot(path, fmt::format("{} cannot be written", v.type_name()));
}

bool is_table_array(const json& v) {
  return v.is_array() && !v.empty() &&
         std::all_of(v.begin(), v.end(), [](const json& e) { return e.is_object(); });
}

// Writes the table `j` at `path`: its plain keys under its header, then its sub-tables.
void write_table(std::ostringstream& out, const json& j, const std::string& path,
                 bool array_entry = false) {
  if (!j.is_object()) cannot(path, fmt::format("expected an object, not {}", j.type_name()));
  std::ostringstream own;
  for (const auto& k : ordered_keys(j, path)) {
    const auto& v = j[k];
    if (v.is_null() || v.is_object() || is_table_array(v)) continue;
    own << toml_key(k) << " = " << toml_value(v, path.empty() ? k : path + "." + k) << "\n";
  }
  if (array_entry)
    out << "\n[[" << path << "]]\n" << own.str();
  else if (!own.str().empty())
    out << (path.empty() ? "" : "\n[" + path + "]\n") << own.str();
  for (const auto& k : ordered_keys(j)) {
    const auto& v = j[k];
    const std::string p = path.empty() ? toml_key(k) : path + "." + toml_key(k);
    if (v.is_object()) write_table(out, v, p);
    if (is_table_array(v))
      for (const auto& e : v) write_table(out, e, p, true);
  }
}

// "FILE:LINE:COL: key 'test.linear.first_mm': -5 must be ..." -> {key, message}; a table's own
// error ("table [test.linear]: ...") is keyed by the table.
SetupProblem problem_of(const std::string& what) {
  static const std::regex keyed(R"(^.*?:\d+:\d+: key '([^']*)': (.*)$)");
  static const std::regex table(R"(^.*?:\d+:\d+: table \[([^\]]*)\]: (.*)$)");
  std::smatch m;
  if (std::regex_match(what, m, keyed) || std::regex_match(what, m, table))
    return {m[1].str(), m[2].str()};
  return {"", what};
}

// Removes a key path from the set-up; false if it was not there.
bool erase_path(json& j, const std::string& path) {
  json* at = &j;
  std::stringstream parts(path);
  std::vector<std::string> keys;
  for (std::string k; std::getline(parts, k, '.');) keys.push_back(k);
  if (keys.empty()) return false;
  for (std::size_t i = 0; i + 1 < keys.size(); ++i) {
    if (!at->is_object() || !at->contains(keys[i])) return false;
    at = &(*at)[keys[i]];
  }
  return at->is_object() && at->erase(keys.back()) > 0;
}

// The checks a run makes when it starts, beyond the loader's: the roles a test needs, each
// device's driver and transport.
// (The loader itself checks each transport's text and each option against its driver's table.)
void check_tests(const cal::daq::Config& c, SetupCheck& out) {
  const auto readiness = [](bool configured, auto check) {
    TestReadiness r{.configured = configured};
    if (!configured) return r;
    try {
      check();
    } catch (const cal::InputError& e) {
      r.problem = e.what();
    }
    return r;
  };
  out.linear = readiness(c.linear.has_value(), [&] { linear_specs(c); });
  out.circle = readiness(c.circle.has_value(), [&] { ballbar_device(c); });
}

}  // namespace

json setup_of(const cal::daq::Config& c) {
  json j{{"schema", "caldaq.setup.v1"}};
  put_text(j, "campaign", c.campaign);
  put_text(j, "operator", c.operator_name);
  json m{{"name", c.machine_name}};
  put_text(m, "description", c.machine_description);
  put_text(m, "make", c.machine_make);
  put_text(m, "model", c.machine_model);
  put_text(m, "serial_number", c.machine_serial);
  // The kinematic chain and its offsets (stored with every run for `daq model build`): a set-up
  // applied from the page lost them, and the page's model was refused ("give --topology").
  put_text(m, "topology", c.machine_topology);
  for (const auto& [key, v] : {std::pair{"tool_offset_mm", &c.machine_tool_offset_mm},
                               std::pair{"table_offset_mm", &c.machine_table_offset_mm}})
    if (*v != std::array<double, 3>{}) m[key] = *v;
  j["machine"] = m;
  json cu = json::object();
  put_text(cu, "name", c.customer.name);
  put_text(cu, "site", c.customer.site);
  put_text(cu, "contact", c.customer.contact);
  if (!cu.empty()) j["customer"] = cu;
  json co = json::object();
  if (c.conditions.controller_compensation)
    co["controller_compensation"] = *c.conditions.controller_compensation;
  put_text(co, "warm_up", c.conditions.warm_up);
  put_text(co, "load", c.conditions.load);
  put_text(co, "state", c.conditions.state);
  put_text(co, "notes", c.conditions.notes);
  if (!co.empty()) j["conditions"] = co;
  j["devices"] = json::object();
  for (const auto& d : c.devices) j["devices"][d.id] = device_json(d);
  j["environment"] = section_json(c.environment, cal::daq::fields::environment());
  j["trigger"] = section_json(c.trigger, cal::daq::fields::trigger());
  j["test"] = json::object();
  if (c.linear) j["test"]["linear"] = linear_json(*c.linear);
  if (c.circle) j["test"]["circle"] = circle_json(*c.circle);
  if (auto t = tolerances_json(c); !t.empty()) j["tolerances"] = t;
  return j;
}

std::string setup_toml(const json& setup) {
  json s = setup;
  if (s.is_object()) s.erase("schema");  // the page's, not the file's
  std::ostringstream out;
  out << "# Written by the caldaq operator's page (daq serve): a set-up that `daq run -c` reads\n"
         "# (docs/config.md).\n";
  write_table(out, s, "");
  return out.str();
}

SetupCheck check_setup(const json& setup, std::string_view source_name) {
  SetupCheck out;
  json current = setup;
  for (int round = 0; round < 50; ++round) {
    std::string text;
    try {
      text = setup_toml(current);
    } catch (const cal::InputError& e) {
      out.problems.push_back({"", e.what()});
      return out;
    }
    if (round == 0) out.toml = text;
    try {
      auto config = cal::daq::parse_config(text, std::string(source_name));
      if (out.problems.empty()) {
        check_tests(config, out);
        if (out.problems.empty()) out.config = std::move(config);
      }
      return out;
    } catch (const cal::InputError& e) {
      auto p = problem_of(e.what());
      // A required key taken out is then "missing": that is the first problem again.
      const bool again = std::any_of(out.problems.begin(), out.problems.end(),
                                     [&](const SetupProblem& q) { return q.key == p.key; });
      if (again) return out;
      out.problems.push_back(p);
      // Read the rest without the key at fault; a table's own error, or a key that is not
      // there (a required key missing), ends the search.
      if (p.key.empty() || !erase_path(current, p.key)) return out;
    }
  }
  return out;
}

json to_json(const SetupCheck& c) {
  json problems = json::array();
  for (const auto& p : c.problems) problems.push_back({{"key", p.key}, {"message", p.message}});
  const auto test = [](const TestReadiness& r) {
    return json{{"configured", r.configured},
                {"problem", r.problem ? json(*r.problem) : json(nullptr)}};
  };
  return {{"ok", c.problems.empty()},
          {"problems", problems},
          {"tests", {{"linear", test(c.linear)}, {"circle", test(c.circle)}}}};
}

}  // namespace daq::serve
