#pragma once
// The location errors of one or more rotary axes fitted together to sphere centres probed at
// poses that may turn several rotary axes at once (a table-table trunnion turning C and A in one
// probing program; a head axis; a table axis and a head axis): the sphere stays fixed on the
// workpiece, each centre is what the control reports (control_tip_mm, machine coordinates), and
// the model is the exact one of rotary.hpp. Conventions: rotary.hpp; derivation, tolerances and
// what is verified: docs/kinematics.md, "Several rotary axes fitted together".
#include <cstddef>
#include <span>
#include <vector>

#include "cal/analysis/rotary.hpp"

namespace cal::kinematics {

struct ProbedPose {
  std::vector<double> angles_deg;  // one per rotary axis, in the chain's order
  Vec3 centre_mm{};                // as the control reports it: machine coordinates
};

struct LocationFit {
  std::vector<std::size_t> axes;  // the fitted axes, indices in the chain
  // Per fitted axis, in the layout of RotaryAxis (the slots along / about its own direction 0).
  std::vector<Vec3> position_um, position_u_um, orientation_urad, orientation_u_urad;
  Vec3 sphere_mm{}, sphere_u_um{};  // the sphere on the workpiece, home coordinates
  // Covariance of the parameters, row-major, n = 3 + 4 * axes.size(): the sphere (mm), then per
  // axis its two positions (mm) and two orientations (rad), the slots across its direction by
  // increasing index. NaN when sigma cannot be estimated.
  std::vector<double> covariance;
  std::vector<Vec3> residual_um;  // reported minus predicted, per pose
  double rms_um = 0.0;            // over the 3 N coordinates
  double sigma_um = 0.0;          // the probe's, or sqrt(sum r^2 / dof)
  int dof = 0;                    // 3 N - n
  // The design's smallest over largest singular value, its columns scaled to unit length: how
  // well the poses tell the parameters apart (1: orthogonal; refused below 1e-4).
  double separability = 0.0;
};

// Gauss-Newton on the exact model: the candidate machine is control_kinematics(control) with the
// fitted axes' location errors replaced by the parameters (relative to their NOMINAL pivots),
// plus control's linear-axis errors when with_linear_errors (they are the machine's, not read
// as the rotary axes'); its centres are probed_centre_mm(candidate, control, sphere, pose).
// probe_u_um: sigma per coordinate, 0 estimates it from the residuals. Throws InputError for
// axes out of range or given twice, poses whose angle count is not the chain's, non-finite
// input, fewer poses than parameters / 3 + 1, a negative probe_u_um, and poses that cannot
// separate the parameters (a parameter that moves no centre by 1 nm per mm or rad; the design's
// smallest singular value, columns scaled to unit length, below 1e-4 of its largest: the
// message says so).
LocationFit fit_location_errors(const FiveAxisMachine& control, std::span<const std::size_t> axes,
                                std::span<const ProbedPose> poses, double probe_u_um = 0.0,
                                bool with_linear_errors = true);

// The point standard deviation of a least-squares fit, in mm: the probe's if given (probe_u_um
// > 0, in um), else sqrt(sum_sq_mm2 / dof) from the residuals; NaN when neither (dof <= 0).
// Shared by the fits of rotary.hpp and this file.
double fit_sigma_mm(double sum_sq_mm2, int dof, double probe_u_um);

// The offset between two fitted axes' lines: for lines that are not parallel, the signed length
// of their common perpendicular, (p2 - p1) . n, n = d1 x d2 normalised (for a C line and an A
// line, n is about +Y: the second line passes that far on +Y of the first); for parallel lines
// (|d1 x d2| < 1e-9) the distance between them. In mm, with its standard uncertainty in um from
// the fit's covariance (the gradient by central differences). The lines are the fitted ones with
// every axis at 0, in home coordinates. first, second: positions in fit.axes.
struct LineOffset {
  double distance_mm = 0.0;
  double u_um = 0.0;
};
LineOffset line_offset(const FiveAxisMachine& control, const LocationFit& fit, std::size_t first,
                       std::size_t second);

}  // namespace cal::kinematics
