#include "verdict.hpp"

#include <fmt/format.h>

#include <cmath>

#include "circle_output.hpp"

namespace daq {

using nlohmann::json;

namespace {

// The value as it is printed (3 decimals), so the verdict agrees with what the reader sees.
bool within(double value, double limit) {
  return std::round(std::abs(value) * 1e3) / 1e3 <= limit + 1e-12;
}

double travel_mm(const json& result) {
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& t : result.value("targets", json::array())) {
    const double x = t.value("target_mm", 0.0);
    lo = std::min(lo, x), hi = std::max(hi, x);
  }
  return hi >= lo ? hi - lo : 0.0;
}

}  // namespace

Verdict linear_verdict(const json& tolerances, const json& result) {
  Verdict v;
  if (!tolerances.is_object()) return v;
  const double travel = travel_mm(result);
  json limits = tolerances;
  v.basis = tolerances.value("source", std::string("tolerances"));
  for (const auto& e : tolerances.value("by_length", json::array()))
    if (travel <= e.value("up_to_mm", 0.0) + 1e-9) {
      for (const auto& [k, val] : e.items())
        if (k != "up_to_mm") limits[k] = val;
      v.basis += fmt::format(" (measured travel {:g} mm, up to {:g} mm)", travel,
                             e.value("up_to_mm", 0.0));
      break;
    }
  const bool bi = result.value("bidirectional", true);
  const auto& axis = result.value("axis", json::object());
  const std::string title = result.contains("standard")
                                ? result["standard"].value("title", std::string("this standard"))
                                : "this standard";
  // Which value of the evaluation each limit applies to.
  const struct {
    const char* limit;
    const char* bi_key;
    const char* uni_key;
  } map[] = {{"E_um", "E_bi", "E_up"},
             {"R_um", "R_bi", "R_up"},
             {"B_um", "B", nullptr},
             {"A_um", "A_bi", "A_up"},
             {"M_um", "M", nullptr}};
  for (const auto& m : map) {
    if (!limits.contains(m.limit)) continue;
    const char* key = bi ? m.bi_key : m.uni_key;
    const std::string name(m.limit, 1);
    if (!key || !axis.contains(key)) {
      v.notes.push_back(fmt::format("{} limit {:g} µm not applied: {} gives no {}{}", name,
                                    limits[m.limit].get<double>(), title, name,
                                    bi ? "" : " for a one-way test"));
      continue;
    }
    const double value = axis[key].value("value_um", 0.0), lim = limits[m.limit].get<double>();
    v.checks.push_back(
        {key, axis[key].value("symbol", name), value, lim, "um", within(value, lim)});
  }
  v.configured = !v.checks.empty();
  v.pass = v.configured;
  for (const auto& c : v.checks) v.pass = v.pass && c.pass;
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
  v.configured = !v.checks.empty();
  v.pass = v.configured;
  for (const auto& c : v.checks) v.pass = v.pass && c.pass;
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
  return linear_verdict(tol, result);
}

json to_json(const Verdict& v) {
  json j{{"configured", v.configured}, {"pass", v.configured ? json(v.pass) : json(nullptr)},
         {"summary", summary(v)},      {"basis", v.basis},
         {"notes", v.notes},           {"checks", json::array()}};
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

void print_verdict(const Verdict& v) {
  if (!v.configured) {
    fmt::print("verdict: no tolerance configured{}\n",
               v.notes.empty() ? " ([tolerances] in the configuration, docs/config.md)" : "");
  } else {
    fmt::print("verdict against {}: {}\n", v.basis, summary(v));
    for (const auto& c : v.checks) {
      const std::string unit = c.unit == "um" ? "um" : c.unit;
      fmt::print("  {:<28} {:>10.3f} {:<5} limit {:>8.3f} {:<5} {}\n", c.symbol, c.value, unit,
                 c.limit, unit, c.pass ? "pass" : "FAIL");
    }
  }
  for (const auto& n : v.notes) fmt::print("  note: {}\n", n);
}

const Check* find_check(const Verdict& v, const std::string& key) {
  for (const auto& c : v.checks)
    if (c.key == key) return &c;
  return nullptr;
}

}  // namespace daq
