// ISO 230-4 circular test and ballbar diagnostics (see circle.hpp, docs/circle.md).
//
// The diagnostic model. In the plane, the tool commanded at angle theta is at
// (u, v) = R (cos theta, sin theta) about the table ball (the pivot); to first order in
// the errors (du, dv) of the two axes, the bar length changes by
//     dr = du cos(theta) + dv sin(theta).
// Each error source gives (du, dv) as a function of the position and the direction of
// travel s (+1 ccw, -1 cw: u' = -R w s sin(theta), v' = R w s cos(theta)):
//   centre offset (cu, cv):         du = cu, dv = cv              -> cu cos + cv sin
//   radius error dR:                                              -> dR
//   scale su, sv:                   du = su u, dv = sv v          -> R(su+sv)/2 + R(su-sv)/2 cos 2t
//   squareness a (E_C0Y, > 0 when the angle between +u and +v exceeds 90 deg): du = -a v
//                                                                 -> -(a R / 2) sin 2t
//   servo mismatch, v lagging u by tau:  dv = -tau v'             -> -(tau R w s / 2) sin 2t
//   backlash bu (lost motion: the axis stays bu/2 behind its direction of travel):
//                                   du = -(bu/2) sign(u') = (bu/2) s sign(sin t)
//                                                                 -> (bu/2) s sign(sin t) cos t
//   backlash bv:                    dv = -(bv/2) sign(v')         -> -(bv/2) s sign(cos t) sin t
//   lateral play pu (u shifts by pu/2 with the direction of v):  du = (pu/2) sign(v')
//                                                                 -> (pu/2) s |cos t|
//   lateral play pv (v shifts with the direction of u):  dv = (pv/2) sign(u')
//                                                                 -> -(pv/2) s |sin t|
//   reversal spike of u (a bump after each reversal of u, at t = 0 and pi, decaying over the
//   angle travelled since):        -> A sum exp(-d/phi), d = s (t - t_r) mod 2 pi
//   cyclic error of u, period p:    du = A sin(2 pi u / p + phase)
//                                  -> cos t [a sin(2 pi R cos t / p) + b cos(2 pi R cos t / p)]
//   straightness, a bow of u along v (du = k v^2 / R^2, k the bow at the ends of the travel):
//                                  -> k sin^2 t cos t;  of v along u: k cos^2 t sin t
// The coefficients are fitted by linear least squares over all samples of both directions
// (the normal equations: the basis is small, the data up to 2 x 36,000 samples).
// Second-order terms (e^2 / R, below 1 nm for errors of 10 um at R = 50 mm) are neglected.
#include "cal/analysis/circle.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <numbers>

#include "cal/analysis/error.hpp"

namespace cal::circle {
namespace {

constexpr double pi = std::numbers::pi;
constexpr double deg = pi / 180.0;

double sgn(double x) { return x > 0 ? 1.0 : x < 0 ? -1.0 : 0.0; }

struct Sample {
  double theta, s, y;
};

std::string axis_names(Plane p) {
  switch (p) {
    case Plane::xy:
      return "XY";
    case Plane::yz:
      return "YZ";
    case Plane::zx:
      return "ZX";
  }
  return "XY";
}

enum Term {
  centre_u,
  centre_v,
  radius,
  scale,
  squareness,
  servo,
  backlash_u,
  backlash_v,
  lateral_u,
  lateral_v,
  spike_u,
  spike_v,
  cyclic_u_a,
  cyclic_u_b,
  cyclic_v_a,
  cyclic_v_b,
  bow_u,
  bow_v,
  term_count
};

struct Model {
  double r_mm, phi_rad, period_mm;
  std::array<bool, term_count> on{};

  double spike(double theta, double s, double first) const {
    double sum = 0.0;
    for (double tr : {first, first + pi}) {
      double d = std::fmod(s * (theta - tr), 2 * pi);
      if (d < 0) d += 2 * pi;
      sum += std::exp(-d / phi_rad);
    }
    return sum;
  }

