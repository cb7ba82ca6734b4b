// Rigid-body model of a 3-axis machine: conventions in kinematics.hpp, derivations and
// sources in docs/kinematics.md (ISO 230-1:2012; Schwenke et al., CIRP Annals 57/2 (2008)
// 660-675, section 2; Ramesh, Mannan & Poo, IJMTM 40 (2000) 1235-1256).
#include "cal/analysis/kinematics.hpp"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <cmath>
#include <limits>

#include "cal/analysis/enum_names.hpp"
#include "cal/analysis/error.hpp"

namespace cal::kinematics {
namespace {

constexpr double kMmPerUm = 1e-3;
constexpr double kRadPerUrad = 1e-6;
// A table end reached within this much (rounding of a grid or of a CSV) is not an
// extrapolation.
constexpr double kTableEndSlackMm = 1e-9;
constexpr std::size_t kMaxMapPoints = 100'000'000;

void check_finite(std::span<const double> v, std::string_view what) {
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (!std::isfinite(v[k])) {
      throw InputError(fmt::format("{}[{}] = {}: expected a finite number", what, k, v[k]));
    }
  }
}

void check_finite(const Vec3& v, std::string_view what) {
  check_finite(std::span<const double>(v), what);
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// ErrorFunction

ErrorFunction ErrorFunction::polynomial(std::span<const double> coefficients) {
  if (coefficients.empty()) {
    throw InputError("polynomial error function: no coefficients (expected at least c0)");
  }
  check_finite(coefficients, "polynomial coefficient");
  ErrorFunction f;
  f.coefficients_.assign(coefficients.begin(), coefficients.end());
  return f;
}

ErrorFunction ErrorFunction::polynomial(std::initializer_list<double> coefficients) {
  return polynomial(std::span<const double>(coefficients.begin(), coefficients.size()));
}

ErrorFunction ErrorFunction::table(std::span<const double> positions_mm,
                                   std::span<const double> values) {
  if (positions_mm.size() != values.size()) {
    throw InputError(fmt::format("error table: {} positions but {} values (expected equal)",
                                 positions_mm.size(), values.size()));
  }
  if (positions_mm.size() < 2) {
    throw InputError(
        fmt::format("error table: {} point(s), expected at least 2", positions_mm.size()));
  }
  check_finite(positions_mm, "error table position_mm");
  check_finite(values, "error table value");
  for (std::size_t k = 1; k < positions_mm.size(); ++k) {
    if (!(positions_mm[k] > positions_mm[k - 1])) {
      throw InputError(
          fmt::format("error table: position_mm[{}] = {} is not greater than position_mm[{}] = {} "
                      "(expected strictly increasing positions)",
                      k, positions_mm[k], k - 1, positions_mm[k - 1]));
    }
  }
  ErrorFunction f;
  f.kind_ = Kind::table;
  f.positions_mm_.assign(positions_mm.begin(), positions_mm.end());
  f.values_.assign(values.begin(), values.end());
  return f;
}

double ErrorFunction::operator()(double q_mm) const {
  if (kind_ == Kind::polynomial) {
    double v = 0.0;  // Horner
    for (auto c = coefficients_.rbegin(); c != coefficients_.rend(); ++c) v = v * q_mm + *c;
    return v;
  }
  const double first = positions_mm_.front(), last = positions_mm_.back();
  if (!(q_mm >= first - kTableEndSlackMm && q_mm <= last + kTableEndSlackMm)) {
    throw InputError(fmt::format(
        "position {} mm is outside the error table [{}, {}] mm (tables are not extrapolated)", q_mm,
        first, last));
  }
  const double q = std::clamp(q_mm, first, last);
  // First table position > q, kept in [1, n-1] so that [k-1, k] is a valid interval.
  auto it = std::upper_bound(positions_mm_.begin(), positions_mm_.end(), q);
  const auto k = std::clamp<std::ptrdiff_t>(it - positions_mm_.begin(), 1,
                                            static_cast<std::ptrdiff_t>(positions_mm_.size()) - 1);
  const auto i = static_cast<std::size_t>(k);
  const double t = (q - positions_mm_[i - 1]) / (positions_mm_[i] - positions_mm_[i - 1]);
  return values_[i - 1] + t * (values_[i] - values_[i - 1]);
}

ErrorFunction ErrorFunction::scaled(double k) const {
  ErrorFunction f = *this;
  for (double& c : f.coefficients_) c *= k;
  for (double& v : f.values_) v *= k;
  return f;
}

// ---------------------------------------------------------------------------------------------
// Names

namespace {

// The 24 serial orders of X, Y, Z and the frame F, in the order of the Topology enum (the four
// classic ones first, so that their numeric values are those of earlier versions).
constexpr std::array<std::string_view, kTopologyCount> kTopologyNames{
    "FXYZ", "XFYZ", "XYFZ", "XYZF",          // the first four
    "FXZY", "FYXZ", "FYZX", "FZXY", "FZYX",  // F first
    "XFZY", "YFXZ", "YFZX", "ZFXY", "ZFYX",  // F second
    "XZFY", "YXFZ", "YZFX", "ZXFY", "ZYFX",  // F third
    "XZYF", "YXZF", "YZXF", "ZXYF", "ZYXF",  // F fourth
};

constexpr std::array kComponents{
    Component::E_XX, Component::E_YX, Component::E_ZX, Component::E_AX, Component::E_BX,
    Component::E_CX, Component::E_XY, Component::E_YY, Component::E_ZY, Component::E_AY,
    Component::E_BY, Component::E_CY, Component::E_XZ, Component::E_YZ, Component::E_ZZ,
    Component::E_AZ, Component::E_BZ, Component::E_CZ,
};
constexpr std::array<std::string_view, 18> kComponentNames{
    "E_XX", "E_YX", "E_ZX", "E_AX", "E_BX", "E_CX", "E_XY", "E_YY", "E_ZY",
    "E_AY", "E_BY", "E_CY", "E_XZ", "E_YZ", "E_ZZ", "E_AZ", "E_BZ", "E_CZ",
};
// One entry per value of each enum (a new value that is not added here does not compile).
static_assert(one_per_value<Topology>(kTopologyNames));
static_assert(one_per_value<Component>(kComponentNames));
static_assert(kComponents.size() == enumerator_count<Component>());

std::string upper(std::string_view s) {
  std::string u(s);
  for (char& c : u) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return u;
}

}  // namespace

std::string_view to_string(Topology t) { return kTopologyNames.at(static_cast<std::size_t>(t)); }

std::span<const Topology> all_topologies() {
  static const auto all = [] {
    std::array<Topology, kTopologyCount> a{};
    for (std::size_t i = 0; i < a.size(); ++i) a[i] = static_cast<Topology>(i);
    return a;
  }();
  return all;
}

int workpiece_side_axes(Topology t) { return static_cast<int>(to_string(t).find('F')); }

std::array<Axis, 3> chain_order(Topology t) {
  std::array<Axis, 3> order{};
  std::size_t n = 0;
  for (char c : to_string(t)) {
    if (c != 'F') order.at(n++) = static_cast<Axis>(c - 'X');
  }
  return order;
}

Topology topology_from_string(std::string_view s) {
  const std::string u = upper(s);
  for (std::size_t i = 0; i < kTopologyNames.size(); ++i) {
    if (u == kTopologyNames[i]) return static_cast<Topology>(i);
  }
  throw InputError(fmt::format(
      "topology '{}' is unknown (expected the letters F, X, Y and Z once each, read from the "
      "workpiece to the tool: e.g. FXYZ, XFYZ, XYFZ, YFXZ, ZFXY)",
      s));
}

namespace {
constexpr std::array<std::string_view, 3> kPlaneNames{"XY", "XZ", "YZ"};
constexpr std::array<std::string_view, 3> kLocationNames{"E_C0Y", "E_B0Z", "E_A0Z"};
// The sign that takes alpha (angle over 90 deg) to the ISO 230-1 location error: see
// kinematics.hpp. Only the rotation about Y closes the angle when positive.
constexpr std::array<double, 3> kAlphaToLocation{+1.0, -1.0, +1.0};
static_assert(one_per_value<Plane>(kPlaneNames) && one_per_value<Plane>(kLocationNames) &&
              one_per_value<Plane>(kAlphaToLocation));
}  // namespace

std::string_view to_string(Plane p) { return kPlaneNames.at(static_cast<std::size_t>(p)); }

Plane plane_from_string(std::string_view s) {
  std::string u = upper(s);
  if (u.size() == 2 && u[0] > u[1]) std::swap(u[0], u[1]);  // "ZX" is the XZ plane
  for (std::size_t i = 0; i < kPlaneNames.size(); ++i) {
    if (u == kPlaneNames[i]) return static_cast<Plane>(i);
  }
  throw InputError(fmt::format("plane '{}' is unknown (expected XY, XZ or YZ)", s));
}

std::string_view location_error_name(Plane p) {
  return kLocationNames.at(static_cast<std::size_t>(p));
}

double location_error_from_angle_over_90(Plane p, double alpha_urad) {
  return kAlphaToLocation.at(static_cast<std::size_t>(p)) * alpha_urad;
}

double angle_over_90_from_location_error(Plane p, double location_error_urad) {
  return kAlphaToLocation.at(static_cast<std::size_t>(p)) * location_error_urad;
}

double& Squareness::of(Plane p) {
  return p == Plane::xy ? c0y_urad : p == Plane::xz ? b0z_urad : a0z_urad;
}
double Squareness::of(Plane p) const {
  return p == Plane::xy ? c0y_urad : p == Plane::xz ? b0z_urad : a0z_urad;
}

std::span<const Component> all_components() { return kComponents; }

std::string_view to_string(Component c) { return kComponentNames.at(static_cast<std::size_t>(c)); }

Component component_from_string(std::string_view name) {
  std::string u = upper(name);
  // Accept "ECX" as written by some controllers (built by concatenation: GCC 12 warns
  // falsely about string::insert under -Werror=restrict).
  if (u.size() == 3) u = u.substr(0, 1) + "_" + u.substr(1);
  for (std::size_t k = 0; k < kComponentNames.size(); ++k) {
    if (u == kComponentNames[k]) return kComponents[k];
  }
  throw InputError(
      fmt::format("component '{}' is unknown (expected an ISO 230-1 name E_<direction><axis>, "
                  "direction X Y Z A B C, axis X Y Z, e.g. E_CX)",
                  name));
}

namespace {
// One lookup for the const and non-const overloads: component k of axis k / 6, in the order
// ex ey ez ea eb ec of AxisErrors (the order of enum Component).
template <typename M>
auto& component_of(M& m, Component c) {
  const auto k = static_cast<std::size_t>(c);
  auto& a = m.axes.at(k / 6);
  std::array f{&a.ex_um, &a.ey_um, &a.ez_um, &a.ea_urad, &a.eb_urad, &a.ec_urad};
  return *f.at(k % 6);
}
}  // namespace

ErrorFunction& component(Machine& m, Component c) { return component_of(m, c); }
const ErrorFunction& component(const Machine& m, Component c) { return component_of(m, c); }

// ---------------------------------------------------------------------------------------------
// The model

namespace {

using Eigen::Matrix3d;
using Eigen::Vector3d;

// The error motion of one axis at its position, in mm and rad.
struct AxisState {
  Vector3d travel_mm;  // q * u, u the actual (out-of-square) direction of the axis
  Vector3d delta_mm;   // translational errors
  Vector3d eps_rad;    // angular errors
};

double eval(const Machine& m, Axis axis, std::size_t dir, double q_mm) {
  const auto c = static_cast<Component>(axis * 6 + dir);
  try {
    return component(m, c)(q_mm);
  } catch (const InputError& e) {
    throw InputError(fmt::format("{}: {}", to_string(c), e.what()));
  }
}

// Actual unit directions of the axes. X is the reference; squareness as in kinematics.hpp:
// u_Y = Rz(E_C0Y) (0,1,0) = (-sin c, cos c, 0);
// u_Z = Ry(E_B0Z) Rx(E_A0Z) (0,0,1) = (cos a sin b, -sin a, cos a cos b).
using Directions = std::array<Vector3d, 3>;

Directions directions(const Squareness& s) {
  const double c = s.c0y_urad * kRadPerUrad, b = s.b0z_urad * kRadPerUrad,
               a = s.a0z_urad * kRadPerUrad;
  return {Vector3d(1, 0, 0), Vector3d(-std::sin(c), std::cos(c), 0),
          Vector3d(std::cos(a) * std::sin(b), -std::sin(a), std::cos(a) * std::cos(b))};
}

std::array<AxisState, 3> axis_states(const Machine& m, const Directions& u, const Vec3& q_mm) {
  std::array<AxisState, 3> s;
  for (std::size_t i = 0; i < 3; ++i) {
    const auto axis = static_cast<Axis>(i);
    s[i].travel_mm = q_mm[i] * u[i];
    s[i].delta_mm = kMmPerUm * Vector3d(eval(m, axis, 0, q_mm[i]), eval(m, axis, 1, q_mm[i]),
                                        eval(m, axis, 2, q_mm[i]));
    s[i].eps_rad = kRadPerUrad * Vector3d(eval(m, axis, 3, q_mm[i]), eval(m, axis, 4, q_mm[i]),
                                          eval(m, axis, 5, q_mm[i]));
  }
  return s;
}

Matrix3d rotation(const Vector3d& eps) {
  return (Eigen::AngleAxisd(eps.z(), Vector3d::UnitZ()) *
          Eigen::AngleAxisd(eps.y(), Vector3d::UnitY()) *
          Eigen::AngleAxisd(eps.x(), Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Isometry3d translation(const Vector3d& v) {
  return Eigen::Isometry3d(Eigen::Translation3d(v));
}

Eigen::Isometry3d rotation_htm(const Vector3d& eps) {
  Eigen::Isometry3d r = Eigen::Isometry3d::Identity();
  r.linear() = rotation(eps);
  return r;
}

// Exact chain, workpiece (table reference frame) to tool, in the order of the topology letters
// with F removed (chain_order). The HTM of a joint is the pose of its tool-side member in its
// workpiece-side member (Schwenke et al. 2008, eq. 1-2, with our sign convention that all
// errors are tool relative to workpiece):
// - tool-side axis: the carriage in its carrier, Trans(q u + delta) * Rot(eps): the rotation is
//   about the carriage's reference point, which moves with the carriage;
// - workpiece-side axis: the carrier in the carriage (table), Rot(eps) * Trans(q u + delta):
//   the rotation is about the table's reference point, fixed on the table.
// The table offset sits at the frame, between the two sides.
VolumetricError by_htm(const Machine& m, const Directions& u, const Vec3& q_mm) {
  const auto s = axis_states(m, u, q_mm);
  const auto order = chain_order(m.topology);
  const auto k = static_cast<std::size_t>(workpiece_side_axes(m.topology));
  const Vector3d table(m.table_offset_mm.data()), tool(m.tool_offset_mm.data());
  Eigen::Isometry3d h = Eigen::Isometry3d::Identity();
  for (std::size_t n = 0; n < k; ++n) {
    const AxisState& a = s[order[n]];
    h = h * rotation_htm(a.eps_rad) * translation(a.travel_mm + a.delta_mm);
  }
  h = h * translation(table);
  for (std::size_t n = k; n < 3; ++n) {
    const AxisState& a = s[order[n]];
    h = h * translation(a.travel_mm + a.delta_mm) * rotation_htm(a.eps_rad);
  }
  const Vector3d nominal = Vector3d(q_mm.data()) + table + tool;
  const Vector3d e_mm = h * tool - nominal;
  const Eigen::AngleAxisd aa(h.linear());
  const Vector3d rot = aa.angle() * aa.axis() / kRadPerUrad;
  VolumetricError r;
  for (std::size_t i = 0; i < 3; ++i) {
    r.translation_um[i] = e_mm[static_cast<Eigen::Index>(i)] / kMmPerUm;
    r.rotation_urad[i] = rot[static_cast<Eigen::Index>(i)];
  }
  return r;
}

// First-order expansion of by_htm, dropping every product of two errors (derivation in
// docs/kinematics.md): e = sum_i delta_i + sum_i eps_i x a_i + squareness terms, where the
// Abbe arm a_i is the nominal vector from axis i's reference point to the tool tip. With the
// axes numbered n = 0, 1, 2 along the chain (chain_order) and k of them on the workpiece side:
//   a_(n) = sum_{m>n} q_(m) e_(m) + tool + [n < k] (q_(n) e_(n) + table).
// Squareness (kinematics.hpp): (-E_C0Y y + E_B0Z z, -E_A0Z z, 0). Orientation: sum_i eps_i.
VolumetricError by_first_order(const Machine& m, const Directions& u, const Vec3& q_mm) {
  const auto s = axis_states(m, u, q_mm);
  const auto order = chain_order(m.topology);
  const auto k = static_cast<std::size_t>(workpiece_side_axes(m.topology));
  const Vector3d table(m.table_offset_mm.data()), tool(m.tool_offset_mm.data());
  const Vector3d q(q_mm.data());
  Vector3d e = Vector3d::Zero(), rot = Vector3d::Zero();
  for (std::size_t n = 0; n < 3; ++n) {
    const std::size_t i = order[n];
    Vector3d arm = tool;
    for (std::size_t later = n + 1; later < 3; ++later) {
      const std::size_t j = order[later];
      arm[static_cast<Eigen::Index>(j)] += q_mm[j];
    }
    if (n < k) {
      arm[static_cast<Eigen::Index>(i)] += q_mm[i];
      arm += table;
    }
    e += s[i].delta_mm + s[i].eps_rad.cross(arm);
    rot += s[i].eps_rad;
  }
  const Squareness& sq = m.squareness;
  e += kRadPerUrad * Vector3d(-sq.c0y_urad * q.y() + sq.b0z_urad * q.z(), -sq.a0z_urad * q.z(), 0);
  VolumetricError r;
  for (std::size_t i = 0; i < 3; ++i) {
    r.translation_um[i] = e[static_cast<Eigen::Index>(i)] / kMmPerUm;
    r.rotation_urad[i] = rot[static_cast<Eigen::Index>(i)] / kRadPerUrad;
  }
  return r;
}

void check_machine(const Machine& m) {
  check_finite(m.tool_offset_mm, "tool_offset_mm");
  check_finite(m.table_offset_mm, "table_offset_mm");
  const Vec3 sq{m.squareness.c0y_urad, m.squareness.b0z_urad, m.squareness.a0z_urad};
  check_finite(sq, "squareness (E_C0Y, E_B0Z, E_A0Z) urad");
  (void)to_string(m.topology);  // throws std::out_of_range for a value outside the enum
}

// The directions are computed once per call or per map: sin/cos per point would cost ~20 %.
VolumetricError evaluate_unchecked(const Machine& m, const Directions& u, const Vec3& q_mm,
                                   Method method) {
  return method == Method::htm ? by_htm(m, u, q_mm) : by_first_order(m, u, q_mm);
}

}  // namespace

VolumetricError volumetric_error(const Machine& m, const Vec3& position_mm, Method method) {
  check_machine(m);
  check_finite(position_mm, "position_mm");
  return evaluate_unchecked(m, directions(m.squareness), position_mm, method);
}

Vec3 volumetric_error_um(const Machine& m, const Vec3& position_mm, Method method) {
  return volumetric_error(m, position_mm, method).translation_um;
}

// ---------------------------------------------------------------------------------------------
// Maps

namespace {

void check_grid(const Grid& g) {
  check_finite(g.min_mm, "grid min_mm");
  check_finite(g.max_mm, "grid max_mm");
  double points = 1.0;
  for (std::size_t i = 0; i < 3; ++i) {
    if (g.count[i] == 0) {
      throw InputError(fmt::format("grid count[{}] = 0: expected at least 1 point", i));
    }
    if (g.max_mm[i] < g.min_mm[i]) {
      throw InputError(fmt::format("grid axis {}: max_mm = {} < min_mm = {} (expected min <= max)",
                                   i, g.max_mm[i], g.min_mm[i]));
    }
    points *= static_cast<double>(g.count[i]);
  }
  if (points > static_cast<double>(kMaxMapPoints)) {
    throw InputError(fmt::format("grid of {} x {} x {} points: more than the limit of {}",
                                 g.count[0], g.count[1], g.count[2], kMaxMapPoints));
  }
}

double grid_value(const Grid& g, std::size_t axis, std::size_t i) {
  if (g.count[axis] == 1) return g.min_mm[axis];
  const double t = static_cast<double>(i) / static_cast<double>(g.count[axis] - 1);
  // Written so that the last point is max_mm exactly (no table end missed by rounding).
  return i + 1 == g.count[axis] ? g.max_mm[axis]
                                : g.min_mm[axis] + t * (g.max_mm[axis] - g.min_mm[axis]);
}

void append(std::vector<double>& v, const Vec3& x) { v.insert(v.end(), x.begin(), x.end()); }

}  // namespace

ErrorMap volumetric_error_map(const Machine& m, const Grid& grid, Method method) {
  check_machine(m);
  check_grid(grid);
  ErrorMap map;
  map.count = grid.count;
  const Directions u = directions(m.squareness);
  const std::size_t n = grid.count[0] * grid.count[1] * grid.count[2];
  map.positions_mm.reserve(3 * n);
  map.errors_um.reserve(3 * n);
  map.rotations_urad.reserve(3 * n);
  for (std::size_t k = 0; k < grid.count[2]; ++k) {
    for (std::size_t j = 0; j < grid.count[1]; ++j) {
      for (std::size_t i = 0; i < grid.count[0]; ++i) {
        const Vec3 p{grid_value(grid, 0, i), grid_value(grid, 1, j), grid_value(grid, 2, k)};
        const auto e = evaluate_unchecked(m, u, p, method);
        append(map.positions_mm, p);
        append(map.errors_um, e.translation_um);
        append(map.rotations_urad, e.rotation_urad);
      }
    }
  }
  return map;
}

MapSummary summarize(const ErrorMap& map) {
  if (map.size() == 0 || map.errors_um.size() != map.positions_mm.size()) {
    throw InputError(
        fmt::format("error map with {} positions and {} error values: expected a "
                    "non-empty map with 3 values per point each",
                    map.positions_mm.size(), map.errors_um.size()));
  }
  MapSummary s;
  s.min_um.fill(std::numeric_limits<double>::infinity());
  s.max_um.fill(-std::numeric_limits<double>::infinity());
  s.max_norm_um = -1.0;
  for (std::size_t p = 0; p < map.size(); ++p) {
    const double* e = &map.errors_um[3 * p];
    const double norm = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
    if (norm > s.max_norm_um) {
      s.max_norm_um = norm;
      s.max_norm_at_mm = {map.positions_mm[3 * p], map.positions_mm[3 * p + 1],
                          map.positions_mm[3 * p + 2]};
    }
    for (std::size_t i = 0; i < 3; ++i) {
      s.min_um[i] = std::min(s.min_um[i], e[i]);
      s.max_um[i] = std::max(s.max_um[i], e[i]);
    }
  }
  for (std::size_t i = 0; i < 3; ++i) s.range_um[i] = s.max_um[i] - s.min_um[i];
  return s;
}

std::vector<Contribution> contributions(const Machine& m, const Grid& grid) {
  check_machine(m);
  check_grid(grid);
  Machine base = m;
  for (Component c : all_components()) component(base, c) = ErrorFunction{};
  base.squareness = {};
  std::vector<Contribution> out;
  auto add = [&](std::string_view name, Axis axis, const Machine& only) {
    const ErrorMap map = volumetric_error_map(only, grid, Method::first_order);
    Contribution c{std::string(name), axis, 0.0, 0.0};
    double sum = 0.0;
    for (std::size_t p = 0; p < map.size(); ++p) {
      const double* e = &map.errors_um[3 * p];
      const double n2 = e[0] * e[0] + e[1] * e[1] + e[2] * e[2];
      c.max_norm_um = std::max(c.max_norm_um, std::sqrt(n2));
      sum += n2;
    }
    c.rms_um = std::sqrt(sum / static_cast<double>(map.size()));
    out.push_back(c);
  };
  for (Component c : all_components()) {
    Machine only = base;
    component(only, c) = component(m, c);
    add(to_string(c), static_cast<Axis>(static_cast<std::size_t>(c) / 6), only);
  }
  for (Plane p : {Plane::xy, Plane::xz, Plane::yz}) {
    Machine only = base;
    only.squareness.of(p) = m.squareness.of(p);
    add(location_error_name(p), p == Plane::xy ? Y : Z, only);
  }
  std::stable_sort(out.begin(), out.end(), [](const Contribution& a, const Contribution& b) {
    return a.max_norm_um > b.max_norm_um;
  });
  return out;
}

}  // namespace cal::kinematics
