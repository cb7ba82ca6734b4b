#include "verdict.hpp"

#include <fmt/format.h>

#include <cmath>

#include "cal/analysis/fixed_text.hpp"
#include "cal/analysis/text.hpp"
#include "cal/daq/config.hpp"
#include "circle_output.hpp"
#include "result_rows.hpp"

namespace daq {

using nlohmann::json;

namespace {

// The value as it is printed (3 decimals), so the verdict agrees with what the reader sees.
bool within(double value, double limit) {
  return cal::fixed_value(std::abs(value), 3) <= limit + 1e-12;
}

// The travel of a result's targets (a position key: "target_mm" of ISO 230-2, "position_mm"
// of a profile).
double travel_mm(const json& result, const char* position_key) {
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& t : result.value("targets", json::array())) {
    const double x = t.value(position_key, 0.0);
    lo = std::min(lo, x), hi = std::max(hi, x);
  }
  return hi >= lo ? hi - lo : 0.0;
}

// An axis's limits for a measured travel: the axis' own, replaced by those of the first
// by_length entry long enough; `basis` names where they come from.
json limits_for_travel(const json& tolerances, double travel, std::string& basis) {
  json limits = tolerances;
  basis = tolerances.value("source", std::string("tolerances"));
  for (const auto& e : tolerances.value("by_length", json::array()))
    if (travel <= e.value("up_to_mm", 0.0) + 1e-9) {
      for (const auto& [k, val] : e.items())
        if (k != "up_to_mm") limits[k] = val;
      basis += fmt::format(" (measured travel {:g} mm, up to {:g} mm)", travel,
                           e.value("up_to_mm", 0.0));
      break;
    }
  return limits;
}

void conclude(Verdict& v) {
  v.configured = !v.checks.empty();
  v.pass = v.configured;
  for (const auto& c : v.checks) v.pass = v.pass && c.pass;
}

}  // namespace

namespace {

// How a positioning evaluation's values and its axis's limits are named: a linear axis's in µm
// (E_um; caldaq.iso230-2.v1's "value_um"), a rotary axis's in arcsec (E_arcsec;
// caldaq.rotary.v1's "value").
struct PositioningUnits {
  const char* suffix;     // of the limits' keys: "_um", "_arcsec"
  const char* value_key;  // of a value in the result's "axis"
  const char* unit;       // of a check: "um", "arcsec"
  const char* shown;      // in a note: "µm", "arcsec"
};
constexpr PositioningUnits linear_units{"_um", "value_um", "um", "µm"};
constexpr PositioningUnits rotary_units{"_arcsec", "value", "arcsec", "arcsec"};

// The standard's title: caldaq.iso230-2.v1 nests it in "standard", caldaq.rotary.v1 has it at
// the top.
std::string standard_title(const json& result) {
  if (result.contains("standard") && result["standard"].is_object())
    return result["standard"].value("title", std::string("this standard"));
  return result.value("title", std::string("this standard"));
}

Verdict positioning_verdict(const json& limits, const json& result, const PositioningUnits& u,
                            Verdict v) {
  const bool bi = result.value("bidirectional", true);
  const auto& axis = result.value("axis", json::object());
  const std::string title = standard_title(result);
  // Which value of the evaluation each limit applies to. ISO 230-2's limits apply to the ISO
  // family (every edition, JIS, GB/T), VDI/DGQ 3441's to a VDI evaluation (it gives P).
  const bool vdi = axis.contains("P");
  const struct {
    const char* limit;  // the key without its unit
    const char* name;
    const char* bi_key;
    const char* uni_key;
    bool vdi;
  } map[] = {{"E", "E", "E_bi", "E_up", false},     {"R", "R", "R_bi", "R_up", false},
             {"B", "B", "B", nullptr, false},       {"A", "A", "A_bi", "A_up", false},
             {"M", "M", "M", nullptr, false},       {"P", "P", "P", nullptr, true},
             {"Pa", "Pa", "Pa", nullptr, true},     {"Ps", "Ps max", "Ps_max", nullptr, true},
             {"U", "U max", "U_max", nullptr, true}};
  const auto keys = [&](bool of_vdi) {
    std::vector<std::string> k;
    for (const auto& m : map)
      if (m.vdi == of_vdi) k.push_back(m.limit + std::string(u.suffix));
    return fmt::format("{}", fmt::join(k, ", "));
  };
  std::vector<std::string> other;  // limits of the other family
  for (const auto& m : map) {
    const std::string limit_key = m.limit + std::string(u.suffix);
    if (!limits.contains(limit_key)) continue;
    if (m.vdi != vdi) {
      other.push_back(limit_key);
      continue;
    }
    const char* key = bi ? m.bi_key : m.uni_key;
    const double lim = limits[limit_key].get<double>();
    if (!key || !axis.contains(key)) {
      v.notes.push_back(fmt::format("{} limit {:g} {} not applied: {} gives no {}{}", m.name, lim,
                                    u.shown, title, m.name, bi ? "" : " for a one-way test"));
      continue;
    }
    const double value = axis[key].value(u.value_key, 0.0);
    v.checks.push_back({key, axis[key].value("symbol", std::string(m.name)), value, lim, u.unit,
                        within(value, lim)});
  }
  // Limits only of the other family: none applies, and the note says which keys would.
  if (v.checks.empty() && !other.empty())
    v.notes.push_back(
        fmt::format("the limits configured ({}) are for {} values; {} is judged by {}",
                    fmt::join(other, ", "), vdi ? "ISO 230-2" : "VDI/DGQ 3441", title,
                    vdi ? keys(true) + " (docs/config.md)" : keys(false)));
  conclude(v);
  return v;
}

// A rotary axis's values (arcsec) against its [tolerances.A|B|C] limits in arcsec. A run
// stored with a linear axis's limits in µm has none that applies: said so, never a µm limit
// compared with arcsec.
Verdict rotary_verdict(const json& tolerances, const json& result) {
  Verdict v;
  if (!tolerances.is_object()) return v;
  v.basis = tolerances.value("source", std::string("tolerances"));
  bool lengths = false;
  for (const auto& k : cal::daq::positioning_limit_keys)
    lengths = lengths || (!k.rotary && tolerances.contains(k.key));
  if (lengths)
    v.notes.push_back(
        "the configured limits are in µm for a linear axis: none applies to a rotary axis's "
        "values in arcsec (its limits are E_arcsec, R_arcsec, ...: docs/config.md)");
  return positioning_verdict(tolerances, result, rotary_units, std::move(v));
}

}  // namespace

