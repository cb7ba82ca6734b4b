// caldaq.model.v1/v2 reading and writing (see model_file.hpp and docs/model-file.md).
#include "model/model_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <vector>

#include "cal/analysis/error.hpp"
#include "json_input.hpp"

namespace cal::daq::model {
namespace {

using Json = nlohmann::ordered_json;
namespace kin = cal::kinematics;

constexpr std::array kAxisNames{"X", "Y", "Z"};
constexpr std::array kPlanes{kin::Plane::xy, kin::Plane::xz, kin::Plane::yz};

// Errors name the file and the key path: "model.json: components.E_YX.table: ...".
class Context {
 public:
  explicit Context(std::string_view where) : where_(where) {}
  [[noreturn]] void fail(std::string_view key, std::string_view what) const {
    throw InputError(fmt::format("{}: {}: {}", where_, key, what));
  }
  [[noreturn]] void fail(std::string_view what) const {
    throw InputError(fmt::format("{}: {}", where_, what));
  }
  const std::string& where() const { return where_; }

 private:
  std::string where_;
};

std::string type_name(const Json& j) { return j.type_name(); }

void only_keys(const Context& cx, const Json& obj, std::string_view key,
               std::initializer_list<std::string_view> allowed) {
  for (auto it = obj.begin(); it != obj.end(); ++it) {
    bool ok = false;
    for (auto a : allowed) ok = ok || it.key() == a;
    if (!ok) {
      std::string list;
      for (auto a : allowed) list += (list.empty() ? "" : ", ") + std::string(a);
      cx.fail(key.empty() ? it.key() : fmt::format("{}.{}", key, it.key()),
              fmt::format("unknown key (expected one of: {})", list));
    }
  }
}

const Json& object_at(const Context& cx, const Json& j, std::string_view key) {
  if (!j.is_object()) cx.fail(key, fmt::format("expected an object, found {}", type_name(j)));
  return j;
}

double number(const Context& cx, const Json& j, std::string_view key) {
  if (!j.is_number()) cx.fail(key, fmt::format("expected a number, found {}", type_name(j)));
  const double v = j.get<double>();
  if (!std::isfinite(v)) cx.fail(key, "expected a finite number");
  return v;
}

std::string text(const Context& cx, const Json& j, std::string_view key) {
  if (!j.is_string()) cx.fail(key, fmt::format("expected a string, found {}", type_name(j)));
  return j.get<std::string>();
}

std::vector<double> numbers(const Context& cx, const Json& j, std::string_view key,
                            std::size_t min_size) {
  if (!j.is_array())
    cx.fail(key, fmt::format("expected an array of numbers, found {}", type_name(j)));
  if (j.size() < min_size)
    cx.fail(key, fmt::format("{} value(s), expected at least {}", j.size(), min_size));
  std::vector<double> v;
  for (std::size_t i = 0; i < j.size(); ++i)
    v.push_back(number(cx, j[i], fmt::format("{}[{}]", key, i)));
  return v;
}

// Physical sense: no machine's position is beyond 100 m, no error beyond 100 m (1e8 um) or
// 1 rad (1e6 urad). Values past these are typing errors, and the maps and predictions made
// from them would print inf or nan.
constexpr double kMaxPositionMm = 100e3, kMaxTranslationUm = 1e8, kMaxAngleUrad = 1e6;

double bounded(const Context& cx, double v, std::string_view key, double limit,
               std::string_view unit) {
  if (std::abs(v) > limit)
    cx.fail(key, fmt::format("{} {} is beyond {:g} {} (a typing error?)", v, unit, limit, unit));
  return v;
}

// Positions in mm, each within kMaxPositionMm.
std::vector<double> positions_mm(const Context& cx, const Json& j, std::string_view key,
                                 std::size_t min_size) {
  auto v = numbers(cx, j, key, min_size);
  for (std::size_t i = 0; i < v.size(); ++i)
    bounded(cx, v[i], fmt::format("{}[{}]", key, i), kMaxPositionMm, "mm");
  return v;
}

kin::Vec3 vec3(const Context& cx, const Json& j, std::string_view key) {
  const auto v = positions_mm(cx, j, key, 3);
  if (v.size() != 3) cx.fail(key, fmt::format("{} values, expected 3 (x, y, z)", v.size()));
  return {v[0], v[1], v[2]};
}

kin::Axis axis_named(const Context& cx, const Json& j, std::string_view key) {
  const std::string s = text(cx, j, key);
  for (std::size_t i = 0; i < 3; ++i)
    if (s == kAxisNames[i]) return static_cast<kin::Axis>(i);
  cx.fail(key, fmt::format("'{}' is not an axis (expected X, Y or Z)", s));
}

// Rejects duplicate keys (nlohmann keeps the last silently: a misread).
Json parse_json(const Context& cx, std::string_view text_in) {
  std::vector<std::set<std::string>> keys;
  std::string duplicate;
  const auto callback = [&](int /*depth*/, Json::parse_event_t event, Json& parsed) {
    if (event == Json::parse_event_t::object_start) keys.emplace_back();
    if (event == Json::parse_event_t::object_end && !keys.empty()) keys.pop_back();
    if (event == Json::parse_event_t::key && !keys.empty() && duplicate.empty() &&
        !keys.back().insert(parsed.get<std::string>()).second)
      duplicate = parsed.get<std::string>();
    return true;
  };
  // Syntax, a number out of range (1e999), bytes that are not UTF-8, nesting too deep (a
  // source or provenance 100 000 levels down would crash every dump of it).
  const Json j = parse_json_input<Json>(text_in, cx.where(), callback);
  if (!duplicate.empty()) cx.fail(duplicate, "key given twice (only one value per key)");
  return j;
}

// "note" is free text: a string, nothing else.
void check_note(const Context& cx, const Json& obj, const std::string& key) {
  if (obj.contains("note")) text(cx, obj["note"], key.empty() ? "note" : key + ".note");
}

Source source_of(const Json& entry) {
  const auto it = entry.find("source");
  return it == entry.end() ? Source{} : Source{it->dump()};
}

// The argument of a table: a linear axis's position in mm, or a rotary axis's angle in degrees.
struct Argument {
  std::string_view key = "position_mm";
  double limit = kMaxPositionMm;
  std::string_view unit = "mm";
};
constexpr Argument kPosition{};
// 10 turns either way: beyond that an angle is a typing error.
constexpr double kMaxAngleDeg = 3600.0;
constexpr Argument kAngle{"angle_deg", kMaxAngleDeg, "deg"};

kin::ErrorFunction function_of(const Context& cx, const Json& e, const std::string& key, bool angle,
                               const Argument& arg = kPosition) {
  const double limit = angle ? kMaxAngleUrad : kMaxTranslationUm;
  const std::string_view unit = angle ? "urad" : "um";
  object_at(cx, e, key);
  only_keys(cx, e, key, {"polynomial", "table", "source", "note"});
  check_note(cx, e, key);
  const bool poly = e.contains("polynomial"), table = e.contains("table");
  if (poly == table)
    cx.fail(key, "give exactly one of \"polynomial\" (coefficients c0, c1, ...) and \"table\"");
  if (poly) {
    const auto c = numbers(cx, e["polynomial"], key + ".polynomial", 1);
    try {
      return kin::ErrorFunction::polynomial(c);
    } catch (const InputError& err) {
      cx.fail(key + ".polynomial", err.what());
    }
  }
  const std::string tk = key + ".table";
  const Json& t = object_at(cx, e["table"], tk);
  only_keys(cx, t, tk, {arg.key, "value"});
  if (!t.contains(arg.key) || !t.contains("value"))
    cx.fail(tk, fmt::format("expected \"{}\" and \"value\" arrays", arg.key));
  const std::string qk = fmt::format("{}.{}", tk, arg.key);
  const auto q = numbers(cx, t[arg.key], qk, 2);
  for (std::size_t i = 0; i < q.size(); ++i)
    bounded(cx, q[i], fmt::format("{}[{}]", qk, i), arg.limit, arg.unit);
  const auto v = numbers(cx, t["value"], tk + ".value", 2);
  for (std::size_t i = 0; i < v.size(); ++i)
    bounded(cx, v[i], fmt::format("{}.value[{}]", tk, i), limit, unit);
  try {
    return kin::ErrorFunction::table(q, v);
  } catch (const InputError& err) {
    cx.fail(tk, err.what());
  }
}

void read_components(const Context& cx, const Json& comps, Model& m) {
  object_at(cx, comps, "components");
  for (auto it = comps.begin(); it != comps.end(); ++it) {
    const std::string key = "components." + it.key();
    kin::Component c;
    try {
      c = kin::component_from_string(it.key());
    } catch (const InputError&) {
      cx.fail(key,
              "unknown component (expected an ISO 230-1 name such as E_XX, E_YX, E_CX; the "
              "squareness errors go under \"squareness\")");
    }
    if (std::string(kin::to_string(c)) != it.key())
      cx.fail(key, fmt::format("write the name as {}", kin::to_string(c)));
    const bool angle = static_cast<std::size_t>(c) % 6 >= 3;  // E_A.., E_B.., E_C..
    kin::component(m.machine, c) = function_of(cx, it.value(), key, angle);
    m.components[static_cast<std::size_t>(c)] = {true, source_of(it.value())};
  }
}

void read_squareness(const Context& cx, const Json& sq, Model& m) {
  object_at(cx, sq, "squareness");
  for (auto it = sq.begin(); it != sq.end(); ++it) {
    const std::string key = "squareness." + it.key();
    std::optional<kin::Plane> plane;
    for (kin::Plane p : kPlanes)
      if (it.key() == kin::location_error_name(p)) plane = p;
    if (!plane) cx.fail(key, "unknown squareness (expected E_C0Y, E_B0Z or E_A0Z)");
    const Json& e = object_at(cx, it.value(), key);
    only_keys(cx, e, key,
              {"iso230_1_urad", "angle_over_90_urad", "method", "placement", "position_mm",
               "compensated_by", "source", "note"});
    check_note(cx, e, key);
    const bool iso = e.contains("iso230_1_urad"), angle = e.contains("angle_over_90_urad");
    if (iso == angle)
      cx.fail(key,
              "give exactly one of \"iso230_1_urad\" (the ISO 230-1 location error) and "
              "\"angle_over_90_urad\" (positive when the angle between the positive axis "
              "directions exceeds 90 deg, as daq analyse squareness reports it)");
    SquarenessEntry& s = m.squareness[static_cast<std::size_t>(*plane)];
    s.given = true;
    s.stated_as = iso ? "iso230_1_urad" : "angle_over_90_urad";
    const double v = bounded(cx, number(cx, e[s.stated_as], key + "." + s.stated_as),
                             key + "." + s.stated_as, kMaxAngleUrad, "urad");
    m.machine.squareness.of(*plane) = iso ? v : kin::location_error_from_angle_over_90(*plane, v);
    if (e.contains("method")) {
      s.method = text(cx, e["method"], key + ".method");
      if (s.method != "straightness" && s.method != "diagonal" && s.method != "circle" &&
          s.method != "circles" && s.method != "other")
        cx.fail(key + ".method", fmt::format("'{}' (expected straightness, diagonal, circle, "
                                             "circles or other)",
                                             s.method));
    }
    if (e.contains("placement")) {
      s.placement = text(cx, e["placement"], key + ".placement");
      if (s.placement != "global" && s.placement != "local")
        cx.fail(key + ".placement", fmt::format("'{}' (expected global or local)", s.placement));
    }
    if (e.contains("position_mm")) s.position_mm = vec3(cx, e["position_mm"], key + ".position_mm");
    if (s.placement == "local" && !s.position_mm)
      cx.fail(key, "a local squareness needs \"position_mm\", where it was measured");
    if (e.contains("compensated_by")) {
      const kin::Axis a = axis_named(cx, e["compensated_by"], key + ".compensated_by");
      const std::string_view plane_name = kin::to_string(*plane);
      if (plane_name.find(kAxisNames[a]) == std::string_view::npos)
        cx.fail(key + ".compensated_by",
                fmt::format("{} is not an axis of the {} plane", kAxisNames[a], plane_name));
      (*plane == kin::Plane::xy   ? m.carriers.xy
       : *plane == kin::Plane::xz ? m.carriers.xz
                                  : m.carriers.yz) = a;
    }
    s.source = source_of(e);
  }
}

void read_travel(const Context& cx, const Json& t, Model& m) {
  object_at(cx, t, "travel_mm");
  only_keys(cx, t, "travel_mm", {"X", "Y", "Z"});
  std::array<std::array<double, 2>, 3> travel{};
  for (std::size_t i = 0; i < 3; ++i) {
    const std::string key = fmt::format("travel_mm.{}", kAxisNames[i]);
    if (!t.contains(kAxisNames[i])) cx.fail(key, "missing (give [min, max] for X, Y and Z)");
    const auto v = positions_mm(cx, t[kAxisNames[i]], key, 2);
    if (v.size() != 2 || !(v[1] > v[0])) cx.fail(key, "expected [min, max] with max > min");
    travel[i] = {v[0], v[1]};
  }
  m.travel_mm = travel;
}

// Every table must cover the travel of its axis: a map or a compensation over the travel would
// otherwise stop at the first point outside it.
void check_tables_cover_travel(const Context& cx, const Model& m) {
  if (!m.travel_mm) return;
  for (kin::Component c : kin::all_components()) {
    const auto& f = kin::component(m.machine, c);
    if (!f.is_table()) continue;
    const auto axis = static_cast<std::size_t>(c) / 6;
    const auto [lo, hi] = (*m.travel_mm)[axis];
    const auto q = f.positions_mm();
    if (q.front() > lo + 1e-9 || q.back() < hi - 1e-9)
      cx.fail(fmt::format("components.{}.table", kin::to_string(c)),
              fmt::format("covers {} .. {} mm but the {} travel is {} .. {} mm (tables are not "
                          "extrapolated)",
                          q.front(), q.back(), kAxisNames[axis], lo, hi));
  }
}

// A polynomial stays within the limits over the travel of its axis (sampled at 101 points):
// coefficients that are each finite can still overflow to inf where the model is evaluated.
void check_polynomials_over_travel(const Context& cx, const Model& m) {
  if (!m.travel_mm) return;
  for (kin::Component c : kin::all_components()) {
    const auto& f = kin::component(m.machine, c);
    if (f.is_table() || f.is_zero()) continue;
    const auto axis = static_cast<std::size_t>(c) / 6;
    const bool angle = static_cast<std::size_t>(c) % 6 >= 3;
    const double limit = angle ? kMaxAngleUrad : kMaxTranslationUm;
    const auto [lo, hi] = (*m.travel_mm)[axis];
    for (int i = 0; i <= 100; ++i) {
      const double q = lo + (hi - lo) * i / 100.0, v = f(q);
      if (!(std::abs(v) <= limit))
        cx.fail(
            fmt::format("components.{}.polynomial", kin::to_string(c)),
            fmt::format("{} {} at {} mm of the {} travel, beyond {:g} {} (a typing error?)", v,
                        angle ? "urad" : "um", q, kAxisNames[axis], limit, angle ? "urad" : "um"));
    }
  }
}

Json function_json(const kin::ErrorFunction& f, std::string_view argument = "position_mm") {
  Json j = Json::object();
  if (f.is_table()) {
    j["table"] = {{std::string(argument),
                   std::vector<double>(f.positions_mm().begin(), f.positions_mm().end())},
                  {"value", std::vector<double>(f.values().begin(), f.values().end())}};
  } else {
    const auto c = f.coefficients();
    j["polynomial"] =
        c.empty() ? std::vector<double>{0.0} : std::vector<double>(c.begin(), c.end());
  }
  return j;
}

void put_source(Json& j, const Source& s) {
  if (!s.json.empty()) j["source"] = Json::parse(s.json);
}

// --- rotary axes (v2) -------------------------------------------------------------------------

constexpr std::array kRotaryDirections{'X', 'Y', 'Z', 'A', 'B', 'C'};

// Component `dir` (X, Y, Z, A, B, C) of a rotary axis's motion; Axis is RotaryAxis, const or not.
template <class Axis>
auto& component_of(Axis& r, std::size_t dir) {
  auto& m = r.motion;
  const std::array f{&m.ex_um, &m.ey_um, &m.ez_um, &m.ea_urad, &m.eb_urad, &m.ec_urad};
  return *f.at(dir);
}

// The slot of a location error in RotaryAxis: position (0..2) or orientation (3..5) index.
std::size_t location_slot(kin::RotaryLetter l, std::size_t n) {
  const std::size_t own = kin::direction_index(l);
  std::size_t k = 0;
  for (std::size_t slot = 0; slot < 6; ++slot) {
    if (slot % 3 == own) continue;
    if (k++ == n) return slot;
  }
  return 0;  // unreachable: n < 4
}

// Location error n (in the order of location_error_names) of a rotary axis, const or not.
template <class Axis>
auto& location_value(Axis& r, std::size_t n) {
  const std::size_t slot = location_slot(r.letter, n);
  return slot < 3 ? r.location_position_um[slot] : r.location_orientation_urad[slot - 3];
}

void read_location(const Context& cx, const Json& loc, const std::string& key, RotaryEntry& r) {
  object_at(cx, loc, key);
  const auto names = kin::location_error_names(r.axis.letter);
  for (auto it = loc.begin(); it != loc.end(); ++it) {
    const std::string k = key + "." + it.key();
    const auto found = std::find(names.begin(), names.end(), it.key());
    if (found == names.end())
      cx.fail(k,
              fmt::format("not a location error of the {} axis (expected {}, {}, {} or {})",
                          kin::to_string(r.axis.letter), names[0], names[1], names[2], names[3]));
    const auto n = static_cast<std::size_t>(found - names.begin());
    const bool angle = location_slot(r.axis.letter, n) >= 3;
    const double limit = angle ? kMaxAngleUrad : kMaxTranslationUm;
    const std::string_view unit = angle ? "urad" : "um";
    LocationEntry& e = r.location[n];
    e.given = true;
    const Json& v = it.value();
    if (v.is_number()) {
      location_value(r.axis, n) = bounded(cx, number(cx, v, k), k, limit, unit);
      continue;
    }
    if (!v.is_object())
      cx.fail(k, fmt::format("expected a number or {{\"value\": ...}}, found {}", type_name(v)));
    only_keys(cx, v, k, {"value", "uncertainty", "source", "note"});
    check_note(cx, v, k);
    if (!v.contains("value")) cx.fail(k + ".value", "missing");
    location_value(r.axis, n) =
        bounded(cx, number(cx, v["value"], k + ".value"), k + ".value", limit, unit);
    if (v.contains("uncertainty")) {
      const double u = bounded(cx, number(cx, v["uncertainty"], k + ".uncertainty"),
                               k + ".uncertainty", limit, unit);
      if (u < 0.0) cx.fail(k + ".uncertainty", "expected a standard uncertainty >= 0");
      e.uncertainty = u;
    }
    e.source = source_of(v);
  }
}

void read_rotary_components(const Context& cx, const Json& comps, const std::string& key,
                            RotaryEntry& r) {
  object_at(cx, comps, key);
  const char own = kin::to_string(r.axis.letter)[0];
  for (auto it = comps.begin(); it != comps.end(); ++it) {
    const std::string k = key + "." + it.key();
    std::optional<std::size_t> dir;
    for (std::size_t d = 0; d < 6; ++d)
      if (it.key() == fmt::format("E_{}{}", kRotaryDirections[d], own)) dir = d;
    if (!dir)
      cx.fail(k, fmt::format("not a component error of the {0} axis (expected E_X{0}, E_Y{0}, "
                             "E_Z{0}, E_A{0}, E_B{0} or E_C{0}: functions of the angle)",
                             own));
    rotary_component(r.axis, *dir) = function_of(cx, it.value(), k, *dir >= 3, kAngle);
    r.components[*dir] = {true, source_of(it.value())};
  }
}

// Every table covers the axis's range and every polynomial stays within the limits over it.
void check_rotary_functions(const Context& cx, const std::string& key, const RotaryEntry& r) {
  const auto [lo, hi] = r.range_deg;
  for (std::size_t d = 0; d < 6; ++d) {
    const auto& f = rotary_component(r.axis, d);
    const std::string k =
        fmt::format("{}.components.{}", key, rotary_component_name(r.axis.letter, d));
    if (f.is_table()) {
      const auto q = f.positions_mm();
      if (q.front() > lo + 1e-9 || q.back() < hi - 1e-9)
        cx.fail(k + ".table", fmt::format("covers {} .. {} deg but the range is {} .. {} deg "
                                          "(tables are not extrapolated)",
                                          q.front(), q.back(), lo, hi));
      continue;
    }
    if (f.is_zero()) continue;
    const bool angle = d >= 3;
    const double limit = angle ? kMaxAngleUrad : kMaxTranslationUm;
    for (int i = 0; i <= 100; ++i) {
      const double a = lo + (hi - lo) * i / 100.0, v = f(a);
      if (!(std::abs(v) <= limit))
        cx.fail(k + ".polynomial",
                fmt::format("{} {} at {} deg, beyond {:g} {} (a typing error?)", v,
                            angle ? "urad" : "um", a, limit, angle ? "urad" : "um"));
    }
  }
}

RotaryEntry read_one_rotary(const Context& cx, const Json& e, const std::string& key) {
  object_at(cx, e, key);
  only_keys(cx, e, key,
            {"axis", "side", "pivot_mm", "range_deg", "location", "components", "note"});
  check_note(cx, e, key);
  RotaryEntry r;
  for (const char* required : {"axis", "side", "pivot_mm", "range_deg"})
    if (!e.contains(required)) cx.fail(key + "." + required, "missing");
  const std::string letter = text(cx, e["axis"], key + ".axis");
  if (letter != "A" && letter != "B" && letter != "C")
    cx.fail(key + ".axis", fmt::format("'{}' (expected A, B or C)", letter));
  r.axis.letter = kin::rotary_letter_from_string(letter);
  const std::string side = text(cx, e["side"], key + ".side");
  if (side != "table" && side != "spindle")
    cx.fail(key + ".side", fmt::format("'{}' (expected table or spindle)", side));
  r.axis.side = side == "table" ? kin::Side::table : kin::Side::spindle;
  r.axis.pivot_mm = vec3(cx, e["pivot_mm"], key + ".pivot_mm");
  const auto range = numbers(cx, e["range_deg"], key + ".range_deg", 2);
  for (std::size_t i = 0; i < range.size(); ++i)
    bounded(cx, range[i], fmt::format("{}.range_deg[{}]", key, i), kMaxAngleDeg, "deg");
  if (range.size() != 2 || !(range[1] > range[0]))
    cx.fail(key + ".range_deg", "expected [min, max] in degrees with max > min");
  r.range_deg = {range[0], range[1]};
  if (e.contains("location")) read_location(cx, e["location"], key + ".location", r);
  if (e.contains("components")) read_rotary_components(cx, e["components"], key + ".components", r);
  if (e.contains("note")) r.note = e["note"].get<std::string>();
  check_rotary_functions(cx, key, r);
  return r;
}

void read_rotary(const Context& cx, const Json& list, Model& m) {
  if (!list.is_array())
    cx.fail("rotary", fmt::format("expected an array of rotary axes, found {}", type_name(list)));
  if (list.size() > 2)
    cx.fail("rotary", fmt::format("{} rotary axes: at most 2 are modelled", list.size()));
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string key = fmt::format("rotary[{}]", i);
    RotaryEntry r = read_one_rotary(cx, list[i], key);
    for (const auto& before : m.rotary) {
      if (before.axis.letter == r.axis.letter)
        cx.fail(key + ".axis", fmt::format("a second {} axis (each letter once: the location "
                                           "errors are named by it)",
                                           kin::to_string(r.axis.letter)));
      if (before.axis.side == kin::Side::spindle && r.axis.side == kin::Side::table)
        cx.fail(key + ".side",
                "a table axis after a spindle axis: list the rotary axes from the workpiece to "
                "the tool, table axes first");
    }
    m.rotary.push_back(std::move(r));
  }
}

Json rotary_json(const RotaryEntry& r) {
  Json j;
  j["axis"] = kin::to_string(r.axis.letter);
  j["side"] = kin::to_string(r.axis.side);
  j["pivot_mm"] = r.axis.pivot_mm;
  j["range_deg"] = r.range_deg;
  Json loc = Json::object();
  const auto names = kin::location_error_names(r.axis.letter);
  for (std::size_t n = 0; n < 4; ++n) {
    const double v = location_value(r.axis, n);
    const auto& e = r.location[n];
    if (!e.given && v == 0.0) continue;
    if (!e.uncertainty && e.source.json.empty()) {
      loc[names[n]] = v;
      continue;
    }
    Json o;
    o["value"] = v;
    if (e.uncertainty) o["uncertainty"] = *e.uncertainty;
    put_source(o, e.source);
    loc[names[n]] = o;
  }
  j["location"] = loc;
  Json comps = Json::object();
  for (std::size_t d = 0; d < 6; ++d) {
    const auto& f = rotary_component(r.axis, d);
    if (!r.components[d].given && f.is_zero()) continue;
    Json e = function_json(f, kAngle.key);
    put_source(e, r.components[d].source);
    comps[rotary_component_name(r.axis.letter, d)] = e;
  }
  j["components"] = comps;
  if (!r.note.empty()) j["note"] = r.note;
  return j;
}

}  // namespace

