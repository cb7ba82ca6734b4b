// ISO 230-4 circular test and ballbar diagnostics (see circle.hpp, docs/circle.md).
//
// The diagnostic model. In the plane, the tool commanded at angle theta is at
// (u, v) = R (cos theta, sin theta) about the table ball (the pivot). The bar measures
// L = |p_tool - p_pivot|; with the axes in error by (du, dv), to first order in du/R, dv/R:
//     L = sqrt((R cos t + du)^2 + (R sin t + dv)^2) = R + du cos t + dv sin t + O(e^2 / R),
// so dr = du cos(t) + dv sin(t). The neglected term is at most e^2 / (2R): 1 nm for
// e = 10 um at R = 50 mm.
// Each error source gives (du, dv) as a function of the position and the direction of
// travel s (+1 ccw, -1 cw: u' = -R w s sin(theta), v' = R w s cos(theta)):
//   centre offset (cu, cv):         du = cu, dv = cv              -> cu cos + cv sin
//   radius error dR:                                              -> dR
//   scale su, sv:                   du = su u, dv = sv v          -> R(su+sv)/2 + R(su-sv)/2 cos 2t
//   squareness a (E_C0Y, > 0 when the angle between +u and +v exceeds 90 deg: the v axis
//   moves along (-a, 1)):           du = -a v                     -> -(a R / 2) sin 2t
//   servo mismatch, v lagging u by tau:  v(t) = v_cmd(t - tau), dv = -tau v'
//                                                                 -> -(tau R w s / 2) sin 2t
//     (s flips with the direction: this separates it from squareness, which does not)
//   backlash bu (lost motion: the axis stays bu/2 behind its direction of travel):
//                                   du = -(bu/2) sign(u') = (bu/2) s sign(sin t)
//                                                                 -> (bu/2) s sign(sin t) cos t
//   backlash bv:                    dv = -(bv/2) sign(v')         -> -(bv/2) s sign(cos t) sin t
//   lateral play pu (u shifts by pu/2 with the direction of v):  du = (pu/2) sign(v')
//                                                                 -> (pu/2) s |cos t|
//   lateral play pv (v shifts with the direction of u):  dv = (pv/2) sign(u')
//                                                                 -> -(pv/2) s |sin t|
//   reversal spike of u (a transient of the following error after each reversal of u, at
//   t = 0 and pi, decaying with the angle d travelled since; positive outwards): at the
//   reversal the u direction is radial (|cos t| = 1 - d^2/2), so to first order in the
//   decay angle phi                -> A sum exp(-d/phi), d = s (t - t_r) mod 2 pi
//   cyclic error of u, period p:    du = a sin(2 pi u / p) + b cos(2 pi u / p)
//                                  -> cos t [a sin(2 pi R cos t / p) + b cos(2 pi R cos t / p)]
//   straightness, a bow of u along v (du = k v^2 / R^2, k the bow at the ends of the travel):
//                                  -> k sin^2 t cos t;  of v along u: k cos^2 t sin t
// The coefficients are fitted by linear least squares over all samples of both directions,
// by the normal equations (the basis is small and fixed; the data up to 2 x 36,000 samples),
// with the columns scaled to unit norm before the LDLT solve.
#include "cal/analysis/circle.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "cal/analysis/error.hpp"
#include "circle_dynamics.hpp"

namespace cal::circle {
namespace {

constexpr double pi = std::numbers::pi;
constexpr double deg = pi / 180.0;
constexpr std::size_t min_samples = 20;

double sgn(double x) { return x > 0 ? 1.0 : x < 0 ? -1.0 : 0.0; }
double sign_of(Direction d) { return d == Direction::ccw ? 1.0 : -1.0; }
const char* name_of(Direction d) { return d == Direction::cw ? "cw" : "ccw"; }

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
  cyclic_u_a,  // the four cyclic columns are contiguous: the period search replaces them only
  cyclic_u_b,
  cyclic_v_a,
  cyclic_v_b,
  bow_u,
  bow_v,
  term_count
};
constexpr int cyclic_first = cyclic_u_a, cyclic_count = 4;
constexpr std::array<const char*, term_count> term_names = {"centre offset (first axis)",
                                                            "centre offset (second axis)",
                                                            "radius error",
                                                            "scale mismatch",
                                                            "squareness",
                                                            "servo mismatch",
                                                            "backlash (first axis)",
                                                            "backlash (second axis)",
                                                            "lateral play (first axis)",
                                                            "lateral play (second axis)",
                                                            "reversal spike (first axis)",
                                                            "reversal spike (second axis)",
                                                            "cyclic error (first axis)",
                                                            "cyclic error (first axis)",
                                                            "cyclic error (second axis)",
                                                            "cyclic error (second axis)",
                                                            "straightness (first axis)",
                                                            "straightness (second axis)"};

struct Model {
  double r_mm, phi_rad;
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

