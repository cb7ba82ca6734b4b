#pragma once
// Two machine models side by side: how far each error of one is from the other's, and what that
// does to the volumetric error. Used to check a model built from measurements against a known
// truth (the SIMULATED shop's injected errors, `daq sim --truth-out`), or a machine's model
// against its model of a year ago.
#include <array>
#include <string>
#include <vector>

#include "model/model_file.hpp"

namespace cal::daq::model {

struct ComponentDifference {
  std::string name;      // "E_YX", "E_C0Y"
  std::string unit;      // "um" or "urad"
  double max_abs = 0.0;  // largest |other - reference| over the compared positions
  double at_mm = 0.0;    // where (0 for a squareness)
  bool squareness = false;
};

struct Comparison {
  // Per axis, the positions compared: where both models are defined (both travels, both tables).
  std::array<std::array<double, 2>, 3> range_mm{};
  std::vector<ComponentDifference> components;  // the 18, then the three squareness errors
  // The volumetric error of `other` minus that of `reference` at the tool point of the
  // reference (other's own offsets replaced by the reference's, so the same point is compared),
  // over a grid of the compared ranges: the largest norm and where.
  double volumetric_max_um = 0.0;
  kinematics::Vec3 volumetric_at_mm{};
  kinematics::Grid grid;
  bool same_topology = true;
  bool same_offsets = true;  // tool and table offsets equal (else the reference's are used)
};

// Compares at every table point of either model inside the common range and at `samples`
// evenly spaced positions per axis; the volumetric difference over `count` points per axis.
// Throws cal::InputError when the models share no range on an axis (naming it) or a model has
// neither a travel nor tables to say where it is defined on an axis.
Comparison compare(const Model& reference, const Model& other, std::array<std::size_t, 3> count,
                   std::size_t samples = 101);

}  // namespace cal::daq::model
