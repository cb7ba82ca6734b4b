#pragma once
// Building a machine model (caldaq.model.v1, model_file.hpp) from measured profiles: the stored
// runs of the test kinds (daq/src/runner/kinds/), one per component. Pure: the caller reads the
// runs (daq model build reads the run store). Method, conventions and what is verified:
// docs/volumetric-walkthrough.md, "How the model is built".
//
// - Angular errors (pitch, yaw, roll) are the profiles, relative to their first target (the
//   optics and levels are zeroed there: a constant angle is not told apart from the set-up).
// - Positioning and straightness profiles were read at a probe offset with the other axes at
//   their stationary positions: the first-order Abbe terms of the measured angular errors (all
//   axes, at those positions, for the machine's chain) are subtracted, so the tables hold the
//   errors at the axes' reference points (docs/kinematics.md).
// - Positioning is then relative to its first target (the laser's datum).
// - Straightness has its least-squares line removed (ISO 230-1 reference lines); the slopes of
//   a plane's two straightness runs read against one square give its squareness:
//   E_C0Y = -(s_YX + s_XY), E_B0Z = s_ZX + s_XZ, E_A0Z = -(s_ZY + s_YZ) (s: slope of the
//   deviation in um/m = urad; derivation in the docs).
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "model/model_file.hpp"

namespace cal::daq::model {

struct MeasuredProfile {
  std::int64_t run_id = 0;
  std::string component;                   // "E_YX"
  std::string kind;                        // positioning | straightness | angular | roll
  std::vector<double> position_mm, value;  // per target: the mean of its stops (um or urad)
  kinematics::Vec3 stationary_mm{}, probe_offset_mm{};
  bool square = false;      // straightness against a square
  std::string started_utc;  // for the listing
};

struct BuildOptions {
  std::string machine;
  kinematics::Topology topology = kinematics::Topology::fxyz;
  kinematics::Vec3 tool_offset_mm{}, table_offset_mm{};
  // Missing components are refused unless allowed; allowed, they are zero and listed.
  bool allow_missing = false;
};

struct BuildReport {
  Model model;
  // Component (or squareness) name -> the run ids it came from.
  std::vector<std::pair<std::string, std::vector<std::int64_t>>> used;
  std::vector<std::string> missing;  // the 21 names not measured
  std::vector<std::string> notes;    // e.g. a straightness not read against a square
};

// One profile per component (the latest of each: the caller chooses). Throws cal::InputError
// naming what is missing (unless allowed), a profile with fewer than 2 targets, or travels of
// one axis's runs that do not overlap.
BuildReport build(const std::vector<MeasuredProfile>& profiles, const BuildOptions& options);

}  // namespace cal::daq::model
