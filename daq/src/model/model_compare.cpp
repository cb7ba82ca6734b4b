#include "model/model_compare.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

#include "cal/analysis/error.hpp"

namespace cal::daq::model {

namespace kin = cal::kinematics;

namespace {

constexpr std::array kAxisName{"X", "Y", "Z"};

std::size_t axis_of(kin::Component c) { return static_cast<std::size_t>(c) / 6; }
bool is_angle(kin::Component c) { return static_cast<std::size_t>(c) % 6 >= 3; }

// Where both models are defined on each axis: their travels and every table's ends.
std::array<std::array<double, 2>, 3> common_range(const Model& a, const Model& b) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  std::array<std::array<double, 2>, 3> r{{{-inf, inf}, {-inf, inf}, {-inf, inf}}};
  const auto narrow = [&](std::size_t axis, double lo, double hi) {
    r[axis][0] = std::max(r[axis][0], lo);
    r[axis][1] = std::min(r[axis][1], hi);
  };
  for (const Model* m : {&a, &b}) {
    if (m->travel_mm)
      for (std::size_t k = 0; k < 3; ++k) narrow(k, (*m->travel_mm)[k][0], (*m->travel_mm)[k][1]);
    for (kin::Component c : kin::all_components()) {
      const auto& f = kin::component(m->machine, c);
      if (f.is_table()) narrow(axis_of(c), f.positions_mm().front(), f.positions_mm().back());
    }
  }
  for (std::size_t k = 0; k < 3; ++k) {
    if (std::isinf(r[k][0]) || std::isinf(r[k][1]))
      throw cal::InputError(fmt::format(
          "axis {}: neither model says where it is defined (no travel_mm and no tables)",
          kAxisName[k]));
    if (r[k][0] > r[k][1])
      throw cal::InputError(
          fmt::format("axis {}: the two models share no range (their travels or tables do not "
                      "overlap)",
                      kAxisName[k]));
  }
  return r;
}

// Every table point of either model on the axis inside the range, and `samples` even steps.
std::vector<double> positions_on(const Model& a, const Model& b, std::size_t axis,
                                 std::array<double, 2> range, std::size_t samples) {
  std::set<double> q;
  for (std::size_t s = 0; s < samples; ++s)
    q.insert(samples == 1 ? range[0]
                          : range[0] + (range[1] - range[0]) * static_cast<double>(s) /
                                           static_cast<double>(samples - 1));
  for (const Model* m : {&a, &b})
    for (kin::Component c : kin::all_components()) {
      const auto& f = kin::component(m->machine, c);
      if (axis_of(c) != axis || !f.is_table()) continue;
      for (const double p : f.positions_mm())
        if (p >= range[0] && p <= range[1]) q.insert(p);
    }
  return {q.begin(), q.end()};
}

ComponentDifference component_difference(const Model& a, const Model& b, kin::Component c,
                                         const std::vector<double>& at) {
  ComponentDifference d{.name = std::string(kin::to_string(c)),
                        .unit = is_angle(c) ? "urad" : "um"};
  const auto& fa = kin::component(a.machine, c);
  const auto& fb = kin::component(b.machine, c);
  for (const double p : at) {
    const double diff = std::abs(fb(p) - fa(p));
    if (!std::isfinite(diff))
      throw cal::InputError(fmt::format("{} at {} mm: not a finite number", d.name, p));
    if (diff > d.max_abs) d.max_abs = diff, d.at_mm = p;
  }
  return d;
}

}  // namespace

Comparison compare(const Model& reference, const Model& other, std::array<std::size_t, 3> count,
                   std::size_t samples) {
  if (samples == 0 || std::any_of(count.begin(), count.end(), [](auto n) { return n == 0; }))
    throw cal::InputError("compare: at least one position per axis");
  Comparison out;
  out.range_mm = common_range(reference, other);
  std::array<std::vector<double>, 3> at;
  for (std::size_t k = 0; k < 3; ++k)
    at[k] = positions_on(reference, other, k, out.range_mm[k], samples);
  for (kin::Component c : kin::all_components())
    out.components.push_back(component_difference(reference, other, c, at[axis_of(c)]));
  for (kin::Plane p : {kin::Plane::xy, kin::Plane::xz, kin::Plane::yz})
    out.components.push_back(
        {.name = std::string(kin::location_error_name(p)),
         .unit = "urad",
         .max_abs = std::abs(other.machine.squareness.of(p) - reference.machine.squareness.of(p)),
         .squareness = true});

  // The same tool point on both: the reference's offsets on the other machine.
  kin::Machine o = other.machine;
  out.same_topology = o.topology == reference.machine.topology;
  out.same_offsets = o.tool_offset_mm == reference.machine.tool_offset_mm &&
                     o.table_offset_mm == reference.machine.table_offset_mm;
  o.tool_offset_mm = reference.machine.tool_offset_mm;
  o.table_offset_mm = reference.machine.table_offset_mm;
  for (std::size_t k = 0; k < 3; ++k) {
    out.grid.min_mm[k] = out.range_mm[k][0];
    out.grid.max_mm[k] = out.range_mm[k][1];
    out.grid.count[k] = count[k];
  }
  const auto ma = kin::volumetric_error_map(reference.machine, out.grid, kin::Method::htm);
  const auto mb = kin::volumetric_error_map(o, out.grid, kin::Method::htm);
  for (std::size_t p = 0; p < ma.size(); ++p) {
    double n2 = 0.0;
    for (std::size_t k = 0; k < 3; ++k) {
      const double d = mb.errors_um[3 * p + k] - ma.errors_um[3 * p + k];
      n2 += d * d;
    }
    if (!std::isfinite(n2))
      throw cal::InputError("the volumetric difference is not a finite number");
    if (std::sqrt(n2) > out.volumetric_max_um) {
      out.volumetric_max_um = std::sqrt(n2);
      out.volumetric_at_mm = {ma.positions_mm[3 * p], ma.positions_mm[3 * p + 1],
                              ma.positions_mm[3 * p + 2]};
    }
  }
  return out;
}

}  // namespace cal::daq::model
