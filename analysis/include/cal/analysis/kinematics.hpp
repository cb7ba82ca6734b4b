#pragma once
// Rigid-body kinematic model of a 3-axis machine tool (ISO 230-1 terminology): the 18 component
// errors of the three linear axes, the 3 squareness errors, the topology of the kinematic
// chain, and the volumetric error of the tool tip relative to the workpiece at any commanded
// position, by the exact product of homogeneous transformation matrices (HTM) or by its
// first-order (small-angle) expansion. Formulas, conventions and sources: docs/kinematics.md.
//
// Units: positions and offsets in mm, translational errors in um, angular errors in urad.
//
// Kinematic chain. The topology letters are read from the workpiece to the tool; F is the
// frame (bed). Axes left of F carry the workpiece (they move the table), axes right of F carry
// the tool. Each letter carries everything on its left (workpiece side) or on its right (tool
// side). Any of the 24 serial orders of X, Y, Z and F is a topology, for example:
//
//   FXYZ  workpiece = F -> X -> Y -> Z -> tool   (workpiece on the bed; X carries Y carries Z)
//   XFYZ  workpiece <- X <- F -> Y -> Z -> tool  (X table on the bed; column Y carries Z)
//   XYFZ  workpiece <- X <- Y <- F -> Z -> tool  (cross table: Y on the bed carries X; Z head)
//   XYZF  workpiece <- X <- Y <- Z <- F = tool   (tool fixed; Z carries Y carries X carries work)
//   YFXZ  workpiece <- Y <- F -> X -> Z -> tool  (Y table; the spindle moves in X, X carries Z)
//   ZFXY  workpiece <- Z <- F -> X -> Y -> tool  (horizontal centre: table in Z; column X
//                                                 carries the head in Y)
//
// Conventions (all derived and illustrated in docs/kinematics.md):
// - Sign: every component error is the error of the tool relative to the workpiece, as an
//   instrument between tool and workpiece sees it, for axes on either side of F. A positive
//   E_XX moves the tool further in +X relative to the workpiece than commanded, whether X moves
//   the tool or the table (the table then moves the other way).
// - Reference points. The errors of a tool-side axis are referred to a point fixed on its
//   carriage, at the tool reference point (spindle gauge point) when that axis is at 0: its
//   angular errors act on the vector from there to the tool tip. The errors of a workpiece-side
//   axis are referred to the table reference point, a point fixed on the table: its angular
//   errors act on the vector from the table reference point to the tool tip, which includes
//   the axis's own travel. (This is the usual HTM model; a straightness measured along a line
//   through the tool on a moving table also contains the term eps x (q u), see the docs.)
// - Squareness (ISO 230-1 location errors, X is the reference axis, Y defines the XY plane):
//   the actual direction of Y is Rz(E_C0Y) * (0,1,0), of Z is Ry(E_B0Z) * Rx(E_A0Z) * (0,0,1).
//   To first order: y travel gives an x error of -E_C0Y*y (E_C0Y > 0: angle between +X and +Y
//   larger than 90 deg), z travel gives x error +E_B0Z*z and y error -E_A0Z*z.
// - Exact rotations: R(ea, eb, ec) = Rz(ec) * Ry(eb) * Rx(ea).
#include <array>
#include <cstddef>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace cal::kinematics {

using Vec3 = std::array<double, 3>;

// An error as a function of the position of its axis (mm). Default: zero everywhere.
class ErrorFunction {
 public:
  ErrorFunction() = default;

  // c[0] + c[1] q + c[2] q^2 + ... with q in mm. Throws InputError when empty or not finite.
  static ErrorFunction polynomial(std::span<const double> coefficients);
  static ErrorFunction polynomial(std::initializer_list<double> coefficients);
  // Linear interpolation in a table with strictly increasing positions (>= 2 points). Positions
  // outside [first, last] are REFUSED (InputError), not extrapolated or clamped: a measured
  // table says nothing beyond its ends.
  static ErrorFunction table(std::span<const double> positions_mm, std::span<const double> values);

  // Throws InputError naming the position and the table range when outside the table.
  double operator()(double position_mm) const;
  // The same function multiplied by k (for sensitivity studies and tests).
  ErrorFunction scaled(double k) const;

