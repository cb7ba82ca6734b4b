// Rotary axes on top of the 3-axis model: conventions in rotary.hpp, derivations and sources in
// docs/kinematics.md ("Rotary axes"; ISO 230-1:2012 and ISO 230-7:2015 terminology).
#include "cal/analysis/rotary.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>
#include <numbers>

#include "cal/analysis/enum_names.hpp"
#include "cal/analysis/error.hpp"
#include "cal/analysis/rotary_fit.hpp"

namespace cal::kinematics {
namespace {

using Eigen::Isometry3d;
using Eigen::Matrix3d;
using Eigen::Vector3d;

constexpr double kMmPerUm = 1e-3;
constexpr double kRadPerUrad = 1e-6;
constexpr double kRadPerDeg = std::numbers::pi / 180.0;
constexpr std::size_t kMaxRotaryAxes = 2;

Vector3d vec(const Vec3& v) { return {v[0], v[1], v[2]}; }
Vec3 arr(const Vector3d& v) { return {v.x(), v.y(), v.z()}; }

void check_finite(const Vec3& v, std::string_view what) {
  for (std::size_t k = 0; k < 3; ++k) {
    if (!std::isfinite(v[k])) {
      throw InputError(fmt::format("{}[{}] = {}: expected a finite number", what, k, v[k]));
    }
  }
}

// R(e) = Rz(e_c) Ry(e_b) Rx(e_a), as in the 3-axis model (kinematics.hpp).
Matrix3d rotation(const Vector3d& eps) {
  return (Eigen::AngleAxisd(eps.z(), Vector3d::UnitZ()) *
          Eigen::AngleAxisd(eps.y(), Vector3d::UnitY()) *
          Eigen::AngleAxisd(eps.x(), Vector3d::UnitX()))
      .toRotationMatrix();
}

Vector3d rotation_vector(const Matrix3d& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.angle() * aa.axis();
}

Isometry3d translation(const Vector3d& v) { return Isometry3d(Eigen::Translation3d(v)); }

Isometry3d pose(const Matrix3d& r, const Vector3d& t) {
  Isometry3d h = Isometry3d::Identity();
  h.linear() = r;
  h.translation() = t;
  return h;
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Names

std::string_view to_string(RotaryLetter l) {
  static constexpr std::array<std::string_view, 3> names{"A", "B", "C"};
  static_assert(one_per_value<RotaryLetter>(names));
  return names.at(static_cast<std::size_t>(l));
}

RotaryLetter rotary_letter_from_string(std::string_view s) {
  if (s.size() == 1) {
    switch (std::toupper(static_cast<unsigned char>(s[0]))) {
      case 'A':
        return RotaryLetter::a;
      case 'B':
        return RotaryLetter::b;
      case 'C':
        return RotaryLetter::c;
      default:
        break;
    }
  }
  throw InputError(fmt::format("rotary axis '{}' is unknown (expected A, B or C)", s));
}

std::size_t direction_index(RotaryLetter l) { return static_cast<std::size_t>(l); }

std::array<std::string, 4> location_error_names(RotaryLetter l) {
  static constexpr std::array<char, 3> linear{'X', 'Y', 'Z'}, angular{'A', 'B', 'C'};
  const std::size_t own = direction_index(l);
  std::array<std::string, 4> names;
  std::size_t n = 0;
  for (const auto& letters : {linear, angular}) {
    for (std::size_t i = 0; i < 3; ++i) {
      if (i != own) names.at(n++) = fmt::format("E_{}0{}", letters[i], to_string(l));
    }
  }
  return names;
}

std::string_view to_string(Side s) { return s == Side::table ? "table" : "spindle"; }

// ---------------------------------------------------------------------------------------------
// The chain

namespace {

// One factor of the kinematic chain, read from the workpiece to the tool. A nominal factor is
// a (possibly large) rigid motion; an error factor is nominally the identity, exactly
// `exact`, and to first order x -> x + eps x x + delta in its local coordinates.
struct Factor {
  Isometry3d exact = Isometry3d::Identity();
  bool is_error = false;
  Vector3d delta_mm = Vector3d::Zero();
  Vector3d eps_rad = Vector3d::Zero();
};

Factor nominal(const Isometry3d& h) { return {h, false, Vector3d::Zero(), Vector3d::Zero()}; }

// T(delta) R(eps): a translation after a rotation about the local origin.
Factor error(const Vector3d& delta_mm, const Vector3d& eps_rad) {
  return {pose(rotation(eps_rad), delta_mm), true, delta_mm, eps_rad};
}

// The inverse motion; to first order the twist changes sign.
Factor inverse(const Factor& f) { return {f.exact.inverse(), f.is_error, -f.delta_mm, -f.eps_rad}; }

std::string rotary_name(const RotaryAxis& r, std::size_t index) {
  return fmt::format("rotary[{}] ({} axis, {} side)", index, to_string(r.letter),
                     to_string(r.side));
}

double eval(const RotaryAxis& r, std::size_t index, std::size_t dir, double angle_deg) {
  static constexpr std::array<char, 6> directions{'X', 'Y', 'Z', 'A', 'B', 'C'};
  const auto& m = r.motion;
  const std::array f{&m.ex_um, &m.ey_um, &m.ez_um, &m.ea_urad, &m.eb_urad, &m.ec_urad};
  try {
    return (*f.at(dir))(angle_deg);
  } catch (const InputError& e) {
    // The table's message says mm: for a rotary axis the argument is the angle in degrees.
    throw InputError(fmt::format("E_{}{} of {} at {} deg: {}", directions.at(dir),
                                 to_string(r.letter), rotary_name(r, index), angle_deg, e.what()));
  }
}

// The joint of a rotary axis: the pose of its moving member in its carrier,
//   J(angle) = T(c) L [T(delta) R(eps)] R_d(angle) L^-1 T(-c),   L = T(position) R(orientation),
// c the nominal pivot, d the nominal direction: a rotation about the actual axis average line
// (through c + position, direction R(orientation) d) with the error motion of the member at the
// actual pivot, in the carrier's axes. At angle 0 with no component errors J is the identity.
std::vector<Factor> joint(const RotaryAxis& r, std::size_t index, double angle_deg) {
  const Vector3d c = vec(r.pivot_mm);
  Vector3d d = Vector3d::Zero();
  d[static_cast<Eigen::Index>(direction_index(r.letter))] = 1.0;
  const Factor location =
      error(kMmPerUm * vec(r.location_position_um), kRadPerUrad * vec(r.location_orientation_urad));
  const Vector3d delta =
      kMmPerUm * Vector3d(eval(r, index, 0, angle_deg), eval(r, index, 1, angle_deg),
                          eval(r, index, 2, angle_deg));
  const Vector3d eps =
      kRadPerUrad * Vector3d(eval(r, index, 3, angle_deg), eval(r, index, 4, angle_deg),
                             eval(r, index, 5, angle_deg));
  Isometry3d turn = Isometry3d::Identity();
  turn.linear() = Eigen::AngleAxisd(angle_deg * kRadPerDeg, d).toRotationMatrix();
  std::vector<Factor> f{nominal(translation(c)), location,          error(delta, eps),
                        nominal(turn),           inverse(location), nominal(translation(-c))};
  if (r.side == Side::table) {
    // Read from the workpiece, a table axis is crossed from its member to its carrier: J^-1.
    std::reverse(f.begin(), f.end());
    for (Factor& x : f) x = inverse(x);
  }
  return f;
}

void check_machine(const FiveAxisMachine& m, std::span<const double> angles_deg) {
  if (m.rotary.size() > kMaxRotaryAxes) {
    throw InputError(
        fmt::format("{} rotary axes: at most {} are modelled", m.rotary.size(), kMaxRotaryAxes));
  }
  if (angles_deg.size() != m.rotary.size()) {
    throw InputError(
        fmt::format("{} angle(s) given for {} rotary axis/axes (expected one each, "
                    "in the order of the chain)",
                    angles_deg.size(), m.rotary.size()));
  }
  for (std::size_t i = 0; i < m.rotary.size(); ++i) {
    const RotaryAxis& r = m.rotary[i];
    const std::string name = rotary_name(r, i);
    (void)to_string(r.letter);  // throws std::out_of_range for a value outside the enum
    if (i > 0 && r.side == Side::table && m.rotary[i - 1].side == Side::spindle) {
      throw InputError(
          fmt::format("{} follows a spindle axis: list the rotary axes from the "
                      "workpiece to the tool, table axes first",
                      name));
    }
    check_finite(r.pivot_mm, name + " pivot_mm");
    check_finite(r.location_position_um, name + " location_position_um");
    check_finite(r.location_orientation_urad, name + " location_orientation_urad");
    const std::size_t own = direction_index(r.letter);
    if (r.location_position_um[own] != 0.0 || r.location_orientation_urad[own] != 0.0) {
      throw InputError(fmt::format(
          "{}: location error along / about its own direction ({} um, {} urad): a position along "
          "the axis average line is not a location error, and a zero offset of the angle belongs "
          "in E_{}{} (expected 0)",
          name, r.location_position_um[own], r.location_orientation_urad[own], "ABC"[own],
          to_string(r.letter)));
    }
    if (!std::isfinite(angles_deg[i])) {
      throw InputError(
          fmt::format("angle of {} = {}: expected a finite number", name, angles_deg[i]));
    }
  }
}

// The chain for one method: linear errors by that method (the 3-axis model, tool offset 0, so
// that it gives the pose of the tool reference point), rotary joints exact (their first-order
// expansion is taken by first_order_error from the factors).
std::vector<Factor> chain(const FiveAxisMachine& m, const Vec3& p_mm,
                          std::span<const double> angles_deg, Method method) {
  std::vector<Factor> f;
  std::size_t i = 0;
  for (; i < m.rotary.size() && m.rotary[i].side == Side::table; ++i) {
    const auto j = joint(m.rotary[i], i, angles_deg[i]);
    f.insert(f.end(), j.begin(), j.end());
  }
  // The 3-axis model gives the pose H of the tool frame in the table reference frame: its
  // linear part the rotation, its origin p + table_offset + e. Read from the home-origin table
  // frame it is T(p) [R, e].
  Machine lin = m.linear;
  lin.tool_offset_mm = {};
  const VolumetricError v = volumetric_error(lin, p_mm, method);
  const Vector3d e_mm = kMmPerUm * vec(v.translation_um);
  const Vector3d rot_rad = kRadPerUrad * vec(v.rotation_urad);
  f.push_back(nominal(translation(vec(p_mm))));
  Factor lin_error = error(e_mm, rot_rad);
  if (method == Method::htm) {
    const double angle = rot_rad.norm();
    const Matrix3d r = angle > 0.0 ? Eigen::AngleAxisd(angle, rot_rad / angle).toRotationMatrix()
                                   : Matrix3d::Identity();
    lin_error.exact = pose(r, e_mm);
  }
  f.push_back(lin_error);
  for (; i < m.rotary.size(); ++i) {
    const auto j = joint(m.rotary[i], i, angles_deg[i]);
    f.insert(f.end(), j.begin(), j.end());
  }
  return f;
}

Isometry3d nominal_pose(const std::vector<Factor>& f) {
  Isometry3d h = Isometry3d::Identity();
  for (const Factor& x : f) {
    if (!x.is_error) h = h * x.exact;
  }
  return h;
}

VolumetricError exact_error(const std::vector<Factor>& f, const Vector3d& tool) {
  Isometry3d h = Isometry3d::Identity();
  for (const Factor& x : f) h = h * x.exact;
  const Isometry3d n = nominal_pose(f);
  const Vector3d e = h * tool - n * tool;
  const Vector3d rot = rotation_vector(h.linear() * n.linear().transpose());
  VolumetricError r;
  r.translation_um = arr(e / kMmPerUm);
  r.rotation_urad = arr(rot / kRadPerUrad);
  return r;
}

// First order in the errors, exact in the nominal motions: with A_j the nominal pose of the
// chain up to error factor j and s_j the nominal tool tip in that factor's frame,
//   e = sum_j R(A_j) (delta_j + eps_j x s_j),   rotation = sum_j R(A_j) eps_j.
VolumetricError first_order_error(const std::vector<Factor>& f, const Vector3d& tool) {
  std::vector<Vector3d> tip_in(f.size());
  Vector3d s = tool;
  for (std::size_t k = f.size(); k-- > 0;) {
    tip_in[k] = s;
    if (!f[k].is_error) s = f[k].exact * s;
  }
  Matrix3d a = Matrix3d::Identity();
  Vector3d e = Vector3d::Zero(), rot = Vector3d::Zero();
  for (std::size_t k = 0; k < f.size(); ++k) {
    if (f[k].is_error) {
      e += a * (f[k].delta_mm + f[k].eps_rad.cross(tip_in[k]));
      rot += a * f[k].eps_rad;
    } else {
      a = a * f[k].exact.linear();
    }
  }
  VolumetricError r;
  r.translation_um = arr(e / kMmPerUm);
  r.rotation_urad = arr(rot / kRadPerUrad);
  return r;
}

}  // namespace

VolumetricError five_axis_error(const FiveAxisMachine& machine, const Vec3& linear_mm,
                                std::span<const double> angles_deg, Method method) {
  check_machine(machine, angles_deg);
  check_finite(linear_mm, "linear_mm");
  const auto f = chain(machine, linear_mm, angles_deg, method);
  const Vector3d tool = vec(machine.linear.tool_offset_mm);
  return method == Method::htm ? exact_error(f, tool) : first_order_error(f, tool);
}

Vec3 five_axis_nominal_tip_mm(const FiveAxisMachine& machine, const Vec3& linear_mm,
                              std::span<const double> angles_deg) {
  check_machine(machine, angles_deg);
  check_finite(linear_mm, "linear_mm");
  const auto f = chain(machine, linear_mm, angles_deg, Method::first_order);
  return arr(nominal_pose(f) * vec(machine.linear.tool_offset_mm));
}

FiveAxisMachine control_kinematics(const FiveAxisMachine& m) {
  FiveAxisMachine k;
  k.linear.topology = m.linear.topology;
  k.linear.tool_offset_mm = m.linear.tool_offset_mm;
  k.linear.table_offset_mm = m.linear.table_offset_mm;
  for (const RotaryAxis& r : m.rotary) {
    RotaryAxis a;
    a.letter = r.letter;
    a.side = r.side;
    a.pivot_mm = r.pivot_mm;
    a.location_position_um = r.location_position_um;
    a.location_orientation_urad = r.location_orientation_urad;
    k.rotary.push_back(a);
  }
  return k;
}

FiveAxisMachine nominal_kinematics(const FiveAxisMachine& m) {
  FiveAxisMachine k = control_kinematics(m);
  for (RotaryAxis& r : k.rotary) {
    r.location_position_um = {};
    r.location_orientation_urad = {};
  }
  return k;
}

Vec3 control_tip_mm(const FiveAxisMachine& control, const Vec3& linear_mm,
                    std::span<const double> angles_deg) {
  check_machine(control, angles_deg);
  const FiveAxisMachine k = control_kinematics(control);
  std::vector<double> angles(angles_deg.begin(), angles_deg.end());
  for (std::size_t i = 0; i < k.rotary.size(); ++i) {
    if (k.rotary[i].side == Side::table) angles[i] = 0.0;
  }
  const Vec3 tip = five_axis_nominal_tip_mm(k, linear_mm, angles);
  const Vec3 e_um = five_axis_error(k, linear_mm, angles, Method::htm).translation_um;
  return {tip[0] + kMmPerUm * e_um[0], tip[1] + kMmPerUm * e_um[1], tip[2] + kMmPerUm * e_um[2]};
}

Vec3 probed_centre_mm(const FiveAxisMachine& machine, const FiveAxisMachine& control,
                      const Vec3& sphere_mm, std::span<const double> angles_deg) {
  check_machine(machine, angles_deg);
  check_machine(control, angles_deg);
  check_finite(sphere_mm, "sphere_mm");
  bool same = machine.rotary.size() == control.rotary.size();
  for (std::size_t i = 0; same && i < machine.rotary.size(); ++i) {
    same = machine.rotary[i].letter == control.rotary[i].letter &&
           machine.rotary[i].side == control.rotary[i].side;
  }
  if (!same) {
    throw InputError(
        "the machine and the control's kinematics have different rotary axes (letters, sides "
        "or order): a control reports for its own chain");
  }
  // The nominal tip is b + A p: A from unit steps (exact: it is affine).
  const auto tip = [&](const Vector3d& p) {
    return vec(five_axis_nominal_tip_mm(machine, arr(p), angles_deg));
  };
  const Vector3d b = tip(Vector3d::Zero());
  Matrix3d a;
  for (Eigen::Index i = 0; i < 3; ++i) a.col(i) = tip(Vector3d::Unit(i)) - b;
  const auto solve = a.partialPivLu();
  const Vector3d s = vec(sphere_mm);
  Vector3d p = solve.solve(s - b);
  for (int it = 0; it < 8; ++it) {
    const Vector3d actual =
        tip(p) +
        kMmPerUm * vec(five_axis_error(machine, arr(p), angles_deg, Method::htm).translation_um);
    const Vector3d miss = actual - s;
    p -= solve.solve(miss);
    if (miss.norm() < 1e-12) break;
  }
  return control_tip_mm(control, arr(p), angles_deg);
}

Vec3 probed_centre_mm(const FiveAxisMachine& machine, const Vec3& sphere_mm,
                      std::span<const double> angles_deg) {
  return probed_centre_mm(machine, nominal_kinematics(machine), sphere_mm, angles_deg);
}

LinearCorrection remove_linear_errors(const Machine& linear,
                                      std::span<const ProbedCentre> centres) {
  LinearCorrection out;
  out.centres.reserve(centres.size());
  out.correction_um.reserve(centres.size());
  for (const auto& c : centres) {
    check_finite(c.centre_mm, "centre_mm");
    Vec3 position{};
    for (std::size_t i = 0; i < 3; ++i) position[i] = c.centre_mm[i] - linear.tool_offset_mm[i];
    const Vec3 e = volumetric_error(linear, position, Method::htm).translation_um;
    ProbedCentre moved = c;
    for (std::size_t i = 0; i < 3; ++i) moved.centre_mm[i] += kMmPerUm * e[i];
    out.centres.push_back(moved);
    out.correction_um.push_back(e);
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Sphere probing: the axis average line

namespace {

// A sphere centre further than this from the others' line is "not collinear" (relative to the
// spread of the centres); a plane normal further than this from the nominal direction is not
// that axis's circle (location errors are well below 1 mrad on any machine worth probing).
constexpr double kCollinearRatio = 1e-6;
constexpr double kCoincidentMm = 1e-6;
constexpr double kMaxTiltRad = 0.01;
constexpr double kAngleSameDeg = 1e-6;

// The 6 parameters, in mm and rad: the two position errors and the two orientation errors (in
// the two directions other than the axis's own, increasing index), the height h of the circle's
// plane along the actual direction from the actual pivot, the radius.
using Params = Eigen::Matrix<double, 6, 1>;

struct Geometry {
  std::size_t own;
  std::array<std::size_t, 2> other;
  Vector3d pivot;
  Vector3d d;
};

Vector3d position_of(const Geometry& g, const Params& q) {
  Vector3d p = Vector3d::Zero();
  p[static_cast<Eigen::Index>(g.other[0])] = q[0];
  p[static_cast<Eigen::Index>(g.other[1])] = q[1];
  return p;
}

Vector3d orientation_of(const Geometry& g, const Params& q) {
  Vector3d o = Vector3d::Zero();
  o[static_cast<Eigen::Index>(g.other[0])] = q[2];
  o[static_cast<Eigen::Index>(g.other[1])] = q[3];
  return o;
}

// The direction of the line exactly as the model builds it: R(orientation) d.
Vector3d direction_of(const Geometry& g, const Params& q) {
  return rotation(orientation_of(g, q)) * g.d;
}

// Radial and axial residuals (mm) of every centre: 2 N values, radial first.
Eigen::VectorXd residuals(const Geometry& g, const std::vector<Vector3d>& pts, const Params& q) {
  const Vector3d origin = g.pivot + position_of(g, q);
  const Vector3d n = direction_of(g, q);
  Eigen::VectorXd r(2 * static_cast<Eigen::Index>(pts.size()));
  for (std::size_t k = 0; k < pts.size(); ++k) {
    const Vector3d w = pts[k] - origin;
    const double along = w.dot(n);
    const auto i = static_cast<Eigen::Index>(k);
    r[i] = (w - along * n).norm() - q[5];
    r[static_cast<Eigen::Index>(pts.size()) + i] = along - q[4];
  }
  return r;
}

// Central differences: the residuals are smooth and the problem has 6 parameters; steps of 1e-6
// (mm or rad) leave a truncation error far below the rounding of probed centres.
Eigen::MatrixXd jacobian(const Geometry& g, const std::vector<Vector3d>& pts, const Params& q) {
  constexpr double step = 1e-6;
  Eigen::MatrixXd j(2 * static_cast<Eigen::Index>(pts.size()), 6);
  for (Eigen::Index c = 0; c < 6; ++c) {
    Params hi = q, lo = q;
    hi[c] += step;
    lo[c] -= step;
    j.col(c) = (residuals(g, pts, hi) - residuals(g, pts, lo)) / (2.0 * step);
  }
  return j;
}

void check_centres(std::span<const ProbedCentre> centres) {
  for (std::size_t k = 0; k < centres.size(); ++k) {
    if (!std::isfinite(centres[k].angle_deg)) {
      throw InputError(fmt::format("probed centre {}: angle_deg = {}: expected a finite number", k,
                                   centres[k].angle_deg));
    }
    check_finite(centres[k].centre_mm,
                 fmt::format("probed centre {} (angle {} deg) centre_mm", k, centres[k].angle_deg));
  }
  std::vector<double> angles;
  for (const auto& c : centres) {
    const double a = std::fmod(std::fmod(c.angle_deg, 360.0) + 360.0, 360.0);
    const bool seen = std::any_of(angles.begin(), angles.end(), [&](double b) {
      const double diff = std::abs(a - b);
      return std::min(diff, 360.0 - diff) < kAngleSameDeg;
    });
    if (!seen) angles.push_back(a);
  }
  if (angles.size() < 3) {
    throw InputError(
        fmt::format("{} probed centre(s) at {} distinct angle(s): the axis average "
                    "line needs centres at 3 or more distinct angles of the axis",
                    centres.size(), angles.size()));
  }
}

// The algebraic start: the plane of the centres (least squares), the circle in it (Kasa), the
// line through the circle's centre along the plane's normal.
Params initial_guess(const Geometry& g, const std::vector<Vector3d>& pts) {
  const auto n_pts = static_cast<Eigen::Index>(pts.size());
  Vector3d mean = Vector3d::Zero();
  for (const auto& p : pts) mean += p;
  mean /= static_cast<double>(pts.size());
  Eigen::MatrixXd centred(n_pts, 3);
  for (Eigen::Index k = 0; k < n_pts; ++k) {
    centred.row(k) = (pts[static_cast<std::size_t>(k)] - mean).transpose();
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(centred, Eigen::ComputeFullV);
  const Vector3d s = svd.singularValues();
  if (s[0] < kCoincidentMm) {
    throw InputError(
        fmt::format("the probed centres coincide (spread {} mm): the sphere must "
                    "stand off the axis so that its centre describes a circle",
                    s[0]));
  }
  if (s[1] < kCollinearRatio * s[0]) {
    throw InputError(
        fmt::format("the probed centres are collinear (spread across the line {} mm "
                    "for {} mm along it): they describe no circle",
                    s[1], s[0]));
  }
  Vector3d n = svd.matrixV().col(2);
  if (n.dot(g.d) < 0) n = -n;
  const double tilt = std::acos(std::clamp(n.dot(g.d), -1.0, 1.0));
  if (tilt > kMaxTiltRad) {
    throw InputError(fmt::format(
        "the probed centres lie in a plane tilted {:.4f} rad from the plane perpendicular to the "
        "nominal direction of the {} axis (expected less than {} rad): the wrong axis, or a centre "
        "not from this axis's probing",
        tilt, "ABC"[g.own], kMaxTiltRad));
  }
  // In-plane basis and the Kasa fit u^2 + v^2 = 2 a u + 2 b v + c.
  const Vector3d e1 = n.unitOrthogonal(), e2 = n.cross(e1);
  Eigen::MatrixXd a(n_pts, 3);
  Eigen::VectorXd rhs(n_pts);
  for (Eigen::Index k = 0; k < n_pts; ++k) {
    const Vector3d w = pts[static_cast<std::size_t>(k)] - mean;
    const double u = w.dot(e1), v = w.dot(e2);
    a.row(k) << 2 * u, 2 * v, 1.0;
    rhs[k] = u * u + v * v;
  }
  const Vector3d abc = a.colPivHouseholderQr().solve(rhs);
  const Vector3d centre = mean + abc[0] * e1 + abc[1] * e2;
  const double radius = std::sqrt(abc[2] + abc[0] * abc[0] + abc[1] * abc[1]);
  // The line through the centre along n, where it crosses the plane through the pivot
  // perpendicular to d.
  const Vector3d at_pivot = centre + n * ((g.pivot - centre).dot(g.d) / n.dot(g.d));
  const Vector3d pos = at_pivot - g.pivot;
  const Vector3d tilt_vec = g.d.cross(n);  // small rotation taking d to n
  Params q;
  q << pos[static_cast<Eigen::Index>(g.other[0])], pos[static_cast<Eigen::Index>(g.other[1])],
      tilt_vec[static_cast<Eigen::Index>(g.other[0])],
      tilt_vec[static_cast<Eigen::Index>(g.other[1])], (centre - at_pivot).dot(n), radius;
  return q;
}

// Gauss-Newton from the algebraic start (a few iterations: the start is already within the
// noise of the solution).
Params refine(const Geometry& g, const std::vector<Vector3d>& pts, Params q) {
  for (int it = 0; it < 50; ++it) {
    const Eigen::MatrixXd j = jacobian(g, pts, q);
    const Eigen::VectorXd r = residuals(g, pts, q);
    const Params step = j.colPivHouseholderQr().solve(-r);
    q += step;
    if (step.norm() < 1e-13) break;
  }
  return q;
}

double wrap_rad(double a) { return std::remainder(a, 2.0 * std::numbers::pi); }

}  // namespace

AxisLineFit fit_axis_line(RotaryLetter letter, const Vec3& nominal_pivot_mm,
                          std::span<const ProbedCentre> centres, double probe_u_um) {
  (void)to_string(letter);
  check_finite(nominal_pivot_mm, "nominal_pivot_mm");
  if (!(std::isfinite(probe_u_um) && probe_u_um >= 0.0)) {
    throw InputError(
        fmt::format("probe_u_um = {}: expected a finite value >= 0 (0: estimate the "
                    "uncertainty from the residuals)",
                    probe_u_um));
  }
  check_centres(centres);
  Geometry g{direction_index(letter), {}, vec(nominal_pivot_mm), Vector3d::Zero()};
  g.d[static_cast<Eigen::Index>(g.own)] = 1.0;
  g.other = g.own == 0   ? std::array<std::size_t, 2>{1, 2}
            : g.own == 1 ? std::array<std::size_t, 2>{0, 2}
                         : std::array<std::size_t, 2>{0, 1};
  std::vector<Vector3d> pts;
  pts.reserve(centres.size());
  for (const auto& c : centres) pts.push_back(vec(c.centre_mm));

  const Params q = refine(g, pts, initial_guess(g, pts));
  const Eigen::VectorXd r = residuals(g, pts, q);
  const Eigen::MatrixXd j = jacobian(g, pts, q);

  AxisLineFit fit;
  fit.letter = letter;
  fit.radius_mm = q[5];
  fit.plane_offset_mm = q[4];
  fit.dof = 2 * static_cast<int>(pts.size()) - 6;
  const double ss = r.squaredNorm();
  fit.rms_um = std::sqrt(ss / static_cast<double>(r.size())) / kMmPerUm;
  const double sigma_mm = fit_sigma_mm(ss, fit.dof, probe_u_um);
  fit.sigma_um = sigma_mm / kMmPerUm;
  const Eigen::Matrix<double, 6, 6> cov = sigma_mm * sigma_mm * (j.transpose() * j).inverse();
  for (std::size_t k = 0; k < 2; ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    fit.position_um[g.other[k]] = q[i] / kMmPerUm;
    fit.position_u_um[g.other[k]] = std::sqrt(cov(i, i)) / kMmPerUm;
    fit.orientation_urad[g.other[k]] = q[2 + i] / kRadPerUrad;
    fit.orientation_u_urad[g.other[k]] = std::sqrt(cov(2 + i, 2 + i)) / kRadPerUrad;
  }

  // Residuals per centre; the tangential one from the angle about the fitted line, less the
  // commanded angle, less their mean (the zero of the angle is not part of the line).
  const auto n_pts = static_cast<Eigen::Index>(pts.size());
  const Vector3d origin = g.pivot + position_of(g, q), n = direction_of(g, q);
  const Vector3d e1 = n.unitOrthogonal(), e2 = n.cross(e1);
  std::vector<double> dphi;
  double sum_sin = 0.0, sum_cos = 0.0;
  for (std::size_t k = 0; k < pts.size(); ++k) {
    const Vector3d w = pts[k] - origin;
    const double phi = std::atan2(w.dot(e2), w.dot(e1));
    dphi.push_back(wrap_rad(phi - centres[k].angle_deg * kRadPerDeg));
    sum_sin += std::sin(dphi.back());
    sum_cos += std::cos(dphi.back());
    const auto i = static_cast<Eigen::Index>(k);
    fit.radial_um.push_back(r[i] / kMmPerUm);
    fit.axial_um.push_back(r[n_pts + i] / kMmPerUm);
  }
  const double mean_phi = std::atan2(sum_sin, sum_cos);
  for (double d : dphi) fit.tangential_um.push_back(q[5] * wrap_rad(d - mean_phi) / kMmPerUm);
  return fit;
}

// ---------------------------------------------------------------------------------------------
// Sphere probing of a head axis

namespace {

// Head centres are the control's computed tip: within the location errors of one another. A
// spread beyond this is not such a file (the linear axes' raw positions describe a circle of
// the tool's arm, hundreds of mm).
constexpr double kMaxHeadSpreadMm = 2.0;

}  // namespace

HeadAxisFit fit_head_axis_line(const FiveAxisMachine& control, std::size_t index,
                               std::span<const ProbedCentre> centres, double probe_u_um,
                               bool with_linear_errors) {
  check_machine(control, std::vector<double>(control.rotary.size(), 0.0));
  if (index >= control.rotary.size() || control.rotary[index].side != Side::spindle) {
    throw InputError(fmt::format(
        "rotary axis {} of {}: the head fit needs a spindle-side axis (a table axis is fitted "
        "by fit_axis_line)",
        index, control.rotary.size()));
  }
  check_centres(centres);  // probe_u_um: checked by fit_location_errors
  const RotaryAxis& axis = control.rotary[index];
  std::vector<Vector3d> pts;
  Vector3d mean = Vector3d::Zero();
  for (const auto& c : centres) {
    pts.push_back(vec(c.centre_mm));
    mean += pts.back();
  }
  mean /= static_cast<double>(pts.size());
  double spread = 0.0;
  for (const auto& p : pts) spread = std::max(spread, (p - mean).norm());
  if (spread > kMaxHeadSpreadMm) {
    throw InputError(fmt::format(
        "the centres of the {} head axis lie up to {:.3f} mm from their mean (expected within "
        "{} mm): a control reports the probed centre where its kinematics puts the turned probe "
        "tip, so they lie within the head's location errors of one another; were these the "
        "linear axes' raw positions?",
        to_string(axis.letter), spread, kMaxHeadSpreadMm));
  }

  std::vector<ProbedPose> poses;
  for (const auto& c : centres) {
    poses.push_back({std::vector<double>(control.rotary.size(), 0.0), c.centre_mm});
    poses.back().angles_deg[index] = c.angle_deg;
  }
  const std::array<std::size_t, 1> axes{index};
  const LocationFit lf = fit_location_errors(control, axes, poses, probe_u_um, with_linear_errors);

  HeadAxisFit out;
  AxisLineFit& fit = out.line;
  fit.letter = axis.letter;
  fit.position_um = lf.position_um[0];
  fit.position_u_um = lf.position_u_um[0];
  fit.orientation_urad = lf.orientation_urad[0];
  fit.orientation_u_urad = lf.orientation_u_urad[0];
  fit.rms_um = lf.rms_um;
  fit.sigma_um = lf.sigma_um;
  fit.dof = lf.dof;
  out.sphere_mm = lf.sphere_mm;
  out.sphere_u_um = lf.sphere_u_um;

  // The probe tip relative to the fitted line, in the head's carrier (the machine's axes to
  // first order): w = tool - actual pivot, turned about the fitted direction n.
  Vector3d d = Vector3d::Zero();
  d[static_cast<Eigen::Index>(direction_index(axis.letter))] = 1.0;
  const Vector3d n = rotation(kRadPerUrad * vec(fit.orientation_urad)) * d;
  const Vector3d w =
      vec(control.linear.tool_offset_mm) - vec(axis.pivot_mm) - kMmPerUm * vec(fit.position_um);
  fit.plane_offset_mm = w.dot(n);
  fit.radius_mm = (w - w.dot(n) * n).norm();
  for (std::size_t k = 0; k < pts.size(); ++k) {
    const Vector3d wk = Eigen::AngleAxisd(centres[k].angle_deg * kRadPerDeg, n) * w;
    Vector3d radial = wk - wk.dot(n) * n;
    radial = radial.norm() > 1e-9 ? Vector3d(radial.normalized()) : n.unitOrthogonal();
    const Vector3d motion = -vec(lf.residual_um[k]);
    fit.radial_um.push_back(motion.dot(radial));
    fit.axial_um.push_back(motion.dot(n));
    fit.tangential_um.push_back(motion.dot(n.cross(radial)));
  }
  return out;
}

}  // namespace cal::kinematics
