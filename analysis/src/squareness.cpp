// Squareness methods (see squareness.hpp).
//
// Two straightness runs. Let the actual directions of the axes be A ~ (1, mA) and
// B ~ (mB, 1) in a frame whose axes are the square's faces (assumed exactly 90 deg). The
// angle between them is 90 deg - (mA + mB) to first order, so the squareness (positive above
// 90 deg) is -(mA + mB). A square whose own angle is 90 deg + e makes the measured slopes
// sum to (mA + mB) - e: subtracting e gives the machine's value; turning the square over
// changes the sign of e, so the mean of the two set-ups cancels it.
//
// Diagonals (ISO 230-6). With x error -alpha y: the diagonal (X, 0) -> (0, Y), vector
// (-X, Y), becomes (-X - alpha Y, Y), length D0 + alpha X Y / D0; the diagonal (0, 0) ->
// (X, Y) becomes (X - alpha Y, Y), length D0 - alpha X Y / D0. So d1 - d2 = 2 alpha X Y / D0.
//
// Circle. With x error -alpha y on a circle of radius R: dr = -alpha R sin t cos t =
// -(alpha R / 2) sin 2t, so alpha = -2 d / R for the sin 2t coefficient d.
#include "cal/analysis/squareness.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <cmath>
#include <numbers>

#include "cal/analysis/error.hpp"
#include "cal/analysis/straightness.hpp"

namespace cal::squareness {

Result from_straightness(const Run& a, const Run& b, double square_error_um_per_m) {
  using straightness::Reference;
  const auto la = straightness::evaluate(a.position_mm, a.deviation_um, Reference::least_squares);
  const auto lb = straightness::evaluate(b.position_mm, b.deviation_um, Reference::least_squares);
  return {-(la.slope_um_per_m + lb.slope_um_per_m) - square_error_um_per_m};
}

Result from_reversal(const Result& normal, const Result& reversed) {
  return {0.5 * (normal.squareness_um_per_m + reversed.squareness_um_per_m)};
}

Result from_diagonals(double x_mm, double y_mm, double d1_um, double d2_um) {
  if (!(x_mm > 0) || !(y_mm > 0))
    throw InputError(fmt::format("diagonal test: sides {} x {} mm must be > 0", x_mm, y_mm));
  if (!std::isfinite(d1_um) || !std::isfinite(d2_um))
    throw InputError("diagonal test: the diagonal errors must be finite");
  const double d0 = std::hypot(x_mm, y_mm);
  // um / mm = 1e-3 rad -> um/m: x 1e3.
  return {d0 * (d1_um - d2_um) / (2.0 * x_mm * y_mm) * 1e3};
}

Result from_circle(double radius_mm, std::span<const CircleTrace> traces) {
  if (!(radius_mm > 0))
    throw InputError(fmt::format("circle: radius {} mm must be > 0", radius_mm));
  if (traces.empty()) throw InputError("circle: no trace");
  Eigen::Matrix<double, 5, 5> ata = Eigen::Matrix<double, 5, 5>::Zero();
  Eigen::Matrix<double, 5, 1> aty = Eigen::Matrix<double, 5, 1>::Zero();
  std::size_t n = 0;
  for (const auto& t : traces) {
    if (t.angle_deg.size() != t.deviation_um.size())
      throw InputError("circle: angles and deviations differ in number");
    for (std::size_t i = 0; i < t.angle_deg.size(); ++i, ++n) {
      const double th = t.angle_deg[i] * std::numbers::pi / 180.0;
      Eigen::Matrix<double, 5, 1> row;
      row << 1.0, std::cos(th), std::sin(th), std::cos(2 * th), std::sin(2 * th);
      ata += row * row.transpose();
      aty += row * t.deviation_um[i];
    }
  }
  if (n < 5) throw InputError(fmt::format("circle: {} samples, at least 5 needed", n));
  const Eigen::Matrix<double, 5, 1> x = ata.ldlt().solve(aty);
  return {-2.0 * x[4] / radius_mm * 1e3};
}

Result from_circles(std::span<const Local> circles) {
  if (circles.empty()) throw InputError("squareness: no circle");
  double sum = 0.0;
  for (const auto& c : circles) sum += c.result.squareness_um_per_m;
  return {sum / static_cast<double>(circles.size())};
}

}  // namespace cal::squareness