  void basis(double t, double s, std::array<double, term_count>& b) const {
    const double c = std::cos(t), n = std::sin(t);
    const double ku = 2 * pi * r_mm * c / period_mm, kv = 2 * pi * r_mm * n / period_mm;
    b = {c,
         n,
         1.0,
         std::cos(2 * t),
         std::sin(2 * t),
         s * std::sin(2 * t),
         s * sgn(n) * c,
         -s * sgn(c) * n,
         s * std::abs(c),
         -s * std::abs(n),
         spike(t, s, 0.0),
         spike(t, s, pi / 2),
         c * std::sin(ku),
         c * std::cos(ku),
         n * std::sin(kv),
         n * std::cos(kv),
         n * n * c,
         c * c * n};
  }
};

struct Fit {
  Eigen::VectorXd coef;  // per term (0 where off)
  double rss = 0.0;
  Eigen::MatrixXd basis;  // samples x terms: reused for the contributions
};

Fit fit(const Model& m, std::span<const Sample> samples) {
  const auto n = static_cast<Eigen::Index>(samples.size());
  Fit f;
  f.basis.resize(n, term_count);
  std::array<double, term_count> b{};
  Eigen::VectorXd y(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    m.basis(samples[static_cast<std::size_t>(i)].theta, samples[static_cast<std::size_t>(i)].s, b);
    for (int k = 0; k < term_count; ++k)
      f.basis(i, k) = m.on[static_cast<std::size_t>(k)] ? b[static_cast<std::size_t>(k)] : 0.0;
    y[i] = samples[static_cast<std::size_t>(i)].y;
  }
  // Normal equations on the active columns, with column scaling for conditioning (the bases
  // differ in size); the inactive columns are zero and get a unit diagonal.
  Eigen::MatrixXd ata = f.basis.transpose() * f.basis;
  Eigen::VectorXd aty = f.basis.transpose() * y;
  for (int k = 0; k < term_count; ++k)
    if (!m.on[static_cast<std::size_t>(k)]) ata(k, k) = 1.0;
  const Eigen::VectorXd scale = ata.diagonal().cwiseSqrt().cwiseMax(1e-300).cwiseInverse();
  const Eigen::MatrixXd scaled = scale.asDiagonal() * ata * scale.asDiagonal();
  f.coef = scale.asDiagonal() * scaled.ldlt().solve(scale.asDiagonal() * aty);
  f.rss = (y - f.basis * f.coef).squaredNorm();
  return f;
}

// The smallest arc covering the angles: 360 minus the largest gap between sorted angles.
double coverage_deg(std::span<const double> angles) {
  std::vector<double> a;
  for (double x : angles) a.push_back(std::fmod(std::fmod(x, 360.0) + 360.0, 360.0));
  std::sort(a.begin(), a.end());
  double gap = a.front() + 360.0 - a.back();
  for (std::size_t i = 1; i < a.size(); ++i) gap = std::max(gap, a[i] - a[i - 1]);
  return 360.0 - gap;
}

void validate(const Setup& setup, std::span<const Trace> traces) {
  if (traces.empty()) throw InputError("circle: no trace given");
  if (traces.size() > 2)
    throw InputError(fmt::format("circle: {} traces given, at most 2 (cw, ccw)", traces.size()));
  if (traces.size() == 2 && traces[0].direction == traces[1].direction)
    throw InputError("circle: two traces in the same direction");
  if (!(setup.radius_mm > 0) || !std::isfinite(setup.radius_mm))
    throw InputError(fmt::format("circle: radius {} mm must be > 0", setup.radius_mm));
  if (!(setup.feed_mm_per_min > 0))
    throw InputError(fmt::format("circle: feed {} mm/min must be > 0", setup.feed_mm_per_min));
  for (const auto& t : traces) {
    const char* name = t.direction == Direction::cw ? "cw" : "ccw";
    if (t.angle_deg.size() != t.deviation_um.size())
      throw InputError(fmt::format("circle: {} trace has {} angles but {} deviations", name,
                                   t.angle_deg.size(), t.deviation_um.size()));
    if (t.angle_deg.size() < 20)
      throw InputError(fmt::format("circle: {} trace has {} samples, at least 20 needed", name,
                                   t.angle_deg.size()));
    for (std::size_t i = 0; i < t.angle_deg.size(); ++i)
      if (!std::isfinite(t.angle_deg[i]) || !std::isfinite(t.deviation_um[i]))
        throw InputError(fmt::format("circle: {} trace sample {} is not finite", name, i));
    if (const double arc = coverage_deg(t.angle_deg); arc < 180.0 - 1e-9)
      throw InputError(
          fmt::format("circle: {} trace covers {:.1f} degrees, at least 180 needed", name, arc));
  }
}

// Least-squares circle (linearised: dr = r0 + cu cos + cv sin) and the residual radii.
struct Circle {
  double cu = 0, cv = 0;
  std::vector<std::vector<double>> residual;  // per trace, in the trace's order
};

Circle lsq_circle(std::span<const Trace> traces) {
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d aty = Eigen::Vector3d::Zero();
  for (const auto& t : traces)
    for (std::size_t i = 0; i < t.angle_deg.size(); ++i) {
      const Eigen::Vector3d a(1.0, std::cos(t.angle_deg[i] * deg), std::sin(t.angle_deg[i] * deg));
      ata += a * a.transpose();
      aty += a * t.deviation_um[i];
    }
  const Eigen::Vector3d x = ata.ldlt().solve(aty);
  Circle c{x[1], x[2], {}};
  for (const auto& t : traces) {
    std::vector<double> r;
    for (std::size_t i = 0; i < t.angle_deg.size(); ++i)
      r.push_back(t.deviation_um[i] - x[1] * std::cos(t.angle_deg[i] * deg) -
                  x[2] * std::sin(t.angle_deg[i] * deg));
    c.residual.push_back(std::move(r));
  }
  return c;
}

double pv(const std::vector<std::vector<double>>& vs) {
  double lo = 1e300, hi = -1e300;
  for (const auto& v : vs)
    for (double x : v) lo = std::min(lo, x), hi = std::max(hi, x);
  return hi - lo;
}

// Largest |r_a(theta) - r_b(theta)|, r_b interpolated (periodically) at the angles of a.
double hysteresis(const Trace& a, const std::vector<double>& ra, const Trace& b,
                  const std::vector<double>& rb) {
  std::vector<std::pair<double, double>> pts;
  for (std::size_t i = 0; i < b.angle_deg.size(); ++i)
    pts.emplace_back(std::fmod(std::fmod(b.angle_deg[i], 360.0) + 360.0, 360.0), rb[i]);
  std::sort(pts.begin(), pts.end());
  double h = 0.0;
  for (std::size_t i = 0; i < a.angle_deg.size(); ++i) {
    const double t = std::fmod(std::fmod(a.angle_deg[i], 360.0) + 360.0, 360.0);
    auto hi = std::lower_bound(pts.begin(), pts.end(), std::make_pair(t, -1e300));
    const auto& p1 = hi == pts.end() ? pts.front() : *hi;
    const auto& p0 = hi == pts.begin() ? pts.back() : *std::prev(hi);
    double span = p1.first - p0.first;
    if (span <= 0) span += 360.0;
    double off = t - p0.first;
    if (off < 0) off += 360.0;
    if (span > 10.0) continue;  // outside the other trace's arc
    const double rbi = p0.second + (p1.second - p0.second) * (span > 0 ? off / span : 0.0);
    h = std::max(h, std::abs(ra[i] - rbi));
  }
  return h;
}

}  // namespace

std::vector<double> angles_from_time(std::span<const double> time_s, double start_deg,
                                     double feed_mm_per_min, double radius_mm, Direction d) {
  if (!(radius_mm > 0) || !(feed_mm_per_min > 0))
    throw InputError(fmt::format("circle: radius {} mm and feed {} mm/min must be > 0", radius_mm,
                                 feed_mm_per_min));
  const double rate_deg_s =
      feed_mm_per_min / 60.0 / radius_mm / deg * (d == Direction::ccw ? 1 : -1);
  std::vector<double> out;
  out.reserve(time_s.size());
  for (double t : time_s) out.push_back(start_deg + rate_deg_s * t);
  return out;
}

Result analyse(const Setup& setup, std::span<const Trace> traces) {
  validate(setup, traces);
  Result res;
  const bool both = traces.size() == 2;
  const std::string ax = axis_names(setup.plane);
  const std::string u(1, ax[0]), v(1, ax[1]);

  // ISO 230-4 values.
  for (const auto& t : traces) {
    const Circle own = lsq_circle(std::span(&t, 1));
    (t.direction == Direction::cw ? res.iso.G_cw_um : res.iso.G_ccw_um) = pv(own.residual);
    res.iso.arc_deg = std::min(res.iso.arc_deg, coverage_deg(t.angle_deg));
  }
  const Circle common = lsq_circle(traces);
  res.iso.G_bi_um = pv(common.residual);
  res.iso.centre_u_um = common.cu;
  res.iso.centre_v_um = common.cv;
  res.iso.F_max_um = -1e300, res.iso.F_min_um = 1e300;
  for (const auto& r : common.residual)
    for (double x : r)
      res.iso.F_max_um = std::max(res.iso.F_max_um, x),
      res.iso.F_min_um = std::min(res.iso.F_min_um, x);
  if (both) res.iso.H_um = hysteresis(traces[0], common.residual[0], traces[1], common.residual[1]);

  // The diagnostic fit.
  std::vector<Sample> samples;
  for (const auto& t : traces) {
    const double s = t.direction == Direction::ccw ? 1.0 : -1.0;
    for (std::size_t i = 0; i < t.angle_deg.size(); ++i)
      samples.push_back({t.angle_deg[i] * deg, s, t.deviation_um[i]});
  }
  Model m{setup.radius_mm, setup.spike_decay_deg * deg, setup.cyclic_period_mm.value_or(10.0), {}};
  m.on.fill(true);
  if (!both) {
    // One direction cannot tell squareness from servo mismatch (both sin 2t), nor lateral
    // play from the radius and the scale terms, nor backlash from a centre shift.
    m.on[servo] = m.on[lateral_u] = m.on[lateral_v] = false;
    res.notes.push_back(
        "one direction only: servo mismatch and lateral play are not separable "
        "from squareness and radius, and are not reported");
  }
  if (res.iso.arc_deg < 359.0) {
    m.on[cyclic_u_a] = m.on[cyclic_u_b] = m.on[cyclic_v_a] = m.on[cyclic_v_b] = false;
    m.on[bow_u] = m.on[bow_v] = m.on[spike_u] = m.on[spike_v] = false;
    res.notes.push_back(
        fmt::format("partial arc ({:.0f} degrees): cyclic error, straightness and "
                    "reversal spikes are not fitted",
                    res.iso.arc_deg));
  }
  Fit f;
  if (setup.cyclic_period_mm || !m.on[cyclic_u_a]) {
    f = fit(m, samples);
  } else {  // search the period: the one that leaves the least residual
    double best = 1e300;
    for (int k = 0; k <= 60; ++k) {
      Model trial = m;
      trial.period_mm = setup.cyclic_search_min_mm *
                        std::pow(setup.cyclic_search_max_mm / setup.cyclic_search_min_mm, k / 60.0);
      Fit tf = fit(trial, samples);
      if (tf.rss < best) best = tf.rss, f = tf, m.period_mm = trial.period_mm;
    }
  }
  if (m.on[cyclic_u_a]) res.cyclic_period_mm = m.period_mm;
  res.residual_rms_um = std::sqrt(f.rss / static_cast<double>(samples.size()));

  // Each term's contribution over the samples, its peak-to-valley.
  auto contribution_pv = [&](std::initializer_list<int> terms) {
    Eigen::VectorXd c = Eigen::VectorXd::Zero(f.basis.rows());
    for (int k : terms) c += f.coef[k] * f.basis.col(k);
    return c.maxCoeff() - c.minCoeff();
  };
  const double r_mm = setup.radius_mm;
  const double w = setup.feed_mm_per_min / 60.0 / r_mm;  // rad/s
  auto add = [&](std::string key, std::string name, double value, std::string unit,
                 std::initializer_list<int> terms) {
    Diagnostic d{std::move(key),  std::move(name),        value,
                 std::move(unit), contribution_pv(terms), 0.0};
    d.share_pct = res.iso.G_bi_um > 0 ? 100.0 * d.pv_um / res.iso.G_bi_um : 0.0;
    res.diagnostics.push_back(std::move(d));
  };
  const auto& c = f.coef;
  if (setup.radius_calibrated) add("radius_error", "Radius error", c[radius], "um", {radius});
  add("scale_mismatch", "Scale mismatch " + u + " - " + v, 2000.0 * c[scale] / r_mm, "um/m",
      {scale});
  add("squareness", "Squareness " + ax, -2000.0 * c[squareness] / r_mm, "um/m", {squareness});
  if (m.on[servo])
    add("servo_mismatch", "Servo mismatch (" + v + " lags " + u + ")",
        -2.0 * c[servo] / (r_mm * 1e3 * w) * 1e3, "ms", {servo});
  add("backlash_" + u, "Backlash " + u, 2.0 * c[backlash_u], "um", {backlash_u});
  add("backlash_" + v, "Backlash " + v, 2.0 * c[backlash_v], "um", {backlash_v});
  if (m.on[lateral_u]) {
    add("lateral_play_" + u, "Lateral play " + u, 2.0 * c[lateral_u], "um", {lateral_u});
    add("lateral_play_" + v, "Lateral play " + v, 2.0 * c[lateral_v], "um", {lateral_v});
  }
  if (m.on[spike_u]) {
    add("reversal_spike_" + u, "Reversal spike " + u, c[spike_u], "um", {spike_u});
    add("reversal_spike_" + v, "Reversal spike " + v, c[spike_v], "um", {spike_v});
  }
  if (m.on[cyclic_u_a]) {
    add("cyclic_" + u, fmt::format("Cyclic error {} ({:.2f} mm period)", u, m.period_mm),
        std::hypot(c[cyclic_u_a], c[cyclic_u_b]), "um", {cyclic_u_a, cyclic_u_b});
    add("cyclic_" + v, fmt::format("Cyclic error {} ({:.2f} mm period)", v, m.period_mm),
        std::hypot(c[cyclic_v_a], c[cyclic_v_b]), "um", {cyclic_v_a, cyclic_v_b});
  }
  if (m.on[bow_u]) {
    add("straightness_" + u, "Straightness " + u + " (bow along " + v + ")", c[bow_u], "um",
        {bow_u});
    add("straightness_" + v, "Straightness " + v + " (bow along " + u + ")", c[bow_v], "um",
        {bow_v});
  }
  std::stable_sort(res.diagnostics.begin(), res.diagnostics.end(),
                   [](const Diagnostic& a, const Diagnostic& b) { return a.pv_um > b.pv_um; });
  res.centre_u = {"centre_" + u, "Centre offset " + u, c[centre_u], "um", 0, 0};
  res.centre_v = {"centre_" + v, "Centre offset " + v, c[centre_v], "um", 0, 0};
  return res;
}

}  // namespace cal::circle
