#pragma once
// The three-plane view of ballbar tests (docs/circle.md, "The three-plane table"): the
// squareness and scale mismatch of the XY, YZ and ZX tests combined into one table of the
// machine's three squareness errors and the scales of its three axes. Pure maths; the stored
// runs are gathered in daq (ballbar_campaign.hpp).
#include <array>
#include <optional>
#include <span>

#include "cal/analysis/circle.hpp"
#include "cal/analysis/kinematics.hpp"

namespace cal::circle {

// One plane's geometric values from its ballbar test(s), in the plane's own axis order
// (circle.hpp: XY = X, Y; YZ = Y, Z; ZX = Z, X) and caldaq's signs (docs/circle.md).
struct PlaneValues {
  Plane plane = Plane::xy;
  double squareness_um_per_m = 0.0;      // alpha: positive when the angle between +u, +v > 90 deg
  double scale_mismatch_um_per_m = 0.0;  // s_u - s_v
  // (s_u + s_v) / 2 = radius error / R, from a calibrated bar only (unset otherwise).
  std::optional<double> mean_scale_um_per_m;
};

struct ThreePlanes {
  std::array<std::optional<PlaneValues>, 3> planes;  // indexed by Plane (xy, yz, zx)
  // The scale errors of X, Y, Z (um/m). Absolute when the calibrated planes' mean scales with
  // the mismatches determine all three (least squares when over-determined); otherwise
  // relative, their mean set to 0, from the mismatches of at least two planes; unset from one.
  std::optional<std::array<double, 3>> scale_um_per_m;
  bool scale_absolute = false;
  // rms of what the scale solution leaves in its equations (over-determined systems only).
  std::optional<double> scale_residual_um_per_m;
  // With all three planes: (s_x - s_y) + (s_y - s_z) + (s_z - s_x) as measured, 0 for a
  // consistent set (noise, drift between the tests, local errors of each position).
  std::optional<double> closure_um_per_m;
};

// Throws cal::InputError for two values of one plane, or a non-finite value.
ThreePlanes combine_planes(std::span<const PlaneValues> planes);

// The model's plane of a ballbar plane (ZX is the model's XZ) and the ISO 230-1 location error
// of its squareness alpha: E_C0Y = +alpha_XY, E_B0Z = -alpha_ZX, E_A0Z = +alpha_YZ.
kinematics::Plane model_plane(Plane p);
double location_error_urad(const PlaneValues& v);

}  // namespace cal::circle