Verdict linear_verdict(const json& tolerances, const json& result) {
  Verdict v;
  if (!tolerances.is_object()) return v;
  const json limits = limits_for_travel(tolerances, travel_mm(result, "target_mm"), v.basis);
  return positioning_verdict(limits, result, linear_units, std::move(v));
}

Verdict profile_verdict(const json& tolerances, const json& result) {
  Verdict v;
  if (!tolerances.is_object()) return v;
  const json limits = limits_for_travel(tolerances, travel_mm(result, "position_mm"), v.basis);
  // A straightness's limit applies to its straightness about the least-squares line; an
  // angular or roll run's to its angular deviation (the range).
  const bool straight = result.value("kind", "") == "straightness";
  const char* limit_key = straight ? "straightness_um" : "angular_urad";
  const std::string row_key = straight ? "straightness_um" : "range";
  if (!limits.contains(limit_key)) return v;
  for (const auto& r : profile_rows(result))
    if (r.key == row_key) {
      const double lim = limits[limit_key].get<double>();
      v.checks.push_back({r.key, r.symbol, r.value, lim, r.unit, within(r.value, lim)});
    }
  conclude(v);
  return v;
}

// A five-axis ballbar run's location errors against each axis's location_um (positions) and
// location_urad (tilts): the magnitude of what the control's kinematics leave (`left`: the
// fitted value less the control's own; against a nominal control, the fitted value).
Verdict ballbar5x_verdict(const json& tolerances, const json& result) {
  Verdict v;
  if (!tolerances.is_object()) return v;
  v.basis = tolerances.value("source", std::string("tolerances"));
  for (const auto& a : result.value("axes", json::array())) {
    const json limits = tolerances.value(a.value("axis", std::string()), json::object());
    const json loc = a.value("location", json::object());
    for (const auto& n : a.value("names", json::array())) {
      const std::string name = n.is_string() ? n.get<std::string>() : std::string();
      if (!loc.contains(name) || !loc[name].is_object()) continue;
      const std::string unit = loc[name].value("unit", std::string());
      const char* key = unit == "um" ? "location_um" : "location_urad";
      if (!limits.contains(key) || !limits[key].is_number()) continue;
      const double left = loc[name].value("left", 0.0), lim = limits[key].get<double>();
      v.checks.push_back({name, name, left, lim, unit, within(left, lim)});
    }
  }
  conclude(v);
  return v;
}