  // The terms that do not depend on the cyclic period (the cyclic ones are left at 0).
  std::array<double, term_count> fixed_basis(double t, double s) const {
    const double c = std::cos(t), n = std::sin(t);
    return {c,
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
            0.0,
            0.0,
            0.0,
            0.0,
            n * n * c,
            c * c * n};
  }
};

struct Solution {
  Eigen::VectorXd coef;                    // per term (0 where off or dropped)
  std::array<bool, term_count> dropped{};  // active, but not separable from earlier terms
  double rss = 0.0;                        // from the normal equations (for comparing periods)
};

// Solves the normal equations (scaled to a unit diagonal) by a Cholesky factorisation in term
// order that skips a column whose part independent of the earlier columns is below 1 % of its
// norm squared (a variance inflation above 100; on a full circle every term keeps 10 % or more):
// the data cannot separate that term (e.g. the backlash of an axis that does not reverse within
// a partial arc, which is then a centre shift), so it is dropped, not guessed.
Solution solve_in_order(const Eigen::MatrixXd& ata, const Eigen::VectorXd& aty,
                        const std::array<bool, term_count>& on) {
  constexpr int n = term_count;
  const Eigen::VectorXd sc = ata.diagonal().cwiseSqrt().cwiseMax(1e-300).cwiseInverse();
  const Eigen::MatrixXd a = sc.asDiagonal() * ata * sc.asDiagonal();
  const Eigen::VectorXd b = sc.asDiagonal() * aty;
  Solution out;
  std::array<bool, n> use{};
  Eigen::MatrixXd l = Eigen::MatrixXd::Zero(n, n);
  for (int j = 0; j < n; ++j) {
    if (!on[static_cast<std::size_t>(j)]) continue;
    double d = a(j, j);
    for (int k = 0; k < j; ++k) d -= l(j, k) * l(j, k);
    if (!(d > 1e-2 * a(j, j))) {
      out.dropped[static_cast<std::size_t>(j)] = true;
      continue;
    }
    use[static_cast<std::size_t>(j)] = true;
    l(j, j) = std::sqrt(d);
    for (int i = j + 1; i < n; ++i) {
      double x = a(i, j);
      for (int k = 0; k < j; ++k) x -= l(i, k) * l(j, k);
      l(i, j) = x / l(j, j);
    }
  }
  Eigen::VectorXd z = Eigen::VectorXd::Zero(n), x = Eigen::VectorXd::Zero(n);
  for (int i = 0; i < n; ++i) {  // L z = b
    if (!use[static_cast<std::size_t>(i)]) continue;
    double t = b[i];
    for (int k = 0; k < i; ++k) t -= l(i, k) * z[k];
    z[i] = t / l(i, i);
  }
  for (int i = n - 1; i >= 0; --i) {  // L' x = z
    if (!use[static_cast<std::size_t>(i)]) continue;
    double t = z[i];
    for (int k = i + 1; k < n; ++k) t -= l(k, i) * x[k];
    x[i] = t / l(i, i);
  }
  out.coef = sc.asDiagonal() * x;
  // rss = |y - A c|^2 = y'y - 2 c'A'y + c'A'A c; the caller adds y'y.
  out.rss = -2 * out.coef.dot(aty) + out.coef.dot(ata * out.coef);
  return out;
}

// The design matrix of one sample set, with the Gram matrix of the fixed columns computed once:
// a trial cyclic period only recomputes the four cyclic columns and their Gram rows.
class Design {
 public:
  Design(const Model& m, std::span<const Sample> samples, std::size_t stride) : m_(m) {
    const auto n = static_cast<Eigen::Index>((samples.size() + stride - 1) / stride);
    a_.resize(n, term_count);
    y_.resize(n);
    cos_.resize(n);
    sin_.resize(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const auto& smp = samples[static_cast<std::size_t>(i) * stride];
      const auto b = m.fixed_basis(smp.theta, smp.s);
      for (int k = 0; k < term_count; ++k)
        a_(i, k) = m.on[static_cast<std::size_t>(k)] ? b[static_cast<std::size_t>(k)] : 0.0;
      y_[i] = smp.y;
      cos_[i] = std::cos(smp.theta);
      sin_[i] = std::sin(smp.theta);
    }
    ata_ = a_.transpose() * a_;
    aty_ = a_.transpose() * y_;
    yty_ = y_.squaredNorm();
  }