  // What the function is, for writing it out: a polynomial's coefficients (empty for the
  // default zero), or a table's positions and values.
  bool is_table() const { return kind_ == Kind::table; }
  bool is_zero() const { return kind_ == Kind::polynomial && coefficients_.empty(); }
  std::span<const double> coefficients() const { return coefficients_; }
  std::span<const double> positions_mm() const { return positions_mm_; }
  std::span<const double> values() const { return values_; }

 private:
  enum class Kind { polynomial, table };
  Kind kind_ = Kind::polynomial;
  std::vector<double> coefficients_;  // polynomial; empty means zero
  std::vector<double> positions_mm_, values_;
};

// The six component errors of one linear axis, named by the direction of the error (ISO 230-1:
// E_<direction><axis>). For the X axis: ex = E_XX (positioning), ey = E_YX and ez = E_ZX
// (straightness), ea = E_AX (roll), eb = E_BX (pitch), ec = E_CX (yaw). For Y: ey = E_YY
// (positioning), ex = E_XY, ez = E_ZY, eb = E_BY (roll), ea = E_AY (pitch), ec = E_CY (yaw).
// For Z: ez = E_ZZ (positioning), ex = E_XZ, ey = E_YZ, ec = E_CZ (roll), ea = E_AZ, eb = E_BZ.
struct AxisErrors {
  ErrorFunction ex_um, ey_um, ez_um;        // translation along X, Y, Z
  ErrorFunction ea_urad, eb_urad, ec_urad;  // rotation about X, Y, Z
};

// Squareness conventions. `daq analyse squareness` (cal::squareness) reports alpha, positive
// when the angle between the positive directions of the two axes exceeds 90 degrees. The model
// holds the ISO 230-1 location errors, rotations about the machine axes: E_C0Y (about Z) of
// Y in the XY plane, E_B0Z (about Y) and E_A0Z (about X) of Z in the XZ and YZ planes. A
// positive rotation of Y about Z tilts +Y towards -X and opens the angle (E_C0Y = +alpha_XY);
// a positive rotation of Z about X tilts +Z towards -Y and opens it (E_A0Z = +alpha_YZ); but a
// positive rotation of Z about Y tilts +Z towards +X and closes it: E_B0Z = -alpha_XZ. The
// angle between two directions does not depend on which one is named first, so alpha_XZ =
// alpha_ZX. Units: urad (1 urad = 1 um/m).
enum class Plane { xy, xz, yz };
std::string_view to_string(Plane p);            // "XY", "XZ", "YZ"
Plane plane_from_string(std::string_view);      // "XY" or "YX", ...; throws InputError
std::string_view location_error_name(Plane p);  // "E_C0Y", "E_B0Z", "E_A0Z"
double location_error_from_angle_over_90(Plane p, double alpha_urad);
double angle_over_90_from_location_error(Plane p, double location_error_urad);

// The three squareness (location) errors, constants in urad; see the sign convention above.
struct Squareness {
  double c0y_urad = 0.0;  // E_C0Y: Y to X
  double b0z_urad = 0.0;  // E_B0Z: Z to X
  double a0z_urad = 0.0;  // E_A0Z: Z to Y
  double& of(Plane p);    // the member for a plane: xy -> c0y, xz -> b0z, yz -> a0z
  double of(Plane p) const;
};

// The 24 serial orders, named by their letters. The first four keep the values they had when
// only they existed.
// clang-format off
enum class Topology {
  fxyz, xfyz, xyfz, xyzf,        // the classic four
  fxzy, fyxz, fyzx, fzxy, fzyx,  // F first: every axis carries the tool
  xfzy, yfxz, yfzx, zfxy, zfyx,  // F second: one table axis
  xzfy, yxfz, yzfx, zxfy, zyfx,  // F third: two table axes
  xzyf, yxzf, yzxf, zxyf, zyxf,  // F fourth: the tool is fixed to the frame
};
// clang-format on
inline constexpr std::size_t kTopologyCount = 24;
std::span<const Topology> all_topologies();
std::string_view to_string(Topology t);           // "FXYZ", ...
Topology topology_from_string(std::string_view);  // case-insensitive; throws InputError
// Number of axes on the workpiece side of the frame (0 for FXYZ ... 3 for XYZF).
int workpiece_side_axes(Topology t);

