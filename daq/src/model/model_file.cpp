// caldaq.model.v1 reading and writing (see model_file.hpp and docs/model-file.md).
#include "model/model_file.hpp"

#include <fmt/format.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
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

kin::ErrorFunction function_of(const Context& cx, const Json& e, const std::string& key,
                               bool angle) {
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
  only_keys(cx, t, tk, {"position_mm", "value"});
  if (!t.contains("position_mm") || !t.contains("value"))
    cx.fail(tk, "expected \"position_mm\" and \"value\" arrays");
  const auto q = positions_mm(cx, t["position_mm"], tk + ".position_mm", 2);
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

Json function_json(const kin::ErrorFunction& f) {
  Json j = Json::object();
  if (f.is_table()) {
    j["table"] = {
        {"position_mm", std::vector<double>(f.positions_mm().begin(), f.positions_mm().end())},
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

}  // namespace

Model parse(std::string_view text_in, std::string_view where) {
  const Context cx(where);
  const Json j = parse_json(cx, text_in);
  if (!j.is_object()) cx.fail(fmt::format("expected a JSON object, found {}", type_name(j)));
  only_keys(cx, j, "",
            {"schema", "machine", "topology", "units", "tool_offset_mm", "table_offset_mm",
             "travel_mm", "components", "squareness", "provenance", "note"});
  check_note(cx, j, "");
  if (!j.contains("schema")) cx.fail("schema", fmt::format("missing (expected \"{}\")", kSchema));
  if (const auto s = text(cx, j["schema"], "schema"); s != kSchema)
    cx.fail("schema", fmt::format("'{}' is not {} (this version reads only that)", s, kSchema));
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
        cx.fail(key, fmt::format("'{}': caldaq.model.v1 is in {} (convert the values)", s, v));
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
  j["schema"] = kSchema;
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