Verdict circle_verdict(const json& tolerances, const json& result) {
  Verdict v;
  if (!tolerances.is_object()) return v;
  v.basis = tolerances.value("source", std::string("tolerances"));
  const auto& iso = result.value("iso230_4", json::object());
  if (tolerances.contains("G_um")) {
    const double lim = tolerances["G_um"].get<double>();
    if (iso.contains("G_bi_um")) {
      const double g = iso.value("G_bi_um", 0.0);
      v.checks.push_back({"G_bi_um", "G", g, lim, "um", within(g, lim)});
    } else {  // ISO 230-4:1996 has no G(b): the limit applies to each direction's G
      for (const auto& [key, symbol] : {std::pair{"G_ccw_um", "G (ccw)"}, {"G_cw_um", "G (cw)"}})
        if (iso.value(key, 0.0) > 0) {
          const double g = iso.value(key, 0.0);
          v.checks.push_back({key, symbol, g, lim, "um", within(g, lim)});
        }
    }
  }
  const json diagnostics = tolerances.value("diagnostics", json::object());
  const json reported = result.value("diagnostics", json::array());
  for (const auto& [key, lim] : diagnostics.items()) {
    const json* found = nullptr;
    for (const auto& d : reported)
      if (d.value("key", "") == key) found = &d;
    if (!found) {
      v.notes.push_back(
          fmt::format("{} limit {:g} not applied: this run's analysis did not report it", key,
                      lim.get<double>()));
      continue;
    }
    const double value = found->value("value", 0.0);
    v.checks.push_back({key, found->value("name", key), value, lim.get<double>(),
                        found->value("unit", ""), within(value, lim.get<double>())});
  }
  conclude(v);
  return v;
}

Verdict verdict_of(const json& settings, const json& result) {
  const json none;
  const json& tol = settings.is_object() && settings.contains("context") &&
                            settings["context"].is_object() &&
                            settings["context"].contains("tolerances")
                        ? settings["context"]["tolerances"]
                        : none;
  if (is_circle_schema(result.value("schema", ""))) return circle_verdict(tol, result);
  if (is_profile_schema(result.value("schema", ""))) return profile_verdict(tol, result);
  if (is_rotary_schema(result.value("schema", ""))) return rotary_verdict(tol, result);
  if (result.value("schema", "") == "caldaq.ballbar5x.v1") return ballbar5x_verdict(tol, result);
  return linear_verdict(tol, result);
}

LimitsWhere limits_where(std::string_view kind, std::string_view axis, const json& settings,
                         const json& result) {
  LimitsWhere w;
  w.keys = tolerance_keys(kind, standard_title(result));
  const json none = json::object();
  const json& context =
      settings.is_object() && settings.contains("context") && settings["context"].is_object()
          ? settings["context"]
          : none;
  const json configuration = context.value("configuration", json());
  if (configuration.is_string()) w.configuration = configuration.get<std::string>();
  if (kind == "ballbar5x") {
    // daq model ballbar5x-run makes these runs, with no configuration: its --tolerances file
    // holds each rotary axis's table.
    w.each = {"each position", "each tilt"};
    for (const char letter : axis) w.tables.push_back("tolerances." + std::string(1, letter));
    w.option = "daq model ballbar5x-run --tolerances";
  } else {
    w.tables.push_back("tolerances." + std::string(axis));
  }
  return w;
}

std::string to_text(const LimitsWhere& w, const LimitsMarkup& m, std::string_view subject,
                    std::string_view maker) {
  const auto list = [](const std::vector<std::string>& items) {  // "a", "a and b", "a, b and c"
    if (items.size() <= 1) return items.empty() ? std::string() : items.front();
    return fmt::format("{} and {}", fmt::join(items.begin(), items.end() - 1, ", "), items.back());
  };
  std::vector<std::string> tables;
  for (const auto& t : w.tables) tables.push_back(m.code("[" + t + "]"));
  const std::string where =
      !w.option.empty() ? "a file given to " + m.code(w.option)
      : w.configuration.empty()
          ? std::string("the configuration")
          : fmt::format("the configuration {} was made with ({})", maker, m.path(w.configuration));
  // A five-axis ballbar run's: each key judges its own values.
  if (!w.each.empty() && w.each.size() == w.keys.size()) {
    std::vector<std::string> keys;
    for (std::size_t i = 0; i < w.keys.size(); ++i)
      keys.push_back(fmt::format("{} ({})", m.code(w.keys[i]), m.text(w.each[i])));
    return fmt::format(
        "no limit was stored with this run: {} under {} in {} judge what the control's "
        "kinematics leave of each location error (docs/config.md)",
        list(keys), list(tables), where);
  }
  std::vector<std::string> keys;
  for (const auto& k : w.keys) keys.push_back(m.code(k));
  return fmt::format(
      "no limit was stored with {}: {} under {} in {} judge{} the runs made with it "
      "(docs/config.md)",
      subject, either_of(keys), list(tables), where, w.keys.size() == 1 ? "s" : "");
}

