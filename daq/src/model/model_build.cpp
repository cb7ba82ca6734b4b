// Building a model from measured profiles (see model_build.hpp).
#include "model/model_build.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "cal/analysis/error.hpp"
#include "cal/analysis/straightness.hpp"

namespace cal::daq::model {

namespace kin = cal::kinematics;
using nlohmann::json;

namespace {

std::size_t axis_of(kin::Component c) { return static_cast<std::size_t>(c) / 6; }
bool is_angle(kin::Component c) { return static_cast<std::size_t>(c) % 6 >= 3; }
// The direction of a translational component (E_YX -> Y).
std::size_t direction_of(kin::Component c) { return static_cast<std::size_t>(c) % 6; }

std::string source_json(const MeasuredProfile& p, std::string_view treatment) {
  return json{{"kind", "run"},
              {"run_id", p.run_id},
              {"measure", p.kind},
              {"started_utc", p.started_utc},
              {"stationary_mm", p.stationary_mm},
              {"probe_offset_mm", p.probe_offset_mm},
              {"treatment", treatment}}
      .dump();
}

}  // namespace

BuildReport build(const std::vector<MeasuredProfile>& profiles, const BuildOptions& o) {
  BuildReport r;
  Model& m = r.model;
  m.name = o.machine;
  m.machine.topology = o.topology;
  m.machine.tool_offset_mm = o.tool_offset_mm;
  m.machine.table_offset_mm = o.table_offset_mm;

  std::map<kin::Component, const MeasuredProfile*> by;
  for (const auto& p : profiles) {
    const auto c = kin::component_from_string(p.component);
    if (p.position_mm.size() < 2 || p.position_mm.size() != p.value.size())
      throw InputError(fmt::format("run {} ({}): {} targets: a table needs at least 2", p.run_id,
                                   p.component, p.position_mm.size()));
    by[c] = &p;
  }
  // The travel of each axis: where all its measured tables overlap.
  std::array<std::array<double, 2>, 3> travel{};
  for (std::size_t a = 0; a < 3; ++a) travel[a] = {-INFINITY, INFINITY};
  std::array<bool, 3> any{};
  for (const auto& [c, p] : by) {
    auto& t = travel[axis_of(c)];
    t[0] = std::max(t[0], p->position_mm.front());
    t[1] = std::min(t[1], p->position_mm.back());
    any[axis_of(c)] = true;
  }
  for (std::size_t a = 0; a < 3; ++a) {
    if (!any[a]) travel[a] = {0.0, 0.0};
    if (any[a] && !(travel[a][0] < travel[a][1]))
      throw InputError(fmt::format("the runs of axis {} cover no common travel", "XYZ"[a]));
  }
  if (std::all_of(any.begin(), any.end(), [](bool b) { return b; })) m.travel_mm = travel;

  // 1. Angular errors: the profiles relative to their first target.
  kin::Machine angles;
  angles.topology = o.topology;
  angles.table_offset_mm = o.table_offset_mm;
  for (const auto& [c, p] : by) {
    if (!is_angle(c)) continue;
    std::vector<double> v(p->value);
    for (auto& x : v) x -= p->value.front();
    kin::component(angles, c) = kin::component(m.machine, c) =
        kin::ErrorFunction::table(p->position_mm, v);
    m.components[static_cast<std::size_t>(c)] = {true,
                                                 {source_json(*p, "relative to the first target")}};
    r.used.push_back({p->component, {p->run_id}});
  }

  // 2. Translations: Abbe terms of the measured angles removed, then the datum or the line.
  std::map<std::string, std::pair<double, std::int64_t>> slopes;  // "E_YX" -> (urad, run)
  for (const auto& [c, p] : by) {
    if (is_angle(c)) continue;
    const auto axis = axis_of(c), dir = direction_of(c);
    kin::Machine at_probe = angles;
    at_probe.tool_offset_mm = p->probe_offset_mm;
    // An angle between two targets is interpolated, and the interpolation error times the
    // travel looks like squareness: the stationary axes belong at targets of their own runs.
    for (std::size_t j = 0; j < 3; ++j) {
      if (j == axis) continue;
      const auto& f = at_probe.axes[j].ea_urad;
      const auto q = f.positions_mm();
      if (f.is_table() && std::none_of(q.begin(), q.end(), [&](double x) {
            return std::abs(x - p->stationary_mm[j]) < 1e-6;
          }))
        r.notes.push_back(fmt::format(
            "{} (run {}): {} stood at {:g} mm, between the targets of its angular runs: its "
            "angles there are interpolated (place stationary axes at targets)",
            p->component, p->run_id, "XYZ"[j], p -> stationary_mm[j]));
    }
    std::vector<double> v(p->value.size());
    for (std::size_t i = 0; i < v.size(); ++i) {
      kin::Vec3 pos = p->stationary_mm;
      pos[axis] = p->position_mm[i];
      v[i] = p->value[i] - kin::volumetric_error_um(at_probe, pos, kin::Method::first_order)[dir];
    }
    std::string treatment;
    if (dir == axis) {
      const double first = v.front();
      for (auto& x : v) x -= first;
      treatment = "Abbe terms of the measured angles removed; relative to the first target";
    } else {
      const auto line = cal::straightness::evaluate(p->position_mm, v,
                                                    cal::straightness::Reference::least_squares);
      v = line.residual_um;
      treatment = "Abbe terms of the measured angles removed; least-squares line removed";
      if (p->square)
        slopes[p->component] = {line.slope_um_per_m, p->run_id};
      else
        r.notes.push_back(
            fmt::format("{} (run {}) was not read against a square: its slope gives no squareness",
                        p->component, p->run_id));
    }
    kin::component(m.machine, c) = kin::ErrorFunction::table(p->position_mm, v);
    m.components[static_cast<std::size_t>(c)] = {true, {source_json(*p, treatment)}};
    r.used.push_back({p->component, {p->run_id}});
  }

  // 3. Squareness from the pairs: slope a of the first run, b of the second, value s (a + b).
  struct Pair {
    kin::Plane plane;
    const char *first, *second;
    double sign;
  };
  for (const Pair& q :
       {Pair{kin::Plane::xy, "E_YX", "E_XY", -1.0}, Pair{kin::Plane::xz, "E_ZX", "E_XZ", 1.0},
        Pair{kin::Plane::yz, "E_ZY", "E_YZ", -1.0}}) {
    const auto a = slopes.find(q.first), b = slopes.find(q.second);
    if (a == slopes.end() || b == slopes.end()) continue;
    m.machine.squareness.of(q.plane) = q.sign * (a->second.first + b->second.first);
    auto& e = m.squareness[static_cast<std::size_t>(q.plane)];
    e.given = true;
    e.method = "straightness";
    e.placement = "global";
    e.source.json =
        json{{"kind", "runs"},
             {"run_ids", {a->second.second, b->second.second}},
             {"from", fmt::format("slopes of {} and {} against one square", q.first, q.second)}}
            .dump();
    r.used.push_back(
        {std::string(kin::location_error_name(q.plane)), {a->second.second, b->second.second}});
  }

  for (kin::Component c : kin::all_components())
    if (!by.count(c)) r.missing.emplace_back(kin::to_string(c));
  for (std::size_t k = 0; k < 3; ++k)
    if (!m.squareness[k].given)
      r.missing.emplace_back(kin::location_error_name(static_cast<kin::Plane>(k)));
  if (!r.missing.empty() && !o.allow_missing)
    throw InputError(fmt::format(
        "machine '{}': {} of the 21 errors {} no stored run: {} (measure them, or allow a "
        "partial model where they are zero)",
        o.machine, r.missing.size(), r.missing.size() == 1 ? "has" : "have",
        fmt::join(r.missing, ", ")));
  json runs = json::object();
  for (const auto& [name, ids] : r.used) runs[name] = ids;
  m.provenance.json = json{
      {"written_by", "daq model build"},
      {"machine", o.machine},
      {"runs", runs},
      {"missing_taken_as_zero",
       r.missing}}.dump();
  return r;
}

}  // namespace cal::daq::model
