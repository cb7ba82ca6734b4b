// Straightness reference lines (see straightness.hpp).
#include "cal/analysis/straightness.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "cal/analysis/enum_names.hpp"
#include "cal/analysis/error.hpp"

namespace cal::straightness {
namespace {

struct Line {
  double slope = 0.0, intercept = 0.0;  // um per mm, um
};

void validate(std::span<const double> x, std::span<const double> y) {
  if (x.size() != y.size())
    throw InputError(
        fmt::format("straightness: {} positions but {} deviations", x.size(), y.size()));
  if (x.size() < 2)
    throw InputError(fmt::format("straightness: {} points, at least 2 needed", x.size()));
  for (std::size_t i = 0; i < x.size(); ++i)
    if (!std::isfinite(x[i]) || !std::isfinite(y[i]))
      throw InputError(fmt::format("straightness: point {} is not finite", i + 1));
  if (std::all_of(x.begin(), x.end(), [&](double v) { return v == x[0]; }))
    throw InputError("straightness: all positions are equal");
}

Line least_squares(std::span<const double> x, std::span<const double> y) {
  const double n = static_cast<double>(x.size());
  const double mx = std::accumulate(x.begin(), x.end(), 0.0) / n;
  const double my = std::accumulate(y.begin(), y.end(), 0.0) / n;
  double sxy = 0, sxx = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxy += (x[i] - mx) * (y[i] - my);
    sxx += (x[i] - mx) * (x[i] - mx);
  }
  const double slope = sxy / sxx;
  return {slope, my - slope * mx};
}

Line end_point(std::span<const double> x, std::span<const double> y) {
  const auto lo = std::min_element(x.begin(), x.end()) - x.begin();
  const auto hi = std::max_element(x.begin(), x.end()) - x.begin();
  const double slope = (y[static_cast<std::size_t>(hi)] - y[static_cast<std::size_t>(lo)]) /
                       (x[static_cast<std::size_t>(hi)] - x[static_cast<std::size_t>(lo)]);
  return {slope, y[static_cast<std::size_t>(lo)] - slope * x[static_cast<std::size_t>(lo)]};
}

double width(std::span<const double> x, std::span<const double> y, double slope, double& mid) {
  double lo = 1e300, hi = -1e300;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double r = y[i] - slope * x[i];
    lo = std::min(lo, r), hi = std::max(hi, r);
  }
  mid = 0.5 * (lo + hi);
  return hi - lo;
}

// The vertical width w(m) = max(y - m x) - min(y - m x) is convex and piecewise linear in the
// slope m, with its breaks at the slopes of the convex hull's edges: the minimum is at one of
// them (Andrew's monotone chain for the hull).
Line minimum_zone(std::span<const double> x, std::span<const double> y) {
  std::vector<std::pair<double, double>> p;
  for (std::size_t i = 0; i < x.size(); ++i) p.emplace_back(x[i], y[i]);
  std::sort(p.begin(), p.end());
  auto cross = [](const auto& o, const auto& a, const auto& b) {
    return (a.first - o.first) * (b.second - o.second) -
           (a.second - o.second) * (b.first - o.first);
  };
  std::vector<std::pair<double, double>> hull;
  for (int pass = 0; pass < 2; ++pass) {
    const std::size_t start = hull.size();
    for (std::size_t k = 0; k < p.size(); ++k) {
      const auto& q = pass == 0 ? p[k] : p[p.size() - 1 - k];
      while (hull.size() >= start + 2 && cross(hull[hull.size() - 2], hull.back(), q) <= 0)
        hull.pop_back();
      hull.push_back(q);
    }
    hull.pop_back();
  }
  Line best = least_squares(x, y);
  double mid = 0.0, best_w = width(x, y, best.slope, mid);
  best.intercept = mid;
  for (std::size_t k = 0; k < hull.size(); ++k) {
    const auto& a = hull[k];
    const auto& b = hull[(k + 1) % hull.size()];
    if (a.first == b.first) continue;
    const double m = (b.second - a.second) / (b.first - a.first);
    const double w = width(x, y, m, mid);
    if (w < best_w) best_w = w, best = {m, mid};
  }
  return best;
}

}  // namespace

std::string_view to_string(Reference r) {
  using enum Reference;
  static constexpr EnumName<Reference> kNames[] = {
      {least_squares, "least squares"}, {end_point, "end point"}, {minimum_zone, "minimum zone"}};
  static_assert(cal::names_every_value(kNames));
  return name_of(kNames, r);
}

Reference reference_from_string(std::string_view s) {
  using enum Reference;
  // The words of the command line and the files (the shown names have a space).
  static constexpr EnumName<Reference> kWords[] = {
      {least_squares, "lsq"},   {least_squares, "least-squares"}, {end_point, "endpoint"},
      {end_point, "end-point"}, {minimum_zone, "minzone"},        {minimum_zone, "minimum-zone"}};
  static_assert(cal::names_every_value(kWords));
  if (const auto r = value_named(kWords, s)) return *r;
  throw InputError(
      fmt::format("unknown reference line '{}' (expected lsq, endpoint or minzone)", s));
}

Result evaluate(std::span<const double> x, std::span<const double> y, Reference reference) {
  validate(x, y);
  const Line line = reference == Reference::least_squares ? least_squares(x, y)
                    : reference == Reference::end_point   ? end_point(x, y)
                                                          : minimum_zone(x, y);
  Result r;
  r.reference = reference;
  r.slope_um_per_m = line.slope * 1e3;
  r.intercept_um = line.intercept;
  double lo = 1e300, hi = -1e300;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double res = y[i] - (line.intercept + line.slope * x[i]);
    r.residual_um.push_back(res);
    lo = std::min(lo, res), hi = std::max(hi, res);
  }
  r.straightness_um = hi - lo;
  return r;
}

}  // namespace cal::straightness
