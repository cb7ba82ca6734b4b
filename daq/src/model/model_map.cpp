// The volumetric error map of a model (see model_map.hpp).
#include "model_map.hpp"

#include <fmt/format.h>

#include <array>
#include <cmath>

#include "cal/analysis/error.hpp"

namespace cal::daq::model {

namespace kin = cal::kinematics;
using nlohmann::json;

namespace {
json vec_json(const kin::Vec3& v) { return json::array({v[0], v[1], v[2]}); }
json triple(const std::vector<double>& flat, std::size_t p) {
  return json::array({flat[3 * p], flat[3 * p + 1], flat[3 * p + 2]});
}
constexpr std::array kAxis{"X", "Y", "Z"};
}  // namespace

void require_finite(std::span<const double> values, std::string_view what) {
  for (double v : values)
    if (!std::isfinite(v))
      throw cal::InputError(fmt::format(
          "{}: {} is not a finite number (the model's values or coefficients overflow here)", what,
          v));
}

ModelMap model_map(const Model& m, const kin::Grid& g, kin::Method method) {
  ModelMap out{.grid = g, .map = kin::volumetric_error_map(m.machine, g, method)};
  out.summary = kin::summarize(out.map);
  out.contributions = kin::contributions(m.machine, g);
  require_finite(out.map.errors_um, "the volumetric error over the grid");
  require_finite(out.map.rotations_urad, "the rotation over the grid");
  for (const auto& c : out.contributions)
    require_finite(std::array{c.max_norm_um, c.rms_um}, "the contribution of " + c.name);
  return out;
}

json model_map_json(const ModelMap& m, bool with_points) {
  const auto& g = m.grid;
  const auto& s = m.summary;
  json cs = json::array();
  for (const auto& c : m.contributions)
    cs.push_back({{"error", c.name},
                  {"axis", kAxis[c.axis]},
                  {"max_norm_um", c.max_norm_um},
                  {"rms_um", c.rms_um}});
  json j{{"grid",
          {{"min_mm", vec_json(g.min_mm)},
           {"max_mm", vec_json(g.max_mm)},
           {"count", {g.count[0], g.count[1], g.count[2]}}}},
         {"summary",
          {{"max_norm_um", s.max_norm_um},
           {"max_norm_at_mm", vec_json(s.max_norm_at_mm)},
           {"min_um", vec_json(s.min_um)},
           {"max_um", vec_json(s.max_um)},
           {"range_um", vec_json(s.range_um)}}},
         {"contributions", std::move(cs)}};
  if (!with_points) return j;
  json pts = json::array();
  for (std::size_t p = 0; p < m.map.size(); ++p)
    pts.push_back({{"position_mm", triple(m.map.positions_mm, p)},
                   {"error_um", triple(m.map.errors_um, p)},
                   {"rotation_urad", triple(m.map.rotations_urad, p)}});
  j["points"] = std::move(pts);
  return j;
}

}  // namespace cal::daq::model
