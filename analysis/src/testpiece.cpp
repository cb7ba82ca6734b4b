// Test piece prediction and evaluation (see testpiece.hpp and docs/testpiece.md).
//
// Prediction. A face with outward normal n is cut by the tool standing outside it, its centre
// at the surface point + r n; the edge touching the surface is at -r n from the tool axis. A
// bore of radius R is cut from inside, the centre at (R - r) u from the bore's centre and the
// edge at +r u. With the tool offset extended by that lateral edge offset, the model's error e
// at the commanded centre is the error of the cutting edge itself (its Abbe arms included); to
// first order only its component along the surface normal changes the surface: a face's
// deviation along its axis is e on that axis, a bore's radial deviation is e . u.
//
// Reference fits. Faces: minimum-zone straightness (ISO 230-1) and the least-squares line for
// the orientation. Squareness of an X face (deviation in +Y, slope m) and a Y face (deviation
// in +X, slope k): the directions (1, m) and (k, 1) make 90 deg - (m + k), so the squareness in
// the "over 90 deg" convention is -(m + k), the formula of two straightness runs
// (squareness.hpp). Bores: the least-squares circle of small radial deviations,
// d(t) = d0 + a cos t + b sin t; (a, b) is the centre offset, 2 d0 the diameter error, the
// range of the residuals the circularity (least-squares reference circle).
// Alignment: turning the part by phi (rad, small) adds phi x to the +Y deviation of a point at
// x and -phi y to the +X deviation of a point at y; a bore centre at (xc, yc) moves by
// phi (-yc, xc). phi = -m(face-Y) makes face-Y run along X.
#include "cal/analysis/testpiece.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>
#include <numbers>
#include <optional>

#include "cal/analysis/error.hpp"
#include "cal/analysis/straightness.hpp"

namespace cal::testpiece {
namespace {

namespace kin = cal::kinematics;
using kin::Vec3;

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

struct Face {
  const char* name;
  std::size_t normal_axis;  // the axis normal to the face
  double sign;              // the outward normal's direction on that axis
};
constexpr std::array<Face, 4> kFaces{
    {{"face+X", 0, 1.0}, {"face-X", 0, -1.0}, {"face+Y", 1, 1.0}, {"face-Y", 1, -1.0}}};

struct Bore {
  std::string name;
  double x_mm, y_mm, radius_mm;
};

std::vector<Bore> bores(const Layout& l) {
  const double c = l.corner_bore_offset_mm, r = 0.5 * l.corner_bore_diameter_mm;
  return {{"bore0", 0.0, 0.0, 0.5 * l.centre_bore_diameter_mm},
          {"bore1", c, c, r},
          {"bore2", -c, c, r},
          {"bore3", -c, -c, r},
          {"bore4", c, -c, r}};
}

Vec3 cut_error_um(const kin::Machine& m, const Vec3& centre_mm, double edge_x, double edge_y) {
  kin::Machine cutting = m;
  cutting.tool_offset_mm[0] += edge_x;
  cutting.tool_offset_mm[1] += edge_y;
  return kin::volumetric_error_um(cutting, centre_mm, kin::Method::htm);
}

constexpr double kMaxPointMm = 100e3;

struct Circle {
  double d0 = 0, a = 0, b = 0, circularity = 0;
};

Circle fit_circle(const Profile& p) {
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d aty = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < p.position.size(); ++i) {
    const double t = p.position[i] / kDegPerRad;
    const Eigen::Vector3d row(1.0, std::cos(t), std::sin(t));
    ata += row * row.transpose();
    aty += row * p.deviation_um[i];
  }
  if (std::abs(ata.determinant()) < 1e-9)
    throw InputError(
        fmt::format("{}: the points do not spread around the bore (a circle needs "
                    "points at three or more distinct angles)",
                    p.feature));
  // Points in one half of the circle (a straight line of points, an arc of one side) fit a
  // "circle" whose centre and circularity mean nothing: they must surround the centre.
  std::vector<double> angles(p.position.begin(), p.position.end());
  std::sort(angles.begin(), angles.end());
  double gap = angles.front() + 360.0 - angles.back();
  for (std::size_t i = 1; i < angles.size(); ++i) gap = std::max(gap, angles[i] - angles[i - 1]);
  if (gap >= 180.0)
    throw InputError(
        fmt::format("{}: the points lie within half of the bore (a gap of {:.1f} deg between "
                    "them): probe it all round",
                    p.feature, gap));
  const Eigen::Vector3d x = ata.ldlt().solve(aty);
  Circle c{x[0], x[1], x[2], 0.0};
  double lo = INFINITY, hi = -INFINITY;
  for (std::size_t i = 0; i < p.position.size(); ++i) {
    const double t = p.position[i] / kDegPerRad;
    const double r = p.deviation_um[i] - (x[0] + x[1] * std::cos(t) + x[2] * std::sin(t));
    lo = std::min(lo, r), hi = std::max(hi, r);
  }
  c.circularity = hi - lo;
  return c;
}

const Face* face_named(const std::string& n) {
  for (const auto& f : kFaces)
    if (n == f.name) return &f;
  return nullptr;
}

}  // namespace