enum Axis : std::size_t { X = 0, Y = 1, Z = 2 };

// The axes in chain order from the workpiece to the tool (the topology letters without F):
// YFXZ gives {Y, X, Z}, of which the first workpiece_side_axes() carry the workpiece.
std::array<Axis, 3> chain_order(Topology t);

struct Machine {
  Topology topology = Topology::fxyz;
  std::array<AxisErrors, 3> axes;  // indexed by Axis: axes[X].ec_urad is E_CX
  Squareness squareness;
  // Tool tip relative to the tool reference point (spindle gauge point), in machine axes: a
  // tool of length L pointing down is {0, 0, -L}; lateral offsets are the x and y entries.
  Vec3 tool_offset_mm{};
  // The workpiece zero (the point under the tool reference point when all axes are at 0)
  // relative to the table reference point, in machine axes. Acts only on workpiece-side axes.
  Vec3 table_offset_mm{};
};

// The 18 component errors by their ISO 230-1 names, for configuration files and reports.
enum class Component {
  E_XX,
  E_YX,
  E_ZX,
  E_AX,
  E_BX,
  E_CX,
  E_XY,
  E_YY,
  E_ZY,
  E_AY,
  E_BY,
  E_CY,
  E_XZ,
  E_YZ,
  E_ZZ,
  E_AZ,
  E_BZ,
  E_CZ,
};
std::span<const Component> all_components();
std::string_view to_string(Component c);                 // "E_CX"
Component component_from_string(std::string_view name);  // "E_CX" or "ECX"; throws InputError
ErrorFunction& component(Machine& m, Component c);
const ErrorFunction& component(const Machine& m, Component c);

enum class Method {
  htm,          // exact product of 4x4 homogeneous transformations, exact rotation matrices
  first_order,  // small-angle expansion: a linear sum of the component errors
};

struct VolumetricError {
  Vec3 translation_um{};  // actual minus nominal tool tip, relative to the workpiece
  Vec3 rotation_urad{};   // orientation of the tool relative to the workpiece (rotation vector)
};

// The error at the commanded axis positions (mm). Throws InputError for a non-finite position
// or offset, or a position outside an error table (the message names the component).
VolumetricError volumetric_error(const Machine& m, const Vec3& position_mm, Method method);
Vec3 volumetric_error_um(const Machine& m, const Vec3& position_mm, Method method);

// A regular grid: count[i] points from min_mm[i] to max_mm[i] (count 1 uses min_mm).
struct Grid {
  Vec3 min_mm{};
  Vec3 max_mm{};
  std::array<std::size_t, 3> count{1, 1, 1};
};

// Flat arrays for plotting: point p has position positions_mm[3p .. 3p+2], error
// errors_um[3p .. 3p+2] and rotation rotations_urad[3p .. 3p+2]. X varies fastest:
// p = i + nx * (j + ny * k).
struct ErrorMap {
  std::array<std::size_t, 3> count{};
  std::vector<double> positions_mm;
  std::vector<double> errors_um;
  std::vector<double> rotations_urad;
  std::size_t size() const { return positions_mm.size() / 3; }
};

// Throws InputError for a count of 0, a non-finite or reversed range, or more than 1e8 points.
ErrorMap volumetric_error_map(const Machine& m, const Grid& grid, Method method);

struct MapSummary {
  double max_norm_um = 0.0;  // max over the points of |e|
  Vec3 max_norm_at_mm{};     // where
  Vec3 min_um{}, max_um{};   // per component
  Vec3 range_um{};           // max - min per component
};
MapSummary summarize(const ErrorMap& map);  // throws InputError for an empty map

// What each of the 21 errors contributes over a grid: the first-order error of a machine with
// only that error (same topology and offsets), its largest |e| and its RMS over the points.
// The first-order model is a sum, so the contributions add up to the whole. Sorted by
// max_norm_um, largest first. Throws as volumetric_error_map.
struct Contribution {
  std::string name;  // "E_CX", ..., "E_C0Y"
  Axis axis = X;     // the axis it belongs to (squareness: the carrier-free plane's second axis)
  double max_norm_um = 0.0;
  double rms_um = 0.0;
};
std::vector<Contribution> contributions(const Machine& m, const Grid& grid);

}  // namespace cal::kinematics
