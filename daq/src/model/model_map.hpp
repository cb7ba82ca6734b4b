#pragma once
// The volumetric error map of a machine model over a grid, its summary and the 21 errors'
// contributions: one computation and one JSON (caldaq.volumetric-map.v1's grid, summary,
// contributions and points) for `daq model map --json` and the operator page's GET /api/model.
#include <nlohmann/json.hpp>
#include <span>
#include <string_view>
#include <vector>

#include "cal/analysis/kinematics.hpp"
#include "model/model_file.hpp"

namespace cal::daq::model {

struct ModelMap {
  kinematics::Grid grid;
  kinematics::ErrorMap map;
  kinematics::MapSummary summary;
  std::vector<kinematics::Contribution> contributions;  // largest first
};

// Throws cal::InputError when the model cannot be evaluated over the grid or a value is not
// finite (require_finite: nothing shows inf or nan).
ModelMap model_map(const Model& m, const kinematics::Grid& g, kinematics::Method method);

// {"grid", "summary", "contributions"} and, with_points, "points" (position_mm, error_um,
// rotation_urad of each).
nlohmann::json model_map_json(const ModelMap& m, bool with_points);

// InputError "WHAT: not a finite number (...)" unless every value is finite: checked before
// anything is printed, so that no map or prediction shows inf or nan.
void require_finite(std::span<const double> values, std::string_view what);

}  // namespace cal::daq::model