void validate(const Layout& l) {
  const auto positive = [](double v) { return std::isfinite(v) && v > 0; };
  if (!positive(l.side_mm) || !(l.face_margin_mm >= 0) || !(2 * l.face_margin_mm < l.side_mm))
    throw InputError(
        fmt::format("test piece: side {} mm with margins {} mm (expected a side > 0 "
                    "longer than both margins)",
                    l.side_mm, l.face_margin_mm));
  if (!positive(l.centre_bore_diameter_mm) || !positive(l.corner_bore_diameter_mm) ||
      !positive(l.corner_bore_offset_mm))
    throw InputError("test piece: bore diameters and the corner bores' offset must be > 0");
  const double c = l.corner_bore_offset_mm, half = 0.5 * l.side_mm;
  if (c + 0.5 * l.corner_bore_diameter_mm >= half ||
      std::hypot(c, c) <= 0.5 * (l.centre_bore_diameter_mm + l.corner_bore_diameter_mm))
    throw InputError(
        "test piece: the corner bores must lie inside the square and clear of the "
        "centre bore");
  if (l.points_per_face < 2 || l.points_per_bore < 3 || l.points_per_face > 100000 ||
      l.points_per_bore > 100000)
    throw InputError("test piece: at least 2 points per face and 3 per bore (at most 100000)");
}

std::vector<Profile> predict_profiles(const kin::Machine& m, const Layout& l, const Cutting& s) {
  validate(l);
  if (!(s.tool_radius_mm > 0) || !std::isfinite(s.tool_radius_mm))
    throw InputError(fmt::format("test piece: tool radius {} mm must be > 0", s.tool_radius_mm));
  for (double v : s.origin_mm)
    if (!std::isfinite(v)) throw InputError("test piece: the part's origin must be finite");
  const double r = s.tool_radius_mm, half = 0.5 * l.side_mm;
  for (const Bore& b : bores(l))
    if (!(b.radius_mm > r))
      throw InputError(
          fmt::format("test piece: the tool radius {} mm does not fit {} (radius {} mm)", r, b.name,
                      b.radius_mm));
  std::vector<Profile> out;
  for (const Face& f : kFaces) {
    Profile p{f.name, {}, {}};
    const std::size_t along = 1 - f.normal_axis;
    for (int i = 0; i < l.points_per_face; ++i) {
      const double t = -half + l.face_margin_mm +
                       (l.side_mm - 2 * l.face_margin_mm) * i / (l.points_per_face - 1);
      Vec3 centre = s.origin_mm;
      centre[along] += t;
      centre[f.normal_axis] += f.sign * (half + r);
      double edge[2] = {0.0, 0.0};
      edge[f.normal_axis] = -f.sign * r;  // the edge faces the surface, -r n from the axis
      const Vec3 e = cut_error_um(m, centre, edge[0], edge[1]);
      p.position.push_back(t);
      p.deviation_um.push_back(e[f.normal_axis]);
    }
    out.push_back(std::move(p));
  }
  for (const Bore& b : bores(l)) {
    Profile p{b.name, {}, {}};
    for (int i = 0; i < l.points_per_bore; ++i) {
      const double t = 2 * std::numbers::pi * i / l.points_per_bore;
      const double ux = std::cos(t), uy = std::sin(t);
      const Vec3 centre{s.origin_mm[0] + b.x_mm + (b.radius_mm - r) * ux,
                        s.origin_mm[1] + b.y_mm + (b.radius_mm - r) * uy, s.origin_mm[2]};
      const Vec3 e = cut_error_um(m, centre, r * ux, r * uy);
      p.position.push_back(t * kDegPerRad);
      p.deviation_um.push_back(e[0] * ux + e[1] * uy);
    }
    out.push_back(std::move(p));
  }
  return out;
}

