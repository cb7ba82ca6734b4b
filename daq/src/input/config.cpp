// TOML configuration (see config.hpp and docs/config.md).
#include "cal/daq/config.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <span>
#include <sstream>

#include "cal/analysis/air.hpp"
#include "cal/analysis/circle_standards.hpp"
#include "cal/analysis/error.hpp"
#include "cal/analysis/iso230_2.hpp"
#include "cal/analysis/iso230_2_targets.hpp"
#include "cal/analysis/kinematics.hpp"
#include "cal/analysis/text.hpp"
#include "cal/daq/config_fields.hpp"
#include "cal/drivers/registry.hpp"
#include "cal/drivers/transport/transport.hpp"
#include "config_tolerances.hpp"

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
    const std::string where =
        key.empty() ? fmt::format("table [{}]", path_)
                    : fmt::format("key '{}{}'", path_.empty() ? "" : path_ + ".", key);
    throw InputError(fmt::format("{}:{}:{}: {}: {}", file_.string(), src.begin.line,
                                 src.begin.column, where, what));
  }

  template <class T>
  std::optional<T> get(std::string_view key) {
    used_.emplace_back(key);
    const toml::node* node = table_.get(key);
    if (!node) return std::nullopt;
    if constexpr (std::is_same_v<T, double>) {
      if (auto v = node->value<double>()) {  // integers convert to double
        if (!std::isfinite(*v)) fail(node, key, fmt::format("{} is not a finite number", *v));
        return *v;
      }
      fail(node, key, "expected a number");
    } else if constexpr (std::is_same_v<T, int>) {
      // TOML integers are 64-bit: 4294967297 must not wrap to 1. Only integer nodes: toml++
      // converts a float such as 3.3e49 to int64 without a range check (undefined
      // behaviour, found by fuzz_config).
      if (auto v = node->is_integer() ? node->value<std::int64_t>() : std::nullopt) {
        if (*v < std::numeric_limits<int>::min() || *v > std::numeric_limits<int>::max())
          fail(node, key, fmt::format("{} is out of range", *v));
        return static_cast<int>(*v);
      }
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

  // A number within a range (config_fields.hpp), the unit named in the message.
  void check_range(std::string_view key, double value, const fields::Range& range) const {
    if (auto e = fields::range_error(range, value)) fail(table_.get(key), key, *e);
  }
  // A name: no control characters (it reaches logs, reports and exports), at most 200 bytes.
  void name(std::string_view key, std::string& target, bool lines_allowed = false) {
    read(key, target);
    for (unsigned char c : target)
      if ((c < 0x20 && !(lines_allowed && (c == '\n' || c == '\t'))) || c == 0x7f)
        fail(table_.get(key), key, "control characters are not allowed");
    if (target.size() > (lines_allowed ? 4000u : 200u))
      fail(table_.get(key), key, fmt::format("{} bytes is too long", target.size()));
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

  void known(std::string_view key) { used_.emplace_back(key); }  // read by the caller

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

// YYYY-MM-DD with a month 1..12 and a day that month can have.
bool iso_date(std::string_view s) {
  if (s.size() != 10 || s[4] != '-' || s[7] != '-') return false;
  for (std::size_t i : {0, 1, 2, 3, 5, 6, 8, 9})
    if (s[i] < '0' || s[i] > '9') return false;
  const int y = std::stoi(std::string(s.substr(0, 4))), m = std::stoi(std::string(s.substr(5, 2))),
            d = std::stoi(std::string(s.substr(8, 2)));
  static constexpr int days[] = {31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
  if (m < 1 || m > 12 || d < 1 || d > days[m - 1]) return false;
  const bool leap = (y % 4 == 0 && y % 100 != 0) || y % 400 == 0;
  return !(m == 2 && d == 29 && !leap);
}

// A limit: a finite number > 0 (TOML allows nan and inf, which are no limits).
std::optional<double> limit(Table& t, std::string_view key) {
  const auto v = t.get<double>(key);
  if (v && !(std::isfinite(*v) && *v > 0))
    t.fail(t.node(key), key, fmt::format("a limit is a finite number > 0, not {}", *v));
  return v;
}

PositioningLimits read_limits(Table& t) {
  PositioningLimits l;
  for (const auto& k : cal::daq::positioning_limit_keys) l.*k.member = limit(t, k.key);
  return l;
}

void one_of(Table& t, std::string_view key, const std::string& value,
            std::span<const std::string_view> allowed) {
  if (std::find(allowed.begin(), allowed.end(), value) == allowed.end())
    t.fail(t.node(key), key,
           fmt::format("'{}' is not one of: {}", value, fmt::join(allowed, ", ")));
}
void one_of(Table& t, std::string_view key, const std::string& value,
            std::initializer_list<std::string_view> allowed) {
  one_of(t, key, value, std::span(allowed.begin(), allowed.size()));
}

template <class S>
void check_number(Table& t, const fields::Field<S>& f, const toml::node& node, double v) {
  if (auto e = fields::number_error(f, v)) t.fail(&node, f.key, *e);
}

template <class S>
void check_word(Table& t, const fields::Field<S>& f, const toml::node& node, std::string_view v) {
  if (auto e = fields::text_error(f, v)) t.fail(&node, f.key, *e);
}

template <class S, class V>
void read_list(Table& t, const fields::Field<S>& f, const toml::node& node, V& target) {
  const auto* arr = node.as_array();
  using E = std::decay_t<decltype(target[0])>;
  constexpr bool words = std::is_same_v<E, std::string>;
  const char* expected = words                    ? "expected an array of strings"
                         : std::is_same_v<E, int> ? "expected an array of integers"
                                                  : "expected an array of numbers";
  if (!arr) t.fail(&node, f.key, expected);
  std::vector<E> values;
  for (const auto& e : *arr) {
    if constexpr (words) {
      const auto v = e.value_exact<std::string>();
      if (!v) t.fail(&e, f.key, expected);
      check_word(t, f, e, *v);
      if (std::find(values.begin(), values.end(), *v) != values.end())
        t.fail(&e, f.key, fmt::format("'{}' given twice", *v));
      values.push_back(*v);
    } else {
      std::optional<double> v;
      if constexpr (std::is_same_v<E, int>) {
        if (const auto i = e.value_exact<std::int64_t>()) v = static_cast<double>(*i);
      } else {
        v = e.value<double>();
      }
      if (!v) t.fail(&e, f.key, expected);
      check_number(t, f, node, *v);  // the position of the list, as for its other checks
      values.push_back(static_cast<E>(*v));
    }
  }
  if constexpr (std::is_same_v<V, std::vector<E>>) {
    target = std::move(values);
  } else {  // std::array: exactly its size
    if (values.size() != target.size())
      t.fail(&node, f.key,
             target.size() == 3 ? std::string("expected [x, y, z]")
                                : fmt::format("expected {} values", target.size()));
    std::copy(values.begin(), values.end(), target.begin());
  }
}

template <class S, class V>
void read_field(Table& t, const fields::Field<S>& f, const toml::node& node, V& target) {
  if constexpr (std::is_same_v<V, double> || std::is_same_v<V, int>) {
    target = *t.get<V>(f.key);
    check_number(t, f, node, target);
  } else if constexpr (std::is_same_v<V, bool>) {
    target = *t.get<bool>(f.key);
  } else if constexpr (std::is_same_v<V, std::string>) {
    target = *t.get<std::string>(f.key);
    check_word(t, f, node, target);
  } else if constexpr (std::is_same_v<V, StalePolicy>) {
    const auto word = *t.get<std::string>(f.key);
    check_word(t, f, node, word);
    target = *fields::stale_policy(word);
  } else if constexpr (std::is_same_v<V, std::optional<double>> ||
                       std::is_same_v<V, std::optional<int>>) {
    typename V::value_type v{};
    read_field(t, f, node, v);
    target = v;
  } else {  // lists: of numbers, words, or a fixed count of numbers
    read_list(t, f, node, target);
  }
}

// Reads the keys of a section's field table (config_fields.hpp): each present key with its
// type, range or words checked; absent keys keep their defaults.
template <class S>
void read_fields(Table& t, std::span<const fields::Field<S>> table, S& out) {
  for (const auto& f : table) {
    t.mark_used(f.key);
    const toml::node* node = t.node(f.key);
    if (!node) continue;
    std::visit([&](auto member) { read_field(t, f, *node, out.*member); }, f.member);
  }
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
  if (!d.role.empty()) one_of(t, "role", d.role, device_roles);
  t.read("origin", d.origin);
  one_of(t, "origin", d.origin, {"real", "simulated"});
  t.name("serial_number", d.serial_number);
  t.name("certificate", d.certificate);
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

// The keys and their ranges are the field table's (config_fields.cpp); the fallback air is
// then checked against the chosen equation itself.
EnvironmentConfig read_environment(Table& t) {
  EnvironmentConfig e;
  read_fields(t, fields::environment(), e);
  try {
    air::refractive_index({.temperature_degc = e.fallback_temperature_degc,
                           .pressure_pa = e.fallback_pressure_pa,
                           .humidity = air::Humidity::relative_pct(e.fallback_humidity_pct),
                           .co2_umol_per_mol = e.co2_umol_per_mol,
                           .wavelength_vacuum_nm = e.wavelength_nm},
                          air::equation_from_string(e.equation));
  } catch (const InputError& err) {
    t.fail(t.node("equation"), "equation", fmt::format("with the fallback air: {}", err.what()));
  }
  t.check_unknown();
  return e;
}

// The machine's offsets: positions within +-100 m (as the tests' positions, config_fields.cpp).
constexpr double kMaxPositionMm = 100'000;

std::array<double, 3> read_vector(Table& t, std::string_view key, std::array<double, 3> v) {
  if (!t.node(key)) {
    t.numbers(key);  // marks it used
    return v;
  }
  const auto x = t.numbers(key);
  if (x.size() != 3) t.fail(t.node(key), key, "expected [x, y, z]");
  for (std::size_t k = 0; k < 3; ++k) {
    t.check_range(key, x[k], {-kMaxPositionMm, kMaxPositionMm, "mm"});
    v[k] = x[k];
  }
  return v;
}

// The measure keys of [test.linear]: what is read at each stop (MeasureConfig). The kinds'
// own checks of the set-up (a separation across the beams, a direction that is not the axis)
// are the kinds' (daq/src/runner/kinds/), run before a run starts.
void read_measure(Table& t, LinearTestConfig& l) {
  auto& m = l.measure;
  read_fields(t, fields::measure(), m);
  // A rotary axis (A, B, C) has its own kind; every other kind measures a linear axis.
  const bool rotary_axis = l.axis == "A" || l.axis == "B" || l.axis == "C";
  if (rotary_axis != (m.kind == "rotary"))
    t.fail(
        t.node("axis"), "axis",
        rotary_axis
            ? fmt::format("a rotary axis {} is measured by measure = \"rotary\"", l.axis)
            : fmt::format("measure = \"rotary\" measures a rotary axis (A, B, C), not {}", l.axis));
  if (!m.reference.empty() && m.kind != "rotary")
    t.fail(t.node("reference"), "reference",
           "the angular reference's kind applies to a rotary test (measure = \"rotary\")");
  if (!m.reference.empty())  // "" (not given): not stated
    one_of(t, "reference", m.reference, {"laser", "autocollimator", "level", "encoder"});
  if (m.kind == "straightness") {
    one_of(t, "direction", m.direction, {"X", "Y", "Z"});
    if (m.direction == l.axis)
      t.fail(
          t.node("direction"), "direction",
          fmt::format("a straightness of {} is read across it, not along {}", l.axis, m.direction));
  } else if (m.kind == "angular") {
    one_of(t, "direction", m.direction, {"A", "B", "C"});
    if (m.direction == std::string(1, static_cast<char>('A' + (l.axis[0] - 'X'))))
      t.fail(t.node("direction"), "direction",
             fmt::format("{} about {} is the roll of {}: measure = \"roll\"", m.direction, l.axis,
                         l.axis));
  } else if (!m.direction.empty()) {
    t.fail(t.node("direction"), "direction",
           fmt::format("a {} test has no direction (straightness: X, Y, Z; angular: A, B, C)",
                       m.kind));
  }
  if (m.beams[0] == m.beams[1])
    t.fail(t.node("beams"), "beams", "expected two different laser axes [a, b] of 0, 1, 2");
  if (m.sign != 1.0 && m.sign != -1.0)
    t.fail(t.node("sign"), "sign", fmt::format("{} must be 1 or -1", m.sign));
  if (m.square && m.kind != "straightness")
    t.fail(t.node("square"), "square", "only a straightness run is read against a square");
  if (m.kind == "angular" && m.separation_mm == std::array<double, 3>{})
    t.fail(nullptr, "separation_mm",
           "an angular test needs the separation of its two beams' reflectors [x, y, z]");
}

LinearTestConfig read_linear(Table& t) {
  LinearTestConfig l;
  read_fields(t, fields::linear(), l);
  // Neither is allowed on an axis over 2000 mm: ISO 230-2's average interval of 250 mm.
  const bool long_axis = cal::iso230_2::is_long_axis(l.first_mm, l.last_mm);
  if ((l.interval_mm && l.count) || (!l.interval_mm && !l.count && !long_axis))
    t.fail(nullptr, "interval_mm",
           "give exactly one of interval_mm and count (or neither on an axis over 2000 mm: "
           "targets an average of 250 mm apart, ISO 230-2)");
  try {  // a misspelt standard is refused now, not after every stop has been captured
    iso230_2::standard_from_string(l.standard);
  } catch (const InputError& e) {
    t.fail(t.node("standard"), "standard", e.what());
  }
  try {  // the combination: travel, interval or count, cycle
    iso230_2::make_plan({.first_mm = l.first_mm,
                         .last_mm = l.last_mm,
                         .interval_mm = l.interval_mm,
                         .count = l.count,
                         .random_fraction = l.random_fraction},
                        {.cycle = iso230_2::cycle_from_string(l.cycle),
                         .bidirectional = l.bidirectional,
                         .runs = l.runs,
                         .overrun_mm = l.overrun_mm});
  } catch (const InputError& e) {
    t.fail(nullptr, "", e.what());
  }
  read_measure(t, l);
  t.check_unknown();
  return l;
}

CircleTestConfig read_circle(Table& t) {
  CircleTestConfig c;
  read_fields(t, fields::circle(), c);
  if (t.node("centre_mm") && c.centre_mm.size() != 3)
    t.fail(t.node("centre_mm"), "centre_mm", "expected [x, y, z]");
  if (t.node("planes") && c.planes.empty())
    t.fail(t.node("planes"), "planes",
           "expected an array of planes, e.g. [\"XY\", \"ZX\", \"YZ\"]");
  if (!c.planes.empty() && t.node("plane"))
    t.fail(t.node("plane"), "plane", "give plane (one test) or planes (a set), not both");
  if (c.radii_mm.size() > 1 && c.calibrated_radius_mm > 0)
    t.fail(t.node("calibrated_radius_mm"), "calibrated_radius_mm",
           "one calibrated length cannot serve several radii: store a calibration per bar and "
           "radius (daq ballbar calibrate) and name the bar");
  try {
    cal::circle::circular_standard_from_key(c.standard);
  } catch (const InputError& e) {
    t.fail(t.node("standard"), "standard", e.what());
  }
  t.check_unknown();
  return c;
}

// A rotary axis (A, B, C) is limited in arcsec, a linear one in um (and urad): a limit of the
// other kind is refused at its line, never compared with values in another unit.
void check_limit_units(Table& t, const PositioningLimits& l, bool rotary_axis) {
  for (const auto& k : cal::daq::positioning_limit_keys)
    if (l.*k.member && k.rotary != rotary_axis)
      t.fail(t.node(k.key), k.key,
             rotary_axis ? "a rotary axis's limits are angles in arcsec (E_arcsec, R_arcsec, "
                           "B_arcsec, A_arcsec, M_arcsec; P_arcsec, Pa_arcsec, Ps_arcsec, "
                           "U_arcsec), not lengths; only its location errors take um and urad "
                           "(location_um, location_urad; docs/config.md)"
                         : "arcsec and location limits are a rotary axis's (A, B, C); a linear "
                           "axis's are in um (E_um, R_um, B_um, A_um, M_um, ...; "
                           "docs/config.md)");
}

AxisTolerance read_axis_tolerance(Table& t, bool rotary_axis) {
  AxisTolerance a;
  a.limits = read_limits(t);
  check_limit_units(t, a.limits, rotary_axis);
  t.known("by_length");
  if (rotary_axis && t.node("by_length"))
    t.fail(t.node("by_length"), "by_length",
           "a rotary axis's limits do not depend on a travel in mm: give them in the axis's "
           "own table");
  if (const auto* node = t.node("by_length")) {
    const auto* arr = node->as_array();
    if (!arr || !arr->is_array_of_tables())
      t.fail(node, "by_length", "expected [[" + t.path() + ".by_length]] tables");
    for (const auto& e : *arr) {
      Table b(*e.as_table(), t.path() + ".by_length", t.file());
      const auto up_to = b.get<double>("up_to_mm");
      if (!up_to || !std::isfinite(*up_to) || *up_to <= 0)
        b.fail(b.node("up_to_mm"), "up_to_mm", "each entry needs up_to_mm, a length > 0 in mm");
      auto limits = read_limits(b);
      check_limit_units(b, limits, false);
      if (limits.empty()) b.fail(nullptr, "up_to_mm", "the entry sets no limit (E_um, R_um, ...)");
      b.check_unknown();
      if (!a.by_length.empty() && a.by_length.back().first >= *up_to)
        b.fail(b.node("up_to_mm"), "up_to_mm", "entries must ascend in up_to_mm");
      a.by_length.emplace_back(*up_to, limits);
    }
  }
  t.check_unknown();
  return a;
}

// The diagnostics a circle in plane UV can report (cal::circle: Diagnostic::key).
bool circle_diagnostic(std::string_view plane, std::string_view key) {
  for (const char* k :
       {"radius_error", "scale_mismatch", "squareness", "servo_mismatch", "vibration"})
    if (key == k) return true;
  for (const char* prefix : {"backlash_", "lateral_play_", "reversal_spike_", "cyclic_",
                             "straightness_", "stick_slip_"}) {
    const std::string_view p(prefix);
    if (key.size() == p.size() + 1 && key.substr(0, p.size()) == p &&
        plane.find(key.back()) != std::string_view::npos)
      return true;
  }
  return false;
}

CircleTolerance read_circle_tolerance(Table& t, std::string_view plane) {
  CircleTolerance c;
  c.G_um = limit(t, "G_um");
  if (const auto* d = t.subtable("diagnostics")) {
    Table dt(*d, t.path() + ".diagnostics", t.file());
    for (const auto& [k, v] : *d) {
      if (!circle_diagnostic(plane, k.str()))
        dt.fail(&v, k.str(),
                fmt::format("not a diagnostic of a circle in {} (radius_error, scale_mismatch, "
                            "squareness, servo_mismatch, vibration, backlash_{}, cyclic_{}, "
                            "stick_slip_{}, ...)",
                            plane, plane.substr(0, 1), plane.substr(0, 1), plane.substr(0, 1)));
      c.diagnostics[std::string(k.str())] = *limit(dt, k.str());
    }
    dt.check_unknown();
  }
  t.check_unknown();
  return c;
}

void read_tolerances(Config& c, Table& top) {
  const auto* tol = top.subtable("tolerances");
  if (!tol) return;
  Table tt(*tol, "tolerances", top.file());
  for (const auto& [k, v] : *tol) {
    const std::string name(k.str());
    const auto* table = tt.subtable(name);
    if (!table) continue;
    Table t(*table, "tolerances." + name, top.file());
    if (name == "X" || name == "Y" || name == "Z")
      c.axis_tolerances[name] = read_axis_tolerance(t, false);
    else if (name == "A" || name == "B" || name == "C")
      c.axis_tolerances[name] = read_axis_tolerance(t, true);
    else if (name == "XY" || name == "YZ" || name == "ZX")
      c.plane_tolerances[name] = read_circle_tolerance(t, name);
    else
      tt.fail(&v, name, "expected an axis (X, Y, Z; A, B, C) or a plane (XY, YZ, ZX)");
  }
  tt.check_unknown();
}

}  // namespace

const DeviceConfig* Config::device_for(std::string_view role) const {
  for (const auto& d : devices)
    if (d.role == role) return &d;
  return nullptr;
}

namespace {
toml::table parse_toml(std::string_view text, const std::filesystem::path& file) {
  try {
    return toml::parse(text, file.string());
  } catch (const toml::parse_error& e) {
    throw InputError(fmt::format("{}:{}:{}: {}", file.string(), e.source().begin.line,
                                 e.source().begin.column, e.description()));
  }
}
}  // namespace

Config parse_tolerances(std::string_view text, const std::filesystem::path& file) {
  for (const auto& [key, value] : parse_toml(text, file))
    if (key.str() != "tolerances")
      throw InputError(fmt::format(
          "{}:{}:{}: '{}': only [tolerances.AXIS] and [tolerances.PLANE] tables are taken here",
          file.string(), value.source().begin.line, value.source().begin.column, key.str()));
  return parse_config(text, file);
}

Config parse_config(std::string_view text, const std::filesystem::path& file) {
  const toml::table root = parse_toml(text, file);
  Config c;
  c.source = file;
  Table top(root, "", file);
  if (const auto* m = top.subtable("machine")) {
    Table t(*m, "machine", file);
    t.name("name", c.machine_name);
    if (c.machine_name.empty()) t.fail(t.node("name"), "name", "must not be empty");
    t.name("description", c.machine_description, true);
    t.name("make", c.machine_make);
    t.name("model", c.machine_model);
    t.name("serial_number", c.machine_serial);
    t.read("topology", c.machine_topology);
    if (!c.machine_topology.empty()) {
      try {
        const auto topology = kinematics::topology_from_string(c.machine_topology);
        c.machine_topology = std::string(kinematics::to_string(topology));
      } catch (const InputError& e) {
        t.fail(t.node("topology"), "topology", e.what());
      }
    }
    c.machine_tool_offset_mm = read_vector(t, "tool_offset_mm", c.machine_tool_offset_mm);
    c.machine_table_offset_mm = read_vector(t, "table_offset_mm", c.machine_table_offset_mm);
    t.check_unknown();
  }
  top.name("campaign", c.campaign);
  top.name("operator", c.operator_name);
  if (const auto* cu = top.subtable("customer")) {
    Table t(*cu, "customer", file);
    t.name("name", c.customer.name);
    t.name("site", c.customer.site, true);
    t.name("contact", c.customer.contact, true);
    t.check_unknown();
  }
  if (const auto* co = top.subtable("conditions")) {
    Table t(*co, "conditions", file);
    c.conditions.controller_compensation = t.get<bool>("controller_compensation");
    t.name("warm_up", c.conditions.warm_up, true);
    t.name("load", c.conditions.load, true);
    t.read("state", c.conditions.state);
    if (!c.conditions.state.empty())
      one_of(t, "state", c.conditions.state, {"as found", "as left"});
    t.name("notes", c.conditions.notes, true);
    t.check_unknown();
  }
  read_tolerances(c, top);
  if (const auto* devs = top.subtable("devices")) {
    for (const auto& [k, v] : *devs) {
      // The id names the device in every message, log and report: a plain word.
      const std::string_view id = k.str();
      if (id.empty() || id.size() > 64 ||
          id.find_first_not_of(
              "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-.") !=
              std::string_view::npos)
        Table(*devs, "devices", file)
            .fail(&v, "",
                  fmt::format("device id '{}': use 1 to 64 letters, digits, '_', '-' or '.'",
                              cal::text::terminal_safe(id)));
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
    read_fields(t, fields::trigger(), c.trigger);
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
