// TOML configuration (see config.hpp and docs/config.md).
#include "cal/daq/config.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <sstream>

#include "cal/analysis/error.hpp"
#include "cal/drivers/registry.hpp"
#include "cal/drivers/transport/transport.hpp"

namespace cal::daq {
namespace {

// Reads keys of one table, remembering which were used so that unknown keys (typos such as
// "feed_mm_min") are refused instead of silently ignored.
class Table {
 public:
  Table(const toml::table& t, std::string path, const std::filesystem::path& file)
      : table_(t), path_(std::move(path)), file_(file) {}

  [[noreturn]] void fail(const toml::node* node, std::string_view key,
                         const std::string& what) const {
    const auto& src = node ? node->source() : table_.source();
    throw InputError(fmt::format("{}:{}:{}: key '{}{}': {}", file_.string(), src.begin.line,
                                 src.begin.column, path_.empty() ? "" : path_ + ".", key, what));
  }

  template <class T>
  std::optional<T> get(std::string_view key) {
    used_.emplace_back(key);
    const toml::node* node = table_.get(key);
    if (!node) return std::nullopt;
    if constexpr (std::is_same_v<T, double>) {
      if (auto v = node->value<double>()) return *v;  // integers convert to double
      fail(node, key, "expected a number");
    } else if constexpr (std::is_same_v<T, int>) {
      if (auto v = node->value<std::int64_t>()) return static_cast<int>(*v);
      fail(node, key, "expected an integer");
    } else if constexpr (std::is_same_v<T, bool>) {
      if (auto v = node->value<bool>()) return *v;
      fail(node, key, "expected true or false");
    } else {
      if (auto v = node->value<std::string>()) return *v;
      fail(node, key, "expected a string");
    }
  }

  template <class T>
  void read(std::string_view key, T& target) {
    if (auto v = get<T>(key)) target = *v;
  }

  void positive(std::string_view key, double& target) {
    read(key, target);
    if (!(target > 0.0)) fail(table_.get(key), key, fmt::format("{} must be > 0", target));
  }

  std::vector<double> numbers(std::string_view key) {
    used_.emplace_back(key);
    std::vector<double> out;
    const toml::node* node = table_.get(key);
    if (!node) return out;
    const auto* arr = node->as_array();
    if (!arr) fail(node, key, "expected an array of numbers");
    for (const auto& e : *arr) {
      const auto v = e.value<double>();
      if (!v) fail(&e, key, "expected an array of numbers");
      out.push_back(*v);
    }
    return out;
  }

  const toml::table* subtable(std::string_view key) {
    used_.emplace_back(key);
    const toml::node* node = table_.get(key);
    if (!node) return nullptr;
    if (!node->is_table()) fail(node, key, "expected a table");
    return node->as_table();
  }

  void check_unknown(const std::string& what = "unknown key (a typo?)") const {
    for (const auto& [k, v] : table_) {
      if (std::find(used_.begin(), used_.end(), k.str()) == used_.end()) fail(&v, k.str(), what);
    }
  }
  void mark_used(std::string_view key) { used_.emplace_back(key); }

  const std::string& path() const { return path_; }
  const std::filesystem::path& file() const { return file_; }
  const toml::node* node(std::string_view key) const { return table_.get(key); }