Model parse(std::string_view text_in, std::string_view where) {
  const Context cx(where);
  const Json j = parse_json(cx, text_in);
  if (!j.is_object()) cx.fail(fmt::format("expected a JSON object, found {}", type_name(j)));
  only_keys(cx, j, "",
            {"schema", "machine", "topology", "units", "tool_offset_mm", "table_offset_mm",
             "travel_mm", "components", "squareness", "rotary", "provenance", "note"});
  check_note(cx, j, "");
  if (!j.contains("schema"))
    cx.fail("schema", fmt::format("missing (expected \"{}\" or \"{}\")", kSchema, kSchemaRotary));
  const std::string schema = text(cx, j["schema"], "schema");
  if (schema != kSchema && schema != kSchemaRotary)
    cx.fail("schema", fmt::format("'{}' is neither {} nor {} (the versions this one reads)", schema,
                                  kSchema, kSchemaRotary));
  if (schema == kSchema && j.contains("rotary"))
    cx.fail("rotary", fmt::format("rotary axes need \"schema\": \"{}\"", kSchemaRotary));
  if (!j.contains("units"))
    cx.fail("units",
            "missing: state {\"position\": \"mm\", \"translation\": \"um\", \"angle\": "
            "\"urad\"}");
  {
    const Json& u = object_at(cx, j["units"], "units");
    only_keys(cx, u, "units", {"position", "translation", "angle"});
    const std::array<std::pair<const char*, const char*>, 3> expected{
        {{"position", "mm"}, {"translation", "um"}, {"angle", "urad"}}};
    for (const auto& [k, v] : expected) {
      const std::string key = std::string("units.") + k;
      if (!u.contains(k)) cx.fail(key, fmt::format("missing (expected \"{}\")", v));
      if (const auto s = text(cx, u[k], key); s != v)
        cx.fail(key, fmt::format("'{}': {} is in {} (convert the values)", s, schema, v));
    }
  }
  Model m;
  if (j.contains("machine")) m.name = text(cx, j["machine"], "machine");
  if (!j.contains("topology")) cx.fail("topology", "missing (e.g. \"FXYZ\", \"YFXZ\")");
  const std::string topology = text(cx, j["topology"], "topology");
  try {
    m.machine.topology = kin::topology_from_string(topology);
  } catch (const InputError& e) {
    cx.fail("topology", e.what());
  }
  if (j.contains("tool_offset_mm"))
    m.machine.tool_offset_mm = vec3(cx, j["tool_offset_mm"], "tool_offset_mm");
  if (j.contains("table_offset_mm"))
    m.machine.table_offset_mm = vec3(cx, j["table_offset_mm"], "table_offset_mm");
  if (j.contains("travel_mm")) read_travel(cx, j["travel_mm"], m);
  if (j.contains("components")) read_components(cx, j["components"], m);
  if (j.contains("squareness")) read_squareness(cx, j["squareness"], m);
  if (j.contains("rotary")) read_rotary(cx, j["rotary"], m);
  if (j.contains("provenance")) m.provenance = {j["provenance"].dump()};
  check_tables_cover_travel(cx, m);
  check_polynomials_over_travel(cx, m);
  return m;
}