std::string to_text(const LimitsWhere& w) {
  const auto same = [](std::string_view t) { return std::string(t); };
  return to_text(w, {.code = same, .path = same, .text = same});
}

Verdict run_verdict(std::string_view kind, std::string_view axis, const json& settings,
                    const json& result) {
  Verdict v = verdict_of(settings, result);
  if (!v.configured && v.notes.empty())
    v.hint = to_text(limits_where(kind, axis, settings, result));
  return v;
}

json to_json(const Verdict& v) {
  json j{{"configured", v.configured}, {"pass", v.configured ? json(v.pass) : json(nullptr)},
         {"summary", summary(v)},      {"basis", v.basis},
         {"notes", v.notes},           {"hint", v.hint},
         {"checks", json::array()}};
  for (const auto& c : v.checks)
    j["checks"].push_back({{"key", c.key},
                           {"symbol", c.symbol},
                           {"value", c.value},
                           {"limit", c.limit},
                           {"unit", c.unit},
                           {"pass", c.pass}});
  return j;
}

std::string summary(const Verdict& v) {
  if (!v.configured) return v.notes.empty() ? "no tolerance configured" : "no tolerance applies";
  return v.pass ? "PASS" : "FAIL";
}

void print_verdict(const Verdict& v) { print_verdict(to_json(v)); }

void print_verdict(const json& v, std::string_view in) {
  const auto safe = [](const json& j, const char* key) {
    return cal::text::terminal_safe(j.value(key, std::string()));
  };
  const json notes = v.value("notes", json::array());
  if (!v.value("configured", false)) {
    // Where the limits would be given, for the run's kind (a verdict made without the run: only
    // that they are a specification, docs/config.md).
    const std::string hint = safe(v, "hint");
    fmt::print("{}verdict: {}{}\n", in, safe(v, "summary"),
               !notes.empty() ? ""
               : hint.empty() ? " (no limit was stored with it: docs/config.md)"
                              : ": " + hint);
  } else {
    fmt::print("{}verdict against {}: {}\n", in, safe(v, "basis"), safe(v, "summary"));
    for (const auto& c : v.value("checks", json::array())) {
      const std::string unit = safe(c, "unit");
      fmt::print("{}  {:<28} {:>10} {:<5} limit {:>8} {:<5} {}\n", in, safe(c, "symbol"),
                 number_text(c.value("value", 0.0)), unit, number_text(c.value("limit", 0.0)), unit,
                 c.value("pass", false) ? "pass" : "FAIL");
    }
  }
  for (const auto& n : notes)
    if (n.is_string())
      fmt::print("{}  note: {}\n", in, cal::text::terminal_safe(n.get<std::string>()));
}

std::vector<std::string> tolerance_keys(std::string_view kind, std::string_view standard_title) {
  if (kind == "circle") return {"G_um"};
  if (kind == "ballbar5x") return {"location_um", "location_urad"};
  if (kind == "straightness") return {"straightness_um"};
  if (kind == "angular" || kind == "roll") return {"angular_urad"};
  const std::string unit = kind == "rotary" ? "_arcsec" : "_um";
  const bool vdi = standard_title.find("3441") != std::string_view::npos;
  std::vector<std::string> keys;
  for (const char* k : vdi ? std::vector<const char*>{"P", "Pa", "Ps", "U"}
                           : std::vector<const char*>{"E", "R", "A", "B", "M"})
    keys.push_back(k + unit);
  return keys;
}

std::string either_of(const std::vector<std::string>& items) {
  std::string out;
  for (std::size_t i = 0; i < items.size(); ++i)
    out += (i == 0 ? "" : i + 1 == items.size() ? " or " : ", ") + items[i];
  return out;
}

const Check* find_check(const Verdict& v, const std::string& key) {
  for (const auto& c : v.checks)
    if (c.key == key) return &c;
  return nullptr;
}

}  // namespace daq