std::vector<Profile> measured_profiles(const Layout& l, std::span<const Point> points) {
  validate(l);
  const double half = 0.5 * l.side_mm;
  std::map<std::string, Profile> by_name;
  const auto all_bores = bores(l);
  for (const Point& q : points) {
    if (!std::isfinite(q.x_mm) || !std::isfinite(q.y_mm))
      throw InputError(fmt::format("{}: a point is not finite", q.feature));
    // A part's point 100 m from its origin is a typing error (and 1e300 would overflow the
    // fits to inf).
    if (std::abs(q.x_mm) > kMaxPointMm || std::abs(q.y_mm) > kMaxPointMm)
      throw InputError(
          fmt::format("{}: the point ({}, {}) mm is beyond {:g} m of the part's origin", q.feature,
                      q.x_mm, q.y_mm, kMaxPointMm / 1e3));
    Profile& p = by_name[q.feature];
    p.feature = q.feature;
    if (const Face* f = face_named(q.feature)) {
      const double along = f->normal_axis == 0 ? q.y_mm : q.x_mm;
      const double across = f->normal_axis == 0 ? q.x_mm : q.y_mm;
      p.position.push_back(along);
      p.deviation_um.push_back((across - f->sign * half) * 1e3);
      continue;
    }
    const auto b = std::find_if(all_bores.begin(), all_bores.end(),
                                [&](const Bore& x) { return x.name == q.feature; });
    if (b == all_bores.end())
      throw InputError(
          fmt::format("feature '{}' is unknown (expected face+X, face-X, face+Y, "
                      "face-Y, bore0 .. bore4)",
                      q.feature));
    const double dx = q.x_mm - b->x_mm, dy = q.y_mm - b->y_mm;
    p.position.push_back(std::atan2(dy, dx) * kDegPerRad);
    p.deviation_um.push_back((std::hypot(dx, dy) - b->radius_mm) * 1e3);
  }
  std::vector<Profile> out;
  for (auto& [name, p] : by_name) {
    const std::size_t need = face_named(name) ? 2 : 3;
    if (p.position.size() < need)
      throw InputError(
          fmt::format("{}: {} point(s), at least {} needed", name, p.position.size(), need));
    out.push_back(std::move(p));
  }
  return out;
}

Result evaluate(const Layout& l, std::span<const Profile> profiles) {
  validate(l);
  std::map<std::string, double> slope;  // um/mm, raw (before alignment)
  std::map<std::string, Circle> circle;
  Result r;
  for (const Profile& p : profiles) {
    if (p.position.size() != p.deviation_um.size())
      throw InputError(fmt::format("{}: positions and deviations differ in number", p.feature));
    if (face_named(p.feature)) {
      const auto z =
          straightness::evaluate(p.position, p.deviation_um, straightness::Reference::minimum_zone);
      const auto lsq = straightness::evaluate(p.position, p.deviation_um,
                                              straightness::Reference::least_squares);
      slope[p.feature] = lsq.slope_um_per_m * 1e-3;
      r.faces.push_back({p.feature, z.straightness_um, lsq.slope_um_per_m});
    } else {
      circle[p.feature] = fit_circle(p);
    }
  }
  // Alignment: phi turns face-Y onto X; the origin goes to bore0's centre.
  double phi = 0.0;  // rad
  const bool aligned = slope.count("face-Y") && circle.count("bore0");
  if (slope.count("face-Y")) phi = -slope["face-Y"] * 1e-3;
  for (auto& f : r.faces) {
    const bool x_face = face_named(f.feature)->normal_axis == 1;  // runs along X
    f.slope_um_per_m += (x_face ? phi : -phi) * 1e6;
  }
  const auto all_bores = bores(l);
  double ox = 0.0, oy = 0.0;
  if (aligned) ox = circle["bore0"].a, oy = circle["bore0"].b;  // bore0 sits at (0, 0): no turn
  for (const Bore& b : all_bores) {
    if (!circle.count(b.name)) continue;
    const Circle& c = circle[b.name];
    const double px = c.a + phi * -b.y_mm * 1e3 - ox, py = c.b + phi * b.x_mm * 1e3 - oy;
    r.bores.push_back({b.name, c.circularity, 2 * c.d0, aligned ? px : c.a, aligned ? py : c.b});
  }
  r.aligned = aligned;
  // Squareness at the corners present: X face (runs along X, slope m) with Y face (slope k).
  for (const char* xf : {"face+Y", "face-Y"})
    for (const char* yf : {"face+X", "face-X"})
      if (slope.count(xf) && slope.count(yf))
        r.squareness_um_per_m.push_back(
            {fmt::format("{} / {}", xf, yf), -(slope[xf] + slope[yf]) * 1e3});
  if (slope.count("face+Y") && slope.count("face-Y"))
    r.parallelism_um_per_m.push_back(
        {"face+Y / face-Y", (slope["face+Y"] - slope["face-Y"]) * 1e3});
  if (slope.count("face+X") && slope.count("face-X"))
    r.parallelism_um_per_m.push_back(
        {"face+X / face-X", (slope["face+X"] - slope["face-X"]) * 1e3});
  return r;
}

}  // namespace cal::testpiece