  Solution solve(double period_mm) {
    if (m_.on[cyclic_first]) set_cyclic(period_mm);
    Solution out = solve_in_order(ata_, aty_, m_.on);
    out.rss += yty_;
    return out;
  }

  const Eigen::MatrixXd& matrix() const { return a_; }
  const Eigen::VectorXd& y() const { return y_; }

 private:
  void set_cyclic(double period_mm) {
    const double k = 2 * pi * m_.r_mm / period_mm;
    for (Eigen::Index i = 0; i < a_.rows(); ++i) {
      const double pu = k * cos_[i], pv = k * sin_[i];
      a_(i, cyclic_u_a) = cos_[i] * std::sin(pu);
      a_(i, cyclic_u_b) = cos_[i] * std::cos(pu);
      a_(i, cyclic_v_a) = sin_[i] * std::sin(pv);
      a_(i, cyclic_v_b) = sin_[i] * std::cos(pv);
    }
    const auto cyc = a_.middleCols(cyclic_first, cyclic_count);
    const Eigen::MatrixXd cross = cyc.transpose() * a_;  // 4 x terms
    ata_.middleRows(cyclic_first, cyclic_count) = cross;
    ata_.middleCols(cyclic_first, cyclic_count) = cross.transpose();
    aty_.segment(cyclic_first, cyclic_count) = cyc.transpose() * y_;
  }

