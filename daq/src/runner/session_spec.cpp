#include "session_spec.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdint>
#include <ctime>

#include "cal/analysis/error.hpp"
#include "cal/analysis/text.hpp"
#include "cal/daq/config_fields.hpp"
#include "config_json.hpp"

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

[[noreturn]] void wrong_shape(std::string_view where, std::string_view key, std::string_view want,
                              const json& found) {
  throw cal::InputError(
      fmt::format("{}: key '{}': expected {}, found {}", where, key, want, found.type_name()));
}

// The string at `key`, or `fallback` when it is absent; InputError naming the key otherwise.
std::string text_at(const json& j, const char* key, std::string fallback, std::string_view where) {
  const auto it = j.find(key);
  if (it == j.end() || it->is_null()) return fallback;
  if (!it->is_string()) wrong_shape(where, key, "a string", *it);
  return it->get<std::string>();
}

// The integer at `key` within [lo, hi], or `fallback` when it is absent.
std::int64_t integer_at(const json& j, const char* key, std::int64_t fallback, std::int64_t lo,
                        std::int64_t hi, std::string_view where) {
  const auto it = j.find(key);
  if (it == j.end() || it->is_null()) return fallback;
  if (!it->is_number_integer()) wrong_shape(where, key, "a whole number", *it);
  const bool huge =
      it->is_number_unsigned() && it->get<std::uint64_t>() > static_cast<std::uint64_t>(INT64_MAX);
  const std::int64_t v = huge ? 0 : it->get<std::int64_t>();
  if (huge || v < lo || v > hi)
    throw cal::InputError(
        fmt::format("{}: key '{}': {} is not within {} .. {}", where, key, it->dump(), lo, hi));
  return v;
}

// Three finite numbers at `key`, or `fallback` when it is absent.
std::array<double, 3> vec3_at(const json& j, const char* key, std::array<double, 3> fallback,
                              std::string_view where) {
  const auto it = j.find(key);
  if (it == j.end() || it->is_null()) return fallback;
  if (!it->is_array() || it->size() != 3 ||
      !std::all_of(it->begin(), it->end(), [](const json& e) { return e.is_number(); }))
    wrong_shape(where, key, "an array of 3 numbers", *it);
  return it->get<std::array<double, 3>>();
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
  if (const auto f = j.find("feed"); f != j.end() && f->is_object())
    s.test_axis = static_cast<int>(integer_at(*f, "axis", 0, 0, 2, "capture header: feed"));
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
  j["origin"] = s.origin;
  return j;
}

InstrumentSpec instrument_spec_from_json(const json& j) {
  constexpr std::string_view where = "capture header: instruments[]";
  if (!j.is_object()) wrong_shape("capture header", "instruments[]", "an object", j);
  InstrumentSpec s;
  if (!j.contains("device") || !j.contains("driver"))
    throw cal::InputError(fmt::format("{}: needs the keys 'device' and 'driver'", where));
  s.device = static_cast<std::uint16_t>(integer_at(j, "device", 0, 0, 65535, where));
  s.driver = text_at(j, "driver", "", where);
  const auto* d = cal::drivers::find_driver(s.driver);
  if (!d)
    throw cal::InputError(
        fmt::format("capture header: instrument {}: driver '{}' is not in this build (it has: {})",
                    s.device, s.driver, fmt::join(cal::drivers::driver_names(), ", ")));
  s.role = text_at(j, "role", "", where);
  s.transport = text_at(j, "transport", "", where);
  s.serial_number = text_at(j, "serial_number", "", where);
  s.certificate = text_at(j, "certificate", "", where);
  s.calibration_due = text_at(j, "calibration_due", "", where);
  // Captures recorded before origins were stored do not say: not recorded, never "real".
  s.origin = j.contains("origin") ? text_at(j, "origin", "", where) : "";
  s.options = cal::drivers::Options(d->options());
  if (const auto o = j.find("options"); o != j.end() && o->is_object()) {
    s.test_axis = static_cast<int>(integer_at(j, "test_axis", 0, 0, 2, where));
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
  namespace fd = cal::daq::fields;
  j["environment"] = fields_json(c.environment, fd::environment());
  j["trigger"] = fields_json(c.trigger, fd::trigger());
  if (c.linear) {
    j["linear"] = fields_json(*c.linear, fd::linear());
    j["linear"]["measure"] = measure_json(c.linear->measure);
  }
  if (c.circle) j["circle"] = fields_json(*c.circle, fd::circle());
  return j;
}

json measure_json(const cal::daq::MeasureConfig& m) {
  return fields_json(m, cal::daq::fields::measure());
}

cal::daq::MeasureConfig measure_from_json(const json& j) {
  cal::daq::MeasureConfig m;
  if (j.is_object()) fields_from_json(j, cal::daq::fields::measure(), m, "capture header: measure");
  return m;
}

cal::daq::Config config_from_json(const json& j) {
  constexpr std::string_view where = "capture header: config";
  if (!j.is_object()) wrong_shape("capture header", "config", "an object", j);
  cal::daq::Config c;
  c.machine_name = text_at(j, "machine", "machine", where);
  c.machine_description = text_at(j, "description", "", where);
  c.machine_topology = text_at(j, "topology", "", where);
  c.machine_tool_offset_mm = vec3_at(j, "tool_offset_mm", c.machine_tool_offset_mm, where);
  c.machine_table_offset_mm = vec3_at(j, "table_offset_mm", c.machine_table_offset_mm, where);
  c.campaign = text_at(j, "campaign", "", where);
  // Sections a capture does not have keep the defaults its run used (older captures).
  namespace fd = cal::daq::fields;
  const auto section = [&](const char* key, auto fields, auto& out) {
    if (const auto at = j.find(key); at != j.end())
      fields_from_json(*at, fields, out, fmt::format("capture header: {}", key));
  };
  section("environment", fd::environment(), c.environment);
  section("trigger", fd::trigger(), c.trigger);
  if (const auto l = j.find("linear"); l != j.end()) {
    c.linear.emplace();
    section("linear", fd::linear(), *c.linear);
    if (const auto m = l->find("measure"); m != l->end()) c.linear->measure = measure_from_json(*m);
  }
  if (j.contains("circle")) section("circle", fd::circle(), c.circle.emplace());
  return c;
}

std::string capture_header(const cal::daq::Config& c, const std::vector<InstrumentSpec>& specs,
                           const std::string& software) {
  json j{{"format", "caldaq.capture-header.v1"}, {"software", software}, {"config", to_json(c)}};
  j["started_utc"] = cal::text::utc_text(std::time(nullptr), "%Y-%m-%dT%H:%M:%SZ");
  j["instruments"] = json::array();
  for (const auto& s : specs) j["instruments"].push_back(to_json(s));
  return j.dump(1);
}

}  // namespace daq