 private:
  const toml::table& table_;
  std::string path_;
  const std::filesystem::path& file_;
  std::vector<std::string> used_;
};

void one_of(Table& t, std::string_view key, const std::string& value,
            std::initializer_list<std::string_view> allowed) {
  if (std::find(allowed.begin(), allowed.end(), value) == allowed.end())
    t.fail(t.node(key), key,
           fmt::format("'{}' is not one of: {}", value, fmt::join(allowed, ", ")));
}

// A TOML value as an option value of the spec's type (the check against the spec follows).
cal::drivers::OptionValue option_value(const toml::node& node, cal::drivers::OptionType type) {
  using cal::drivers::OptionType;
  switch (type) {
    case OptionType::boolean:
      if (auto v = node.value_exact<bool>()) return *v;
      break;
    case OptionType::integer:
      if (auto v = node.value_exact<std::int64_t>()) return *v;
      break;
    case OptionType::number:
      if (auto v = node.value_exact<std::int64_t>()) return *v;
      if (auto v = node.value_exact<double>()) return *v;
      break;
    case OptionType::string:
    case OptionType::choice:
      if (auto v = node.value_exact<std::string>()) return *v;
      break;
    case OptionType::integer_list:
      if (const auto* arr = node.as_array()) {
        std::vector<std::int64_t> list;
        for (const auto& e : *arr) {
          const auto v = e.value_exact<std::int64_t>();
          if (!v) return std::string("(not an integer)");  // refused by the check
          list.push_back(*v);
        }
        return list;
      }
      break;
  }
  return std::monostate{};  // refused by the check with the type expected
}

// "request, pattern, unit", or "no keys of its own" (for the unknown-key message).
std::string option_names(const cal::drivers::DeviceDriver& d) {
  std::vector<std::string_view> names{cal::drivers::common_device_keys().begin(),
                                      cal::drivers::common_device_keys().end()};
  for (const auto& o : d.options()) names.push_back(o.name);
  return fmt::format("{}", fmt::join(names, ", "));
}

// "2027-03-31": a real calendar date.
bool iso_date(std::string_view s) {
  if (s.size() != 10 || s[4] != '-' || s[7] != '-') return false;
  for (std::size_t i : {0, 1, 2, 3, 5, 6, 8, 9})
    if (s[i] < '0' || s[i] > '9') return false;
  const int y = std::stoi(std::string(s.substr(0, 4))), m = std::stoi(std::string(s.substr(5, 2))),
            d = std::stoi(std::string(s.substr(8, 2)));
  static constexpr int days[] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  const bool leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
  return m >= 1 && m <= 12 && d >= 1 && d <= days[m - 1] + (m == 2 && leap ? 1 : 0);
}

DeviceConfig read_device(const std::string& id, const toml::table& tbl,
                         const std::filesystem::path& file) {
  Table t(tbl, "devices." + id, file);
  DeviceConfig d;
  d.id = id;
  if (!t.get<std::string>("driver")) t.fail(nullptr, "driver", "missing");
  d.driver = *t.get<std::string>("driver");
  const auto names = cal::drivers::driver_names();
  if (std::find(names.begin(), names.end(), d.driver) == names.end())
    t.fail(t.node("driver"), "driver",
           fmt::format("'{}' is not one of: {}", d.driver, fmt::join(names, ", ")));
  const auto& driver = cal::drivers::driver(d.driver);
  if (!t.get<std::string>("transport")) t.fail(nullptr, "transport", "missing");
  d.transport = *t.get<std::string>("transport");
  const std::string kind = d.transport.substr(0, d.transport.find(' '));
  one_of(t, "transport", kind, {"tcp", "serial", "hid"});
  try {
    cal::drivers::transport::check_transport_text(d.transport);
  } catch (const InputError& e) {
    t.fail(t.node("transport"), "transport", e.what());
  }
  t.read("poll_s", d.poll_s);
  if (d.poll_s < 0) t.fail(t.node("poll_s"), "poll_s", "must be >= 0");
  t.read("role", d.role);
  if (!d.role.empty())
    one_of(t, "role", d.role, {"laser", "air", "material", "ballbar", "position"});
  t.read("serial_number", d.serial_number);
  t.read("certificate", d.certificate);
  t.read("calibration_due", d.calibration_due);
  if (!d.calibration_due.empty() && !iso_date(d.calibration_due))
    t.fail(t.node("calibration_due"), "calibration_due",
           fmt::format("'{}' is not a date YYYY-MM-DD", d.calibration_due));
  // The driver's own keys, each checked against its option table.
  d.options = cal::drivers::Options(driver.options());
  for (const auto& spec : driver.options()) {
    const toml::node* node = t.node(spec.name);
    t.mark_used(spec.name);
    if (!node) continue;
    auto checked = cal::drivers::check_option(spec, option_value(*node, spec.type));
    if (!checked.error.empty()) t.fail(node, spec.name, checked.error);
    d.options.set(spec.name, std::move(checked.value));
  }
  try {
    driver.validate(d.options);
  } catch (const InputError& e) {
    t.fail(nullptr, "driver", fmt::format("driver '{}': {}", d.driver, e.what()));
  }
  t.check_unknown(
      fmt::format("unknown key (a typo?); driver '{}' takes {}", d.driver, option_names(driver)));
  return d;
}

EnvironmentConfig read_environment(Table& t) {
  EnvironmentConfig e;
  t.read("equation", e.equation);
  one_of(t, "equation", e.equation, {"ciddor", "edlen", "shop-floor"});
  t.positive("stale_after_s", e.stale_after_s);
  std::string on_stale = "stop";
  t.read("on_stale", on_stale);
  one_of(t, "on_stale", on_stale, {"stop", "fallback"});
  e.on_stale = on_stale == "stop" ? StalePolicy::stop : StalePolicy::fallback;
  t.read("fallback_temperature_degc", e.fallback_temperature_degc);
  t.positive("fallback_pressure_pa", e.fallback_pressure_pa);
  t.read("fallback_humidity_pct", e.fallback_humidity_pct);
  t.read("fallback_material_degc", e.fallback_material_degc);
  t.read("co2_umol_per_mol", e.co2_umol_per_mol);
  t.positive("wavelength_nm", e.wavelength_nm);
  t.read("expansion_ppm_per_k", e.expansion_ppm_per_k);
  t.check_unknown();
  return e;
}

LinearTestConfig read_linear(Table& t) {
  LinearTestConfig l;
  t.read("axis", l.axis);
  one_of(t, "axis", l.axis, {"X", "Y", "Z"});
  t.read("first_mm", l.first_mm);
  t.read("last_mm", l.last_mm);
  l.interval_mm = t.get<double>("interval_mm");
  l.count = t.get<int>("count");
  if (l.interval_mm.has_value() == l.count.has_value())
    t.fail(nullptr, "interval_mm", "give exactly one of interval_mm and count");
  t.read("random_fraction", l.random_fraction);
  t.read("cycle", l.cycle);
  one_of(t, "cycle", l.cycle, {"linear", "pendulum", "pilgrim-step"});
  t.read("runs", l.runs);
  if (l.runs < 1) t.fail(t.node("runs"), "runs", "must be >= 1");
  t.read("bidirectional", l.bidirectional);
  t.read("overrun_mm", l.overrun_mm);
  t.positive("feed_mm_per_min", l.feed_mm_per_min);
  t.positive("dwell_s", l.dwell_s);
  t.read("dead_path_mm", l.dead_path_mm);
  t.read("standard", l.standard);
  t.check_unknown();
  return l;
}

CircleTestConfig read_circle(Table& t) {
  CircleTestConfig c;
  t.read("plane", c.plane);
  one_of(t, "plane", c.plane, {"XY", "YZ", "ZX"});
  t.positive("radius_mm", c.radius_mm);
  t.positive("feed_mm_per_min", c.feed_mm_per_min);
  t.positive("sample_rate_hz", c.sample_rate_hz);
  t.read("overshoot_deg", c.overshoot_deg);
  if (auto centre = t.numbers("centre_mm"); !centre.empty()) {
    if (centre.size() != 3) t.fail(t.node("centre_mm"), "centre_mm", "expected [x, y, z]");
    c.centre_mm = centre;
  }
  t.read("calibrated_radius_mm", c.calibrated_radius_mm);
  t.check_unknown();
  return c;
}

}  // namespace

const DeviceConfig* Config::device_for(std::string_view role) const {
  for (const auto& d : devices)
    if (d.role == role) return &d;
  return nullptr;
}

Config parse_config(std::string_view text, const std::filesystem::path& file) {
  toml::table root;
  try {
    root = toml::parse(text, file.string());
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}:{}:{}: {}", file.string(), e.source().begin.line,
                                 e.source().begin.column, e.description()));
  }
  Config c;
  c.source = file;
  Table top(root, "", file);
  if (const auto* m = top.subtable("machine")) {
    Table t(*m, "machine", file);
    t.read("name", c.machine_name);
    t.read("description", c.machine_description);
    t.check_unknown();
  }
  top.read("campaign", c.campaign);
  if (const auto* devs = top.subtable("devices")) {
    for (const auto& [k, v] : *devs) {
      if (!v.is_table())
        Table(*devs, "devices", file)
            .fail(&v, k.str(), "expected a table [devices." + std::string(k.str()) + "]");
      c.devices.push_back(read_device(std::string(k.str()), *v.as_table(), file));
    }
  }
  if (const auto* e = top.subtable("environment")) {
    Table t(*e, "environment", file);
    c.environment = read_environment(t);
  }
  if (const auto* tr = top.subtable("trigger")) {
    Table t(*tr, "trigger", file);
    t.positive("tolerance_um", c.trigger.tolerance_um);
    t.positive("dwell_s", c.trigger.dwell_s);
    t.positive("window_mm", c.trigger.window_mm);
    t.check_unknown();
  }
  if (const auto* tests = top.subtable("test")) {
    Table tt(*tests, "test", file);
    if (const auto* l = tt.subtable("linear")) {
      Table t(*l, "test.linear", file);
      c.linear = read_linear(t);
      if (c.linear->dwell_s <= c.trigger.dwell_s)
        t.fail(t.node("dwell_s"), "dwell_s",
               fmt::format("the programmed dwell {} s must exceed the trigger dwell {} s",
                           c.linear->dwell_s, c.trigger.dwell_s));
    }
    if (const auto* ci = tt.subtable("circle")) {
      Table t(*ci, "test.circle", file);
      c.circle = read_circle(t);
    }
    tt.check_unknown();
  }
  top.check_unknown();
  return c;
}

Config load_config(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw InputError(fmt::format("{}: cannot open", file.string()));
  std::stringstream buffer;
  buffer << in.rdbuf();
  return parse_config(buffer.str(), file);
}

}  // namespace cal::daq
