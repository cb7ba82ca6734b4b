// The three-plane table (docs/circle.md, "The three-plane table"). The scale equations, with
// the axes X = 0, Y = 1, Z = 2 and each plane's (u, v):
//   s_u - s_v = mismatch          (every plane)
//   (s_u + s_v) / 2 = mean scale  (calibrated planes)
// The mismatches alone have rank 2 at most (the three sum to zero: a common scale of all axes
// leaves every mismatch unchanged), so only a calibrated bar fixes the absolute scale.
#include "cal/analysis/ballbar_planes.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <cmath>
#include <vector>

#include "cal/analysis/error.hpp"

namespace cal::circle {
namespace {

std::array<int, 2> axes_of(Plane p) {
  switch (p) {
    case Plane::yz:
      return {1, 2};
    case Plane::zx:
      return {2, 0};
    case Plane::xy:
    default:
      return {0, 1};
  }
}

struct Equations {
  std::vector<std::array<double, 3>> rows;
  std::vector<double> rhs;
  void add(std::array<double, 3> row, double value) {
    rows.push_back(row);
    rhs.push_back(value);
  }
  Eigen::MatrixXd a() const {
    Eigen::MatrixXd m(static_cast<Eigen::Index>(rows.size()), 3);
    for (std::size_t i = 0; i < rows.size(); ++i)
      for (int k = 0; k < 3; ++k) m(static_cast<Eigen::Index>(i), k) = rows[i][std::size_t(k)];
    return m;
  }
  Eigen::VectorXd b() const {
    return Eigen::Map<const Eigen::VectorXd>(rhs.data(), static_cast<Eigen::Index>(rhs.size()));
  }
};

// The minimum-norm least-squares solution when the equations determine `rank` unknowns.
std::optional<std::array<double, 3>> solve(const Equations& e, int rank_needed,
                                           std::optional<double>& residual_rms) {
  if (e.rows.empty()) return std::nullopt;
  const Eigen::MatrixXd a = e.a();
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(a);
  cod.setThreshold(1e-9);
  if (cod.rank() < rank_needed) return std::nullopt;
  const Eigen::VectorXd x = cod.solve(e.b());
  if (static_cast<int>(e.rows.size()) > cod.rank())
    residual_rms = std::sqrt((a * x - e.b()).squaredNorm() / static_cast<double>(e.rows.size()));
  return std::array<double, 3>{x(0), x(1), x(2)};
}

}  // namespace

kinematics::Plane model_plane(Plane p) {
  return p == Plane::zx   ? kinematics::Plane::xz
         : p == Plane::yz ? kinematics::Plane::yz
                          : kinematics::Plane::xy;
}

double location_error_urad(const PlaneValues& v) {
  return kinematics::location_error_from_angle_over_90(model_plane(v.plane), v.squareness_um_per_m);
}

ThreePlanes combine_planes(std::span<const PlaneValues> planes) {
  ThreePlanes out;
  Equations mismatch, all;
  for (const auto& p : planes) {
    auto& slot = out.planes[static_cast<std::size_t>(p.plane)];
    if (slot) throw InputError("three-plane table: two sets of values for one plane");
    if (!std::isfinite(p.squareness_um_per_m) || !std::isfinite(p.scale_mismatch_um_per_m) ||
        (p.mean_scale_um_per_m && !std::isfinite(*p.mean_scale_um_per_m)))
      throw InputError("three-plane table: a value is not finite");
    slot = p;
    const auto [u, v] = axes_of(p.plane);
    std::array<double, 3> diff{}, mean{};
    diff[std::size_t(u)] = 1.0, diff[std::size_t(v)] = -1.0;
    mean[std::size_t(u)] = 0.5, mean[std::size_t(v)] = 0.5;
    mismatch.add(diff, p.scale_mismatch_um_per_m);
    all.add(diff, p.scale_mismatch_um_per_m);
    if (p.mean_scale_um_per_m) all.add(mean, *p.mean_scale_um_per_m);
  }
  if (out.planes[0] && out.planes[1] && out.planes[2])
    out.closure_um_per_m = out.planes[0]->scale_mismatch_um_per_m +
                           out.planes[1]->scale_mismatch_um_per_m +
                           out.planes[2]->scale_mismatch_um_per_m;
  std::optional<double> residual;
  if (auto s = solve(all, 3, residual)) {
    out.scale_um_per_m = s, out.scale_absolute = true, out.scale_residual_um_per_m = residual;
    return out;
  }
  residual.reset();
  // Relative: the minimum-norm solution of the mismatches has no component along (1, 1, 1),
  // i.e. its mean is 0.
  if (auto s = solve(mismatch, 2, residual))
    out.scale_um_per_m = s, out.scale_residual_um_per_m = residual;
  return out;
}

}  // namespace cal::circle