  Model m_;
  Eigen::MatrixXd a_;
  Eigen::VectorXd y_, cos_, sin_, aty_;
  Eigen::MatrixXd ata_;
  double yty_ = 0.0;
};

// The cyclic period that leaves the least residual. The residual dips where the trial period
// keeps the phase along the whole travel 2R: a period off by dp drifts by 2 pi 2R dp / p^2,
// half a cycle when dp / p = p / (4R). So the grid steps by p / (8R) (at most 800 steps), on
// a decimated copy of the samples (>= 8 samples per shortest period along the path), and the
// best grid point is refined by golden section on all samples.
double search_period(const Model& m, std::span<const Sample> samples, const Setup& setup,
                     Design& full) {
  const double p_min = setup.cyclic_search_min_mm, p_max = setup.cyclic_search_max_mm;
  const double path_per_sample_mm =
      2 * pi * setup.radius_mm / std::max(1.0, static_cast<double>(samples.size()) / 2.0);
  const auto stride = static_cast<std::size_t>(
      std::clamp(std::floor(p_min / (8 * path_per_sample_mm)), 1.0,
                 std::max(1.0, static_cast<double>(samples.size()) / 2000.0)));
  Design coarse(m, samples, stride);
  const double min_step = std::log(p_max / p_min) / 800.0;
  double best_p = p_min, best_rss = 1e300, best_step = min_step;
  for (double p = p_min, step = min_step; p <= p_max * (1 + 1e-12); p *= std::exp(step)) {
    step = std::max(min_step, p / (8 * setup.radius_mm));
    if (const double rss = coarse.solve(p).rss; rss < best_rss)
      best_rss = rss, best_p = p, best_step = step;
  }
  // Golden section over log p in [best / e^step, best * e^step].
  const double g = (std::sqrt(5.0) - 1) / 2;
  double lo = std::log(best_p) - best_step, hi = std::log(best_p) + best_step;
  double x1 = hi - g * (hi - lo), x2 = lo + g * (hi - lo);
  double f1 = full.solve(std::exp(x1)).rss, f2 = full.solve(std::exp(x2)).rss;
  for (int i = 0; i < 24; ++i) {
    if (f1 < f2) {
      hi = x2, x2 = x1, f2 = f1, x1 = hi - g * (hi - lo), f1 = full.solve(std::exp(x1)).rss;
    } else {
      lo = x1, x1 = x2, f1 = f2, x2 = lo + g * (hi - lo), f2 = full.solve(std::exp(x2)).rss;
    }
  }
  return std::exp((lo + hi) / 2);
}

// The smallest arc covering the angles: 360 minus the largest gap between sorted angles.
double coverage_deg(std::span<const double> angles) {
  std::vector<double> a;
  a.reserve(angles.size());
  for (double x : angles) a.push_back(std::fmod(std::fmod(x, 360.0) + 360.0, 360.0));
  std::sort(a.begin(), a.end());
  double gap = a.front() + 360.0 - a.back();
  for (std::size_t i = 1; i < a.size(); ++i) gap = std::max(gap, a[i] - a[i - 1]);
  return 360.0 - gap;
}

void validate_setup(const Setup& setup) {
  if (!(setup.radius_mm > 0) || !std::isfinite(setup.radius_mm))
    throw InputError(fmt::format("circle: radius {} mm must be > 0", setup.radius_mm));
  if (!(setup.feed_mm_per_min > 0) || !std::isfinite(setup.feed_mm_per_min))
    throw InputError(fmt::format("circle: feed {} mm/min must be > 0", setup.feed_mm_per_min));
  if (setup.calibrated_radius_mm &&
      (!(*setup.calibrated_radius_mm > 0) || !std::isfinite(*setup.calibrated_radius_mm)))
    throw InputError(
        fmt::format("circle: calibrated radius {} mm must be > 0", *setup.calibrated_radius_mm));
  if (setup.cyclic_period_mm && !(*setup.cyclic_period_mm > 0))
    throw InputError(
        fmt::format("circle: cyclic period {} mm must be > 0", *setup.cyclic_period_mm));
  if (!(setup.cyclic_search_min_mm > 0) ||
      !(setup.cyclic_search_max_mm > setup.cyclic_search_min_mm))
    throw InputError(fmt::format("circle: cyclic search range {}..{} mm must be 0 < min < max",
                                 setup.cyclic_search_min_mm, setup.cyclic_search_max_mm));
  if (!(setup.spike_decay_deg > 0))
    throw InputError(
        fmt::format("circle: spike decay {} degrees must be > 0", setup.spike_decay_deg));
  if (!(setup.stick_slip_window_deg > 1.0 && setup.stick_slip_window_deg <= 45.0))
    throw InputError(fmt::format("circle: stick-slip window {} degrees must be > 1 and <= 45",
                                 setup.stick_slip_window_deg));
}

void validate_trace(const Trace& t) {
  const char* name = name_of(t.direction);
  if (t.angle_deg.size() != t.deviation_um.size())
    throw InputError(fmt::format("circle: {} trace has {} angles but {} deviations", name,
                                 t.angle_deg.size(), t.deviation_um.size()));
  if (t.angle_deg.size() < min_samples)
    throw InputError(fmt::format("circle: {} trace has {} samples, at least {} needed", name,
                                 t.angle_deg.size(), min_samples));
  for (std::size_t i = 0; i < t.angle_deg.size(); ++i)
    if (!std::isfinite(t.angle_deg[i]) || !std::isfinite(t.deviation_um[i]))
      throw InputError(fmt::format("circle: {} trace sample {} is not finite (angle {}, {} um)",
                                   name, i, t.angle_deg[i], t.deviation_um[i]));
  if (const double arc = coverage_deg(t.angle_deg); arc < 180.0 - 1e-9)
    throw InputError(
        fmt::format("circle: {} trace covers {:.1f} degrees, at least 180 needed", name, arc));
}

void validate(const Setup& setup, std::span<const Trace> traces) {
  if (traces.empty()) throw InputError("circle: no trace given");
  if (traces.size() > 2)
    throw InputError(fmt::format("circle: {} traces given, at most 2 (cw, ccw)", traces.size()));
  if (traces.size() == 2 && traces[0].direction == traces[1].direction)
    throw InputError(
        fmt::format("circle: two traces in the same direction ({})", name_of(traces[0].direction)));
  validate_setup(setup);
  for (const auto& t : traces) validate_trace(t);
}

// Least-squares circle, linearised as the bar length itself (dr = r0 + cu cos + cv sin, the
// first-order form above; the exact circle differs by O(e^2 / R)), and the radial deviations
// about its centre, from the nominal radius.
struct Circle {
  double cu = 0, cv = 0;
  std::vector<std::vector<double>> residual;  // per trace, in the trace's order
};

Circle lsq_circle(std::span<const Trace> traces, double offset_um) {
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d aty = Eigen::Vector3d::Zero();
  for (const auto& t : traces)
    for (std::size_t i = 0; i < t.angle_deg.size(); ++i) {
      const Eigen::Vector3d a(1.0, std::cos(t.angle_deg[i] * deg), std::sin(t.angle_deg[i] * deg));
      ata += a * a.transpose();
      aty += a * (t.deviation_um[i] + offset_um);
    }
  const Eigen::Vector3d x = ata.ldlt().solve(aty);
  Circle c{x[1], x[2], {}};
  for (const auto& t : traces) {
    std::vector<double> r;
    r.reserve(t.angle_deg.size());
    for (std::size_t i = 0; i < t.angle_deg.size(); ++i)
      r.push_back(t.deviation_um[i] + offset_um - x[1] * std::cos(t.angle_deg[i] * deg) -
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
  pts.reserve(b.angle_deg.size());
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

Iso230_4 iso_values(std::span<const Trace> traces, double offset_um) {
  Iso230_4 iso;
  for (const auto& t : traces) {
    const Circle own = lsq_circle(std::span(&t, 1), offset_um);
    (t.direction == Direction::cw ? iso.G_cw_um : iso.G_ccw_um) = pv(own.residual);
    iso.arc_deg = std::min(iso.arc_deg, coverage_deg(t.angle_deg));
  }
  const Circle common = lsq_circle(traces, offset_um);
  iso.G_bi_um = pv(common.residual);
  iso.centre_u_um = common.cu;
  iso.centre_v_um = common.cv;
  iso.F_max_um = -1e300, iso.F_min_um = 1e300;
  for (const auto& r : common.residual)
    for (double x : r)
      iso.F_max_um = std::max(iso.F_max_um, x), iso.F_min_um = std::min(iso.F_min_um, x);
  if (traces.size() == 2)
    iso.H_um = hysteresis(traces[0], common.residual[0], traces[1], common.residual[1]);
  return iso;
}

// G of y (all samples, one common LSQ circle): the same as iso_values' G_bi, on a vector.
class CircularDeviation {
 public:
  explicit CircularDeviation(const Eigen::MatrixXd& a)
      : a_(a.leftCols<3>()), ldlt_((a_.transpose() * a_).eval()) {}
  double operator()(const Eigen::VectorXd& y) const {
    const Eigen::Vector3d x = ldlt_.solve(a_.transpose() * y);
    const Eigen::VectorXd r = y - a_.leftCols<2>() * x.head<2>();  // about the centre
    return r.maxCoeff() - r.minCoeff();
  }

 private:
  Eigen::MatrixXd a_;  // the design's first columns: cos, sin, 1
  Eigen::LDLT<Eigen::Matrix3d> ldlt_;
};

std::vector<Sample> flatten(std::span<const Trace> traces, double offset_um) {
  std::vector<Sample> samples;
  for (const auto& t : traces) {
    const double s = sign_of(t.direction);
    for (std::size_t i = 0; i < t.angle_deg.size(); ++i)
      samples.push_back({t.angle_deg[i] * deg, s, t.deviation_um[i] + offset_um});
  }
  return samples;
}

// Which terms the data can carry, with a note for each that it cannot.
Model choose_terms(const Setup& setup, bool both, double arc_deg, std::vector<std::string>& notes) {
  Model m{setup.radius_mm, setup.spike_decay_deg * deg, {}};
  m.on.fill(true);
  if (!both) {
    // One direction cannot tell squareness from servo mismatch (both sin 2t), nor lateral
    // play from the radius and the scale terms.
    m.on[servo] = m.on[lateral_u] = m.on[lateral_v] = false;
    notes.push_back(
        "one direction only: servo mismatch and lateral play are not separable "
        "from squareness and radius, and are not reported");
  }
  if (arc_deg < 359.0) {
    // A simple bow needs the whole diameter (as in the usual ballbar software, which shows no
    // straightness for a partial arc). The cyclic and spike terms stay: they are local to the
    // axis' position and reversals, and the separability check drops one the arc cannot carry.
    for (int k : {bow_u, bow_v}) m.on[static_cast<std::size_t>(k)] = false;
    notes.push_back(
        fmt::format("partial arc ({:.0f} degrees): straightness is not fitted", arc_deg));
  }
  if (!setup.radius_calibrated)
    notes.push_back("uncalibrated bar: the radius error is fitted but not reported");
  return m;
}

// The ranked diagnostics from the fitted coefficients.
class Reporter {
 public:
  Reporter(Result& res, const Model& m, const Design& d, const Eigen::VectorXd& coef,
           const CircularDeviation& g)
      : res_(res), m_(m), d_(d), c_(coef), g_(g), y_(d.y()) {}

  void add(std::string key, std::string name, double value, std::string unit,
           std::initializer_list<int> terms) {
    for (int k : terms)
      if (!on(k)) return;  // off, or dropped as not separable
    Eigen::VectorXd contrib = Eigen::VectorXd::Zero(d_.matrix().rows());
    for (int k : terms) contrib += c_[k] * d_.matrix().col(k);
    push({std::move(key), std::move(name), value, std::move(unit), 0.0, 0.0, 0.0, {}}, contrib);
  }
  // A diagnostic found in the residual (stick-slip, vibration): its contribution is given.
  void add(const dynamics::Found& f) {
    const Eigen::Map<const Eigen::VectorXd> contrib(
        f.contribution.data(), static_cast<Eigen::Index>(f.contribution.size()));
    push({f.key, f.name, f.value, f.unit, 0.0, 0.0, 0.0, f.frequency_hz}, contrib);
  }
  bool on(int k) const { return m_.on[static_cast<std::size_t>(k)]; }
  double c(int k) const { return c_[k]; }

 private:
  Result& res_;
  const Model& m_;
  const Design& d_;
  const Eigen::VectorXd& c_;
  const CircularDeviation& g_;
  Eigen::VectorXd y_;

  // PV of the contribution, its share of G, and what G would be without it (docs/circle.md).
  void push(Diagnostic dg, const Eigen::Ref<const Eigen::VectorXd>& contrib) {
    dg.pv_um = contrib.maxCoeff() - contrib.minCoeff();
    const double g_bi = res_.iso.G_bi_um;
    dg.share_pct = g_bi > 0 ? 100.0 * dg.pv_um / g_bi : 0.0;
    dg.g_reduction_um = g_bi - g_(y_ - contrib);
    res_.diagnostics.push_back(std::move(dg));
  }
};

void report(Reporter& r, const Setup& setup, const std::string& ax, double period_mm) {
  const std::string u(1, ax[0]), v(1, ax[1]);
  const double r_mm = setup.radius_mm;
  const double w_rad_s = setup.feed_mm_per_min / 60.0 / r_mm;
  if (setup.radius_calibrated) r.add("radius_error", "Radius error", r.c(radius), "um", {radius});
  // scale: R (su - sv) / 2 um -> (su - sv) = 2 c / R [um/mm] = 2000 c / R [um/m]
  r.add("scale_mismatch", "Scale mismatch " + u + " - " + v, 2000.0 * r.c(scale) / r_mm, "um/m",
        {scale});
  r.add("squareness", "Squareness " + ax, -2000.0 * r.c(squareness) / r_mm, "um/m", {squareness});
  if (r.on(servo))  // c = -tau R[um] w / 2 -> tau = -2 c / (R w), in ms
    r.add("servo_mismatch", "Servo mismatch (" + v + " lags " + u + ")",
          -2.0 * r.c(servo) / (r_mm * 1e3 * w_rad_s) * 1e3, "ms", {servo});
  r.add("backlash_" + u, "Backlash " + u, 2.0 * r.c(backlash_u), "um", {backlash_u});
  r.add("backlash_" + v, "Backlash " + v, 2.0 * r.c(backlash_v), "um", {backlash_v});
  if (r.on(lateral_u)) {
    r.add("lateral_play_" + u, "Lateral play " + u, 2.0 * r.c(lateral_u), "um", {lateral_u});
    r.add("lateral_play_" + v, "Lateral play " + v, 2.0 * r.c(lateral_v), "um", {lateral_v});
  }
  if (r.on(spike_u)) {
    r.add("reversal_spike_" + u, "Reversal spike " + u, r.c(spike_u), "um", {spike_u});
    r.add("reversal_spike_" + v, "Reversal spike " + v, r.c(spike_v), "um", {spike_v});
  }
  if (r.on(cyclic_u_a)) {
    r.add("cyclic_" + u, fmt::format("Cyclic error {} ({:.2f} mm period)", u, period_mm),
          std::hypot(r.c(cyclic_u_a), r.c(cyclic_u_b)), "um", {cyclic_u_a, cyclic_u_b});
    r.add("cyclic_" + v, fmt::format("Cyclic error {} ({:.2f} mm period)", v, period_mm),
          std::hypot(r.c(cyclic_v_a), r.c(cyclic_v_b)), "um", {cyclic_v_a, cyclic_v_b});
  }
  if (r.on(bow_u)) {
    r.add("straightness_" + u, "Straightness " + u + " (bow along " + v + ")", r.c(bow_u), "um",
          {bow_u});
    r.add("straightness_" + v, "Straightness " + v + " (bow along " + u + ")", r.c(bow_v), "um",
          {bow_v});
  }
}

}  // namespace

std::vector<double> angles_from_time(std::span<const double> time_s, double start_deg,
                                     double feed_mm_per_min, double radius_mm, Direction d) {
  if (!(radius_mm > 0) || !(feed_mm_per_min > 0))
    throw InputError(fmt::format("circle: radius {} mm and feed {} mm/min must be > 0", radius_mm,
                                 feed_mm_per_min));
  // The tool runs along the circle at the feed: d(theta)/dt = F / R (rad/s, F in mm/s).
  const double rate_deg_s = feed_mm_per_min / 60.0 / radius_mm / deg * sign_of(d);
  std::vector<double> out;
  out.reserve(time_s.size());
  for (double t : time_s) out.push_back(start_deg + rate_deg_s * t);
  return out;
}

Trace trace_from_time(const Setup& setup, Direction d, std::span<const double> time_s,
                      std::span<const double> deviation_um) {
  validate_setup(setup);
  if (time_s.size() != deviation_um.size())
    throw InputError(fmt::format("circle: {} trace has {} times but {} deviations", name_of(d),
                                 time_s.size(), deviation_um.size()));
  if (!(setup.arc_deg >= 180.0 && setup.arc_deg <= 360.0))
    throw InputError(fmt::format("circle: arc {} degrees must be 180..360", setup.arc_deg));
  if (!(setup.overshoot_deg >= 0.0) || !std::isfinite(setup.overshoot_deg))
    throw InputError(fmt::format("circle: overshoot {} degrees must be >= 0", setup.overshoot_deg));
  const double os = setup.overshoot_deg, s = sign_of(d);
  const double move_start =
      d == Direction::ccw ? setup.start_deg : setup.start_deg + setup.arc_deg + 2 * os;
  const auto angles =
      angles_from_time(time_s, move_start, setup.feed_mm_per_min, setup.radius_mm, d);
  Trace t{d, {}, {}};
  const double tol = 1e-9;
  for (std::size_t i = 0; i < angles.size(); ++i) {
    if (!std::isfinite(time_s[i]))
      throw InputError(fmt::format("circle: {} trace time {} is not finite", name_of(d), i));
    const double travelled = s * (angles[i] - move_start);  // degrees along the move
    if (travelled < os - tol || travelled > os + setup.arc_deg + tol) continue;
    t.angle_deg.push_back(angles[i]);
    t.deviation_um.push_back(deviation_um[i]);
  }
  if (t.angle_deg.size() < min_samples)
    throw InputError(fmt::format(
        "circle: {} trace keeps {} samples after trimming the {} degree overshoot arcs, at least "
        "{} needed (is the time from the start of the arc move?)",
        name_of(d), t.angle_deg.size(), os, min_samples));
  return t;
}

Trace trace_from_samples(const Setup& setup, Direction d, std::span<const double> deviation_um) {
  if (!(setup.sample_rate_hz > 0) || !std::isfinite(setup.sample_rate_hz))
    throw InputError(fmt::format("circle: sample rate {} Hz must be > 0", setup.sample_rate_hz));
  std::vector<double> time_s(deviation_um.size());
  for (std::size_t i = 0; i < time_s.size(); ++i)
    time_s[i] = static_cast<double>(i) / setup.sample_rate_hz;
  return trace_from_time(setup, d, time_s, deviation_um);
}

Result analyse(const Setup& setup, std::span<const Trace> traces) {
  validate(setup, traces);
  Result res;
  // Deviations from the nominal radius: the bar reads 0 at its calibrated length.
  const double offset_um =
      1e3 * (setup.calibrated_radius_mm.value_or(setup.radius_mm) - setup.radius_mm);
  res.iso = iso_values(traces, offset_um);

  const auto samples = flatten(traces, offset_um);
  const Model m = choose_terms(setup, traces.size() == 2, res.iso.arc_deg, res.notes);
  Design full(m, samples, 1);
  double period_mm = setup.cyclic_period_mm.value_or(10.0);
  if (m.on[cyclic_first] && !setup.cyclic_period_mm)
    period_mm = search_period(m, samples, setup, full);
  const Solution sol = full.solve(period_mm);
  Model reported = m;
  for (int k = 0; k < term_count; ++k)
    if (sol.dropped[static_cast<std::size_t>(k)]) reported.on[static_cast<std::size_t>(k)] = false;
  for (int k = 0; k < term_count; ++k)
    if (sol.dropped[static_cast<std::size_t>(k)])
      res.notes.push_back(
          fmt::format("{}: not separable from the other terms on these traces, not reported",
                      term_names[static_cast<std::size_t>(k)]));
  if (reported.on[cyclic_first]) res.cyclic_period_mm = period_mm;
  const Eigen::VectorXd resid = full.y() - full.matrix() * sol.coef;
  const std::string ax = axis_names(setup.plane);

  // Stick-slip and vibration live in what the geometric model leaves.
  std::vector<dynamics::TraceResidual> residuals;
  for (Eigen::Index at = 0; const auto& t : traces) {
    dynamics::TraceResidual tr{.s = sign_of(t.direction)};
    for (std::size_t i = 0; i < t.angle_deg.size(); ++i, ++at) {
      tr.theta_rad.push_back(t.angle_deg[i] * deg);
      tr.r_um.push_back(resid[at]);
    }
    residuals.push_back(std::move(tr));
  }
  const dynamics::Settings dyn{.radius_mm = setup.radius_mm,
                               .feed_mm_per_min = setup.feed_mm_per_min,
                               .window_deg = setup.stick_slip_window_deg,
                               .u = ax[0],
                               .v = ax[1]};
  const auto vibration = dynamics::vibration(dyn, residuals, res.notes);
  const auto stick_slip = dynamics::stick_slip(dyn, residuals, res.notes);
  double ss = 0.0;  // what is left after the geometric model and a vibration
  for (const auto& tr : residuals)
    for (double x : tr.r_um) ss += x * x;
  res.residual_rms_um = std::sqrt(ss / static_cast<double>(samples.size()));

  const CircularDeviation g(full.matrix());
  Reporter rep(res, reported, full, sol.coef, g);
  report(rep, setup, ax, period_mm);
  if (vibration) rep.add(*vibration);
  for (const auto& f : stick_slip) rep.add(f);
  // Ranked by what correcting each would gain (G with its term removed), as a ballbar user
  // reads the list: the first is the one to fix first. Equal gains (terms absent) by PV.
  std::stable_sort(res.diagnostics.begin(), res.diagnostics.end(),
                   [](const Diagnostic& a, const Diagnostic& b) {
                     const double ga = std::round(a.g_reduction_um * 1e3);
                     const double gb = std::round(b.g_reduction_um * 1e3);
                     return ga != gb ? ga > gb : a.pv_um > b.pv_um;
                   });
  const std::string u(1, ax[0]), v(1, ax[1]);
  res.centre_u = {"centre_" + u, "Centre offset " + u, sol.coef[centre_u], "um", 0, 0, 0, {}};
  res.centre_v = {"centre_" + v, "Centre offset " + v, sol.coef[centre_v], "um", 0, 0, 0, {}};
  return res;
}

}  // namespace cal::circle