Model read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(fmt::format("{}: cannot open the model file", path));
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw InputError(fmt::format("{}: cannot read the model file", path));
  return parse(ss.str(), path);
}

std::string to_json(const Model& m) {
  Json j;
  j["schema"] = m.rotary.empty() ? kSchema : kSchemaRotary;
  if (!m.name.empty()) j["machine"] = m.name;
  j["topology"] = kin::to_string(m.machine.topology);
  j["units"] = {{"position", "mm"}, {"translation", "um"}, {"angle", "urad"}};
  j["tool_offset_mm"] = m.machine.tool_offset_mm;
  j["table_offset_mm"] = m.machine.table_offset_mm;
  if (m.travel_mm) {
    Json t;
    for (std::size_t i = 0; i < 3; ++i) t[kAxisNames[i]] = (*m.travel_mm)[i];
    j["travel_mm"] = t;
  }
  Json comps = Json::object();
  for (kin::Component c : kin::all_components()) {
    const auto& entry = m.components[static_cast<std::size_t>(c)];
    const auto& f = kin::component(m.machine, c);
    if (!entry.given && f.is_zero()) continue;
    Json e = function_json(f);
    put_source(e, entry.source);
    comps[std::string(kin::to_string(c))] = e;
  }
  j["components"] = comps;
  Json sq = Json::object();
  for (kin::Plane p : kPlanes) {
    const auto& s = m.squareness[static_cast<std::size_t>(p)];
    const double v = m.machine.squareness.of(p);
    if (!s.given && v == 0.0) continue;
    Json e;
    e["iso230_1_urad"] = v;  // always written in the model's convention
    if (!s.method.empty()) e["method"] = s.method;
    if (!s.placement.empty()) e["placement"] = s.placement;
    if (s.position_mm) e["position_mm"] = *s.position_mm;
    e["compensated_by"] = kAxisNames[m.carriers.of(p)];
    put_source(e, s.source);
    sq[std::string(kin::location_error_name(p))] = e;
  }
  j["squareness"] = sq;
  if (!m.rotary.empty()) {
    Json rot = Json::array();
    for (const auto& r : m.rotary) rot.push_back(rotary_json(r));
    j["rotary"] = rot;
  }
  if (!m.provenance.json.empty()) j["provenance"] = Json::parse(m.provenance.json);
  return j.dump(2) + "\n";
}

