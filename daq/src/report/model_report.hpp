#pragma once
// The volumetric error page of a machine model (daq model map --report, daq model compensate
// --report): the model's facts, the error vectors over the volume as distorted grids in three
// slices, the 21 errors' contributions ranked, and, after a compensation, what remains. Self-
// contained HTML with PLplot SVG plots (plot.hpp). Content: docs/reports.md.
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cal/analysis/kinematics.hpp"

namespace cal::daq::report {

struct ModelPage {
  std::string title;   // e.g. the machine's name
  std::string source;  // the model file
  bool simulated = false;
  std::string origin;  // the model's provenance's origin ("SIMULATED", "MIXED", ...), if any
  std::map<std::string, std::string>
      origins;  // MIXED: each error not measured for real, its origin
  kinematics::Machine machine;
  kinematics::Grid grid;  // the volume (a map over it; slices through its middle)
  kinematics::Method method = kinematics::Method::htm;
  std::vector<std::pair<std::string, std::string>> facts;  // shown as a key/value table
  std::vector<std::vector<std::string>> components;        // name, form, range, source
  // After a compensation: its name and what the tool does relative to the commanded
  // position with it applied (um).
  struct Compensated {
    std::string what;
    std::function<kinematics::Vec3(const kinematics::Vec3&)> residual_um;
    std::vector<std::string> notes;
  };
  std::optional<Compensated> compensated;
  std::string software = "daq";
};

// Throws cal::InputError when the model cannot be evaluated over the grid.
std::string model_page(const ModelPage& p);

}  // namespace cal::daq::report