void write(const Model& m, const std::string& path) {
  const std::string text_out = to_json(m);
  const std::filesystem::path target(path), tmp = target.string() + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!(out << text_out) || !(out.close(), out)) {
      std::error_code ignored;
      std::filesystem::remove(tmp, ignored);
      throw InputError(fmt::format("{}: cannot write the model file", path));
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, target, ec);
  if (ec) {
    std::filesystem::remove(tmp, ec);
    throw InputError(fmt::format("{}: cannot write the model file", path));
  }
}

kinematics::FiveAxisMachine five_axis(const Model& m) {
  kinematics::FiveAxisMachine f;
  f.linear = m.machine;
  for (const auto& r : m.rotary) f.rotary.push_back(r.axis);
  return f;
}

kinematics::ErrorFunction& rotary_component(kinematics::RotaryAxis& r, std::size_t dir) {
  return component_of(r, dir);
}
const kinematics::ErrorFunction& rotary_component(const kinematics::RotaryAxis& r,
                                                  std::size_t dir) {
  return component_of(r, dir);
}

std::string rotary_component_name(kinematics::RotaryLetter l, std::size_t dir) {
  return fmt::format("E_{}{}", kRotaryDirections.at(dir), kinematics::to_string(l));
}

void require_no_rotary(const Model& m, std::string_view file, std::string_view what) {
  if (m.rotary.empty()) return;
  throw InputError(fmt::format(
      "{}: rotary: {} does not model rotary axes yet (the model has {}); it would ignore them",
      file, what, m.rotary.size() == 1 ? "one" : "two"));
}

kinematics::Grid travel_grid(const Model& m, std::array<std::size_t, 3> count) {
  if (!m.travel_mm)
    throw InputError(
        "the model has no travel_mm: give the grid (--min-mm, --max-mm) or add the travel");
  kinematics::Grid g;
  for (std::size_t i = 0; i < 3; ++i) {
    g.min_mm[i] = (*m.travel_mm)[i][0];
    g.max_mm[i] = (*m.travel_mm)[i][1];
    g.count[i] = count[i];
  }
  return g;
}

}  // namespace cal::daq::model
