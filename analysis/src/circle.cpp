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
// by the normal equations, accumulated over blocks of samples (the basis is small and fixed, so
// the fit holds an 18 x 18 Gram matrix, never the n x 18 design: issue 32), with the columns
// scaled to unit norm before the Cholesky solve. The diagnostics' peak-to-valley and gains come
// from one more pass over the samples (Reporter).
#include "cal/analysis/circle.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <numbers>
#include <utility>

#include "cal/analysis/angle_reduce.hpp"
#include "cal/analysis/circle_records.hpp"
#include "cal/analysis/circle_search.hpp"
#include "cal/analysis/circle_source.hpp"
#include "cal/analysis/enum_names.hpp"
#include "cal/analysis/error.hpp"
#include "cal/analysis/outer_sums.hpp"
#include "cal/analysis/sin_cos.hpp"
#include "circle_dynamics.hpp"

namespace cal::circle {
namespace {

constexpr double pi = std::numbers::pi;
constexpr double deg = pi / 180.0;
constexpr std::size_t min_samples = 20;

double sgn(double x) { return x > 0 ? 1.0 : x < 0 ? -1.0 : 0.0; }

// cos x and sin x in one call, without the library's (sin_cos.hpp: within 0.79 ulp, 1.07 where
// the value is near 0, where glibc's are within 0.52; its sincos was 10 - 14 % of a long run's
// replay at five or six calls a sample: issue 32). Every sine and cosine of the fit's passes is
// this one's, so a record rebuilt is the record held, bit for bit.
std::pair<double, double> cos_sin(double x) {
  const SinCos sc = sin_cos(x);
  return {sc.c, sc.s};
}
// cos x and sin x for |x| <= 1.5 by their Taylor series to x^22 and x^23 (the rest is below
// 1.5^24 / 24! = 3e-20), branch-free so that a loop of them is vectorised.
inline void cos_sin_small(double x, double& c, double& s) {
  constexpr int terms = 12;
  constexpr auto coef = [] {  // (-1)^m / (2m)! and (-1)^m / (2m + 1)!
    std::array<std::array<double, 2>, terms> a{};
    double f = 1.0;
    for (int m = 0; m < terms; ++m) {
      if (m > 0) f *= -1.0 / ((2.0 * m - 1) * (2.0 * m));
      a[static_cast<std::size_t>(m)] = {f, f / (2.0 * m + 1)};
    }
    return a;
  }();
  const double x2 = x * x;
  double pc = coef[terms - 1][0], ps = coef[terms - 1][1];
  for (int m = terms - 2; m >= 0; --m)
    pc = pc * x2 + coef[static_cast<std::size_t>(m)][0],
    ps = ps * x2 + coef[static_cast<std::size_t>(m)][1];
  c = pc, s = ps * x;
}

double sign_of(Direction d) { return d == Direction::ccw ? 1.0 : -1.0; }
const char* name_of(Direction d) { return d == Direction::cw ? "cw" : "ccw"; }

// What the fit keeps of a sample (40 bytes; a dense row of the design took 144 more): the
// basis is rebuilt from it on every pass over the samples, except the two reversal-spike
// columns (four exponentials), which cost more to rebuild than to keep. The direction is the
// trace's, known from the sample's index (Model::direction).
struct Sample {
  double c, n, y, spike_u, spike_v;  // cos, sin of the angle; deviation
};

std::string axis_names(Plane p) {
  using enum Plane;
  static constexpr cal::EnumName<Plane> kNames[] = {{xy, "XY"}, {yz, "YZ"}, {zx, "ZX"}};
  static_assert(cal::names_every_value(kNames));
  return std::string(cal::name_of(kNames, p, "XY"));
}

enum Term {
  centre_u,  // the first three are the LSQ circle's columns (always on): CircularDeviation
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
// A name for every term: an array given fewer names than term_count holds null pointers.
static_assert(term_names.back() != nullptr);

struct Model {
  double r_mm, phi_rad;
  std::array<bool, term_count> on{};
  // The flattened samples' directions: s_before below index split (the first trace), s_after
  // from it (the second).
  std::size_t split = 0;
  double s_before = 1.0, s_after = 1.0;
  double direction(std::size_t index) const { return index < split ? s_before : s_after; }

  double spike(double theta, double s, double first) const {
    double sum = 0.0;
    for (double tr : {first, first + pi}) {
      double d = fmod_near(s * (theta - tr), 2 * pi);  // std::fmod's value (angle_reduce.hpp)
      if (d < 0) d += 2 * pi;
      sum += std::exp(-d / phi_rad);
    }
    return sum;
  }

  Sample sample(double theta, double s, double y) const {
    const auto [c, n] = cos_sin(theta);
    return {c, n, y, spike(theta, s, 0.0), spike(theta, s, pi / 2)};
  }

  // k = 2 pi R / period: the cyclic columns' wave number along the axes.
  double wave_number(double period_mm) const { return 2 * pi * r_mm / period_mm; }

  // The basis row of a sample in direction s, the terms that are off left at 0; with `cyclic`
  // false the four cyclic columns are left at 0 too, without their sines and cosines (a pass
  // whose cyclic rows of the normal equations come from CyclicSeries: issue 32).
  template <class RowRef>
  void row(const Sample& x, double s, double k, RowRef&& out, bool cyclic = true) const {
    const double c = x.c, n = x.n;
    const double c2 = c * c - n * n, s2 = 2 * c * n;  // cos 2t, sin 2t
    const auto [cu, su] = cyclic ? cos_sin(k * c) : std::pair<double, double>{};
    const auto [cv, sv] = cyclic ? cos_sin(k * n) : std::pair<double, double>{};
    const std::array<double, term_count> b = {c,
                                              n,
                                              1.0,
                                              c2,
                                              s2,
                                              s * s2,
                                              s * sgn(n) * c,
                                              -s * sgn(c) * n,
                                              s * std::abs(c),
                                              -s * std::abs(n),
                                              x.spike_u,
                                              x.spike_v,
                                              c * su,
                                              c * cu,
                                              n * sv,
                                              n * cv,
                                              n * n * c,
                                              c * c * n};
    for (int j = 0; j < term_count; ++j)
      out(j) = on[static_cast<std::size_t>(j)] &&
                       (cyclic || j < cyclic_first || j >= cyclic_first + cyclic_count)
                   ? b[static_cast<std::size_t>(j)]
                   : 0.0;
  }
};

// The samples of each trace: [begin, end) in the flattened samples, and the trace itself.
struct Span {
  const TraceSource* trace;
  std::size_t begin, end;
};

// The fit's samples: the traces flattened in order, sample i of trace t at spans()[t].begin + j.
// Each one's record is held (40 bytes a sample) for a run of at most
// fit_records_held_max_samples samples (circle_records.hpp), and otherwise rebuilt from its trace
// whenever it is read, by the same operations and so to the same values: then the fit holds nothing
// per sample beyond the traces, at the price of a sine, a cosine and four exponentials a sample on
// every pass (issue 32: a 10 kHz circle's records were most of its peak memory).
class Samples {
 public:
  Samples(std::span<const TraceSource> traces, double offset_um, double spike_decay_rad,
          std::size_t held_max)
      : m_{0.0, spike_decay_rad, {}}, offset_um_(offset_um) {
    for (const auto& t : traces) {
      spans_.push_back({&t, size_, size_ + t.size()});
      size_ += t.size();
    }
    if (size_ > held_max) return;
    held_.reserve(size_);
    for (std::size_t i = 0; i < size_; ++i) held_.push_back(make(i, true));
  }

  std::size_t size() const { return size_; }
  const std::vector<Span>& spans() const { return spans_; }
  Sample operator[](std::size_t i) const { return held_.empty() ? make(i, true) : held_[i]; }
  // Cos, sin and deviation only (the spike columns are left 0 when rebuilt): the circle's.
  Sample plain(std::size_t i) const { return held_.empty() ? make(i, false) : held_[i]; }
  // The held records go (40 bytes a sample); the samples are rebuilt from then on.
  void release() { held_ = std::vector<Sample>(); }  // (= {} would keep the capacity)

 private:
  Sample make(std::size_t i, bool spikes) const {
    const Span& sp = spans_.size() > 1 && i >= spans_[1].begin ? spans_[1] : spans_[0];
    const std::size_t j = i - sp.begin;
    const double theta = sp.trace->angle_deg(j) * deg, y = sp.trace->deviation_um(j) + offset_um_;
    if (!spikes) {
      const auto [c, n] = cos_sin(theta);
      return {c, n, y, 0.0, 0.0};
    }
    return m_.sample(theta, sign_of(sp.trace->direction()), y);
  }

  Model m_;  // for its spike columns
  double offset_um_;
  std::vector<Span> spans_;
  std::size_t size_ = 0;
  std::vector<Sample> held_;
};

using Gram = Eigen::Matrix<double, term_count, term_count>;
using TermVector = Eigen::Matrix<double, term_count, 1>;

// The samples in blocks of rows of the design (every stride-th sample): f(block, y, first) with
// the block's first row's index. A pass holds one block (18 kB), never the n x 18 design.
using Block = Eigen::Matrix<double, Eigen::Dynamic, term_count>;
// `each(at, x)`, if given, sees every sample's record as it is read (another pass's per-sample
// work done in this one: each record rebuilt costs a sine, a cosine and four exponentials);
// `cyclic` false leaves the cyclic columns 0 (Model::row).
struct NoHook {
  void operator()(std::size_t, const Sample&) const {}
};
template <class F, class Each = NoHook>
void for_each_block(const Model& m, const Samples& samples, std::size_t stride, double k, F&& f,
                    Each&& each = {}, bool cyclic = true) {
  constexpr std::size_t block_rows = 128;  // 18 kB: the rows are written where they are read
  const std::size_t n = (samples.size() + stride - 1) / stride;
  Block b(static_cast<Eigen::Index>(std::min(n, block_rows)), term_count);
  Eigen::VectorXd y(b.rows());
  for (std::size_t first = 0; first < n; first += block_rows) {
    const auto rows = static_cast<Eigen::Index>(std::min(block_rows, n - first));
    for (Eigen::Index i = 0; i < rows; ++i) {
      const std::size_t at = (first + static_cast<std::size_t>(i)) * stride;
      const Sample x = samples[at];
      each(at, x);
      m.row(x, m.direction(at), k, b.row(i), cyclic);
      y[i] = x.y;
    }
    f(b.topRows(rows), y.head(rows), first);
  }
}

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
Solution solve_in_order(const Gram& ata, const TermVector& aty,
                        const std::array<bool, term_count>& on) {
  constexpr int n = term_count;
  const TermVector sc = ata.diagonal().cwiseSqrt().cwiseMax(1e-300).cwiseInverse();
  const Gram a = sc.asDiagonal() * ata * sc.asDiagonal();
  const TermVector b = sc.asDiagonal() * aty;
  Solution out;
  std::array<bool, n> use{};
  Gram l = Gram::Zero();
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
  TermVector z = TermVector::Zero(), x = TermVector::Zero();
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
  const TermVector coef = sc.asDiagonal() * x;
  out.coef = coef;
  // rss = |y - A c|^2 = y'y - 2 c'A'y + c'A'A c; the caller adds y'y.
  out.rss = -2 * coef.dot(aty) + coef.dot(ata * coef);
  return out;
}

// The four cyclic rows of the normal equations (A'A's and A'y's) at one wave number.
struct CyclicRows {
  Eigen::Matrix<double, cyclic_count, term_count> cross;
  Eigen::Matrix<double, cyclic_count, 1> cty;
};

// The cyclic rows of the normal equations at any wave number k in [k0 - d, k0 + d], from sums
// made in one pass over the samples (issue 32: the period search's refinement took a pass over
// every sample for each of its 10 - 26 trials). With x = k - k0, a cyclic column is
//   c sin(kc) = Im(c e^{i k c}),  c cos(kc) = Re(c e^{i k c}),  c e^{i k c} = sum_q (i x)^q / q!
//   c^{q+1} e^{i k0 c},
// so its products with any other column w (and y) are sum_q (i x)^q / q! S_q, with
// S_q = sum w c^{q+1} e^{i k0 c} summed once; |c| <= 1, so the terms after q are below
// d^{q+1} / (q+1)! sum |w| and the series is cut where that is under 1e-17 of sum |w| (about
// the rounding of the sums themselves). The cyclic columns' own products, by
//   sin^2 a = (1 - cos 2a) / 2, sin a cos a = sin 2a / 2, cos^2 a = (1 + cos 2a) / 2,
//   sin a sin b = (cos(a - b) - cos(a + b)) / 2, sin a cos b = (sin(a + b) + sin(a - b)) / 2, ...
// need sum c^2 e^{2ikc} (series in 2x), sum c n e^{ik(c + n)} and sum c n e^{ik(c - n)} (series
// in x (c +- n), |c +- n| <= sqrt 2), the same way.
class CyclicSeries {
 public:
  // The other columns (all but the four cyclic ones), in term order, and then y.
  static constexpr std::array<int, term_count - cyclic_count> others = {
      centre_u,   centre_v,  radius,    scale,   squareness, servo, backlash_u,
      backlash_v, lateral_u, lateral_v, spike_u, spike_v,    bow_u, bow_v};
  static constexpr std::size_t weights = others.size() + 1;
  static constexpr std::size_t lanes = 16;  // the weights and a 0

  // `d`: the largest |k - k0| asked for.
  CyclicSeries(double k0, double d)
      : k0_(k0),
        q_(terms_for(d)),
        qx_(terms_for(2 * d)),
        qy_(terms_for(std::sqrt(2.0) * d)),
        np_(static_cast<std::size_t>(4 * q_ + lanes)),
        s_(lanes * np_, 0.0),
        xu_(static_cast<std::size_t>(qx_)),
        xv_(static_cast<std::size_t>(qx_)),
        yp_(static_cast<std::size_t>(qy_)),
        ym_(static_cast<std::size_t>(qy_)) {}

  // The number of terms of a series in x^q / q! with |x| <= d that leaves less than 1e-17.
  static int terms_for(double d) {
    int q = 0;
    for (double t = 1.0, tail = 1.0; tail > 1e-17; ++q) {
      t *= d / (q + 1);                                        // d^{q+1} / (q+1)!
      tail = t * (q + 2 > d ? (q + 2) / (q + 2 - d) : 1e300);  // geometric bound of the rest
    }
    return q;
  }

  // One block of rows of the design (the cyclic columns are not read) and its y. Each row's
  // weights w (the other columns, y and a 0: 16, a multiple of the products' tile) and its
  // powers p = (c^{q+1} e^{i k0 c}, n^{q+1} e^{i k0 n} for q < Q, as Re, Im, Re, Im; then w
  // itself), and S += w' p (add_outer_products): the series' sums and the weights' own Gram
  // matrix (the design's normal equations but for the cyclic rows) in one product. The four
  // sums of the cyclic columns' own products as column sums of their powers, over the block.
  template <class B, class Y>
  void add(const B& b, const Y& y) {
    const auto rows = static_cast<std::size_t>(b.rows());
    w_.resize(rows * lanes);
    p_.resize(rows * np_);
    e_.resize(b.rows(), 4);  // cos, sin of k0 c; of k0 n
    const auto q = static_cast<std::size_t>(q_);
    for (std::size_t i = 0; i < rows; ++i) {
      const auto ei = static_cast<Eigen::Index>(i);
      double* w = &w_[i * lanes];
      for (std::size_t j = 0; j + 1 < weights; ++j) w[j] = b(ei, others[j]);
      w[weights - 1] = y[ei];
      w[weights] = 0.0;
      const double c = b(ei, centre_u), n = b(ei, centre_v);
      const auto [cu, su] = cos_sin(k0_ * c);
      const auto [cv, sv] = cos_sin(k0_ * n);
      e_(ei, 0) = cu, e_(ei, 1) = su, e_(ei, 2) = cv, e_(ei, 3) = sv;
      double* p = &p_[i * np_];
      double a0 = c * cu, a1 = c * su, a2 = n * cv, a3 = n * sv;
      for (std::size_t k = 0; k < q; ++k) {
        p[4 * k] = a0, p[4 * k + 1] = a1, p[4 * k + 2] = a2, p[4 * k + 3] = a3;
        a0 *= c, a1 *= c, a2 *= n, a3 *= n;
      }
      std::copy(w, w + lanes, p + 4 * q);
    }
    add_outer_products(s_.data(), w_.data(), p_.data(), rows, lanes, np_);
    // e^{2 i k0 c}, e^{2 i k0 n}, e^{i k0 (c + n)}, e^{i k0 (c - n)} (Re, Im).
    const auto c = b.col(centre_u).array(), n = b.col(centre_v).array();
    const auto eu_re = e_.col(0).array(), eu_im = e_.col(1).array();
    const auto ev_re = e_.col(2).array(), ev_im = e_.col(3).array();
    e2_.resize(b.rows(), 8);
    e2_.col(0).array() = eu_re * eu_re - eu_im * eu_im, e2_.col(1).array() = 2 * eu_re * eu_im;
    e2_.col(2).array() = ev_re * ev_re - ev_im * ev_im, e2_.col(3).array() = 2 * ev_re * ev_im;
    e2_.col(4).array() = eu_re * ev_re - eu_im * ev_im;
    e2_.col(5).array() = eu_re * ev_im + eu_im * ev_re;
    e2_.col(6).array() = eu_re * ev_re + eu_im * ev_im;
    e2_.col(7).array() = eu_im * ev_re - eu_re * ev_im;
    // sum w t^q e (q = 0, 1, ...) of the block's rows into sums[q].
    t_.resize(b.rows());
    const auto sums_of = [&](std::vector<std::complex<double>>& sums, const auto& wt, const auto& t,
                             int e) {
      t_.array() = wt;
      const auto re = e2_.col(e).array(), im = e2_.col(e + 1).array();
      for (auto& sum : sums) {
        sum += std::complex<double>((t_.array() * re).sum(), (t_.array() * im).sum());
        t_.array() *= t;
      }
    };
    sums_of(xu_, c * c, c, 0);
    sums_of(xv_, n * n, n, 2);
    sums_of(yp_, c * n, c + n, 4);
    sums_of(ym_, c * n, c - n, 6);
  }

  // The design's normal equations but for the cyclic rows (left 0), from the weights' Gram
  // matrix summed in add().
  void normal_equations(Gram& ata, TermVector& aty, double& yty) const {
    ata.setZero();
    aty.setZero();
    const auto g = [&](std::size_t j, std::size_t l) { return s_[j * np_ + 4 * q_ + l]; };
    for (std::size_t j = 0; j + 1 < weights; ++j) {
      for (std::size_t l = 0; l + 1 < weights; ++l) ata(others[j], others[l]) = g(j, l);
      aty[others[j]] = g(j, weights - 1);
    }
    yty = g(weights - 1, weights - 1);
  }

  // The cyclic rows at k. `ata`: the design's Gram matrix (its sums of c^2 and n^2).
  CyclicRows rows(double k, const Gram& ata) const {
    const double x = k - k0_;
    CyclicRows out;
    out.cross.setZero();
    out.cty.setZero();
    const auto cross_of = [&](std::size_t first, int a_row, int b_row) {
      for (std::size_t j = 0; j < weights; ++j) {
        const std::complex<double> v = series_at(first, j, x);
        if (j == weights - 1) {
          out.cty[a_row] = v.imag(), out.cty[b_row] = v.real();
        } else {
          const int t = others[j];
          out.cross(a_row, t) = v.imag(), out.cross(b_row, t) = v.real();
        }
      }
    };
    cross_of(0, 0, 1);
    cross_of(2, 2, 3);
    // The 4 x 4 block of the cyclic columns (u_a, u_b, v_a, v_b = rows 0 .. 3).
    const auto square = [&](const std::vector<std::complex<double>>& xs, double sum_sq, int a) {
      const std::complex<double> v = sum_at(xs, 2 * x);  // sum w^2 e^{2 i k w}
      const int ca = cyclic_first + a;
      out.cross(a, ca) = (sum_sq - v.real()) / 2;
      out.cross(a, ca + 1) = out.cross(a + 1, ca) = v.imag() / 2;
      out.cross(a + 1, ca + 1) = (sum_sq + v.real()) / 2;
    };
    square(xu_, ata(centre_u, centre_u), 0);
    square(xv_, ata(centre_v, centre_v), 2);
    const std::complex<double> p = sum_at(yp_, x), m = sum_at(ym_, x);  // sum c n e^{ik(c +- n)}
    const double uava = (m.real() - p.real()) / 2, uavb = (p.imag() + m.imag()) / 2;
    const double ubva = (p.imag() - m.imag()) / 2, ubvb = (m.real() + p.real()) / 2;
    out.cross(0, cyclic_v_a) = out.cross(2, cyclic_u_a) = uava;
    out.cross(0, cyclic_v_b) = out.cross(3, cyclic_u_a) = uavb;
    out.cross(1, cyclic_v_a) = out.cross(2, cyclic_u_b) = ubva;
    out.cross(1, cyclic_v_b) = out.cross(3, cyclic_u_b) = ubvb;
    return out;
  }

 private:
  // sum_q (i x)^q / q! sums[q].
  static std::complex<double> sum_at(const std::vector<std::complex<double>>& sums, double x) {
    std::complex<double> out = 0.0, t = 1.0;
    for (std::size_t q = 0; q < sums.size(); ++q) {
      out += t * sums[q];
      t *= std::complex<double>(0.0, x / static_cast<double>(q + 1));
    }
    return out;
  }
  // sum_q (i x)^q / q! S_q of weight j (S_q's real part in column 4 q + first, imaginary in
  // 4 q + first + 1: first 0 for the u series, 2 for the v series).
  std::complex<double> series_at(std::size_t first, std::size_t j, double x) const {
    std::complex<double> out = 0.0, t = 1.0;
    for (int q = 0; q < q_; ++q) {
      const double* sq = &s_[j * np_ + 4 * static_cast<std::size_t>(q) + first];
      out += t * std::complex<double>(sq[0], sq[1]);
      t *= std::complex<double>(0.0, x / (q + 1));
    }
    return out;
  }

  double k0_;
  int q_, qx_, qy_;
  std::size_t np_;         // the powers of a row: 4 q_, then the 16 weights
  std::vector<double> s_;  // 16 x np_, row-major: each weight's sums with every power
  std::vector<std::complex<double>> xu_, xv_, yp_, ym_;
  std::vector<double> w_, p_;  // one block's weights and powers, row-major
  Eigen::MatrixXd e_, e2_;     // one block's phases
  Eigen::VectorXd t_;
};

// The normal equations of one sample set (every stride-th sample), accumulated block by block
// (for_each_block): memory independent of the number of samples. A trial cyclic period
// recomputes only the four cyclic columns' rows of the Gram matrix, in one more pass.
class Design {
 public:
  // `series`, if given, takes every block of the design's pass too (the period search's sums),
  // and then the cyclic columns are not made: their rows of the normal equations are the
  // series' (use_cyclic_rows). `each(at, x)` sees every sample read (for_each_block).
  template <class Each = NoHook>
  Design(const Model& m, const Samples& samples, std::size_t stride, double period_mm,
         CyclicSeries* series = nullptr, Each&& each = {})
      : m_(m), samples_(samples), stride_(stride), period_mm_(period_mm) {
    ata_.setZero();
    aty_.setZero();
    const std::size_t rows = (samples_.size() + stride_ - 1) / stride_;
    if (rows <= dense_max_rows) {
      dense_.resize(static_cast<Eigen::Index>(rows), term_count);
      dense_y_.resize(static_cast<Eigen::Index>(rows));
    }
    for_each_block(
        m_, samples_, stride_, k(),
        [&](const auto& b, const auto& y, std::size_t first) {
          if (series)
            series->add(b, y);  // and the rest of the normal equations with it
          else
            add_gram(b, y);
          if (dense_.rows() > 0) {
            dense_.middleRows(static_cast<Eigen::Index>(first), b.rows()) = b;
            dense_y_.segment(static_cast<Eigen::Index>(first), b.rows()) = y;
          }
        },
        each, series == nullptr);
    if (series) {
      series->normal_equations(ata_, aty_, yty_);
      dense_.resize(0, term_count);  // its cyclic columns were not made
    } else {
      const auto g = [&](std::size_t j, std::size_t l) { return gram_[j * gram_lanes + l]; };
      for (std::size_t j = 0; j < term_count; ++j) {
        for (std::size_t l = 0; l < term_count; ++l)
          ata_(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(l)) = g(j, l);
        aty_[static_cast<Eigen::Index>(j)] = g(j, term_count);
      }
      yty_ = g(term_count, term_count);
    }
  }

  // A block's products into the normal equations: [b y 0]' [b y 0] (add_outer_products),
  // each sum over the rows in order, as CyclicSeries::add sums the same products of the
  // columns it takes (so both give the same bits for those: the one-pass refinement then
  // differs from the pass per trial only by its series).
  template <class B, class Y>
  void add_gram(const B& b, const Y& y) {
    const auto rows = static_cast<std::size_t>(b.rows());
    w_.resize(rows * gram_lanes);
    for (std::size_t i = 0; i < rows; ++i) {
      const auto ei = static_cast<Eigen::Index>(i);
      double* w = &w_[i * gram_lanes];
      for (std::size_t j = 0; j < term_count; ++j) w[j] = b(ei, static_cast<Eigen::Index>(j));
      w[term_count] = y[ei];
      w[term_count + 1] = 0.0;
    }
    add_outer_products(gram_.data(), w_.data(), w_.data(), rows, gram_lanes, gram_lanes);
  }

  // The cyclic rows of the normal equations at `period_mm` given (CyclicSeries::rows at the
  // period found), as set_cyclic's pass would make them to the sums' rounding (issue 32: that
  // pass was a tenth of a long replay).
  void use_cyclic_rows(const CyclicRows& rows, double period_mm) {
    period_mm_ = period_mm;
    ata_.middleRows<cyclic_count>(cyclic_first) = rows.cross;
    ata_.middleCols<cyclic_count>(cyclic_first) = rows.cross.transpose();
    aty_.segment<cyclic_count>(cyclic_first) = rows.cty;
  }

  Solution solve(double period_mm) {
    if (m_.on[cyclic_first] && period_mm != period_mm_) set_cyclic(period_mm);
    Solution out = solve_in_order(ata_, aty_, m_.on);
    out.rss += yty_;
    return out;
  }

  // solve() for the period search's grid, on a dense design: each row's e^{i k c} and e^{i k n}
  // are carried from the last trial's k by a rotation by e^{i dk c} (cos_sin_small: no library
  // call), and computed afresh (cos_sin) every 16th trial or after a step in k above 1.5. The
  // rotations' rounding (a few ulps a step, so at most ~1e-14 of each column after 15 steps)
  // is the only difference from solve(): the grid's residuals move by ~1e-14 of themselves,
  // which changes its best point only for two points within that of each other (issue 32:
  // the grid's 2 x ~5,000 sines and cosines a trial were most of a short run's search).
  Solution solve_grid(double period_mm) {
    if (dense_.rows() == 0 || !m_.on[cyclic_first]) return solve(period_mm);
    period_mm_ = period_mm;
    const double kc = k();
    const auto rows = static_cast<std::size_t>(dense_.rows());
    if (phase_.size() != 4 * rows || phase_steps_ >= 15 || !(std::abs(kc - phase_k_) <= 1.5)) {
      phase_.resize(4 * rows);
      for (std::size_t i = 0; i < rows; ++i) {
        const auto ei = static_cast<Eigen::Index>(i);
        const auto [cu, su] = cos_sin(kc * dense_(ei, centre_u));
        const auto [cv, sv] = cos_sin(kc * dense_(ei, centre_v));
        phase_[4 * i] = cu, phase_[4 * i + 1] = su, phase_[4 * i + 2] = cv, phase_[4 * i + 3] = sv;
      }
      phase_steps_ = 0;
    } else {
      const double dk = kc - phase_k_;
      double* ph = phase_.data();
      const double* c = dense_.col(centre_u).data();
      const double* n = dense_.col(centre_v).data();
      for (std::size_t i = 0; i < rows; ++i) {
        double cu, su, cv, sv;
        cos_sin_small(dk * c[i], cu, su);
        cos_sin_small(dk * n[i], cv, sv);
        const double a = ph[4 * i], b = ph[4 * i + 1], e = ph[4 * i + 2], f = ph[4 * i + 3];
        ph[4 * i] = a * cu - b * su, ph[4 * i + 1] = b * cu + a * su;
        ph[4 * i + 2] = e * cv - f * sv, ph[4 * i + 3] = f * cv + e * sv;
      }
      ++phase_steps_;
    }
    phase_k_ = kc;
    Eigen::Matrix<double, cyclic_count, term_count> cross =
        Eigen::Matrix<double, cyclic_count, term_count>::Zero();
    Eigen::Matrix<double, cyclic_count, 1> cty = Eigen::Matrix<double, cyclic_count, 1>::Zero();
    // In blocks of rows, so that the product reads the columns just written from the cache.
    constexpr Eigen::Index block = 256;
    for (Eigen::Index first = 0; first < dense_.rows(); first += block) {
      const Eigen::Index len = std::min(block, dense_.rows() - first);
      for (Eigen::Index i = first; i < first + len; ++i) {
        const double* ph = &phase_[4 * static_cast<std::size_t>(i)];
        const double c = dense_(i, centre_u), n = dense_(i, centre_v);
        dense_(i, cyclic_u_a) = c * ph[1], dense_(i, cyclic_u_b) = c * ph[0];
        dense_(i, cyclic_v_a) = n * ph[3], dense_(i, cyclic_v_b) = n * ph[2];
      }
      const auto b = dense_.middleRows(first, len);
      const auto cyc = b.middleCols<cyclic_count>(cyclic_first);
      cross.noalias() += cyc.transpose() * b;
      cty.noalias() += cyc.transpose() * dense_y_.segment(first, len);
    }
    ata_.middleRows<cyclic_count>(cyclic_first) = cross;
    ata_.middleCols<cyclic_count>(cyclic_first) = cross.transpose();
    aty_.segment<cyclic_count>(cyclic_first) = cty;
    Solution out = solve_in_order(ata_, aty_, m_.on);
    out.rss += yty_;
    return out;
  }

  // The solution with the cyclic rows of the normal equations given (CyclicSeries::rows); the
  // design itself is left as it is.
  Solution solve_with(const CyclicRows& rows) const {
    Gram ata = ata_;
    TermVector aty = aty_;
    ata.middleRows<cyclic_count>(cyclic_first) = rows.cross;
    ata.middleCols<cyclic_count>(cyclic_first) = rows.cross.transpose();
    aty.segment<cyclic_count>(cyclic_first) = rows.cty;
    Solution out = solve_in_order(ata, aty, m_.on);
    out.rss += yty_;
    return out;
  }

  const Model& model() const { return m_; }
  double k() const { return m_.wave_number(period_mm_); }  // of the period last solved for
  const Gram& ata() const { return ata_; }
  const TermVector& aty() const { return aty_; }

 private:
  void set_cyclic(double period_mm) {
    period_mm_ = period_mm;
    Eigen::Matrix<double, cyclic_count, term_count> cross =
        Eigen::Matrix<double, cyclic_count, term_count>::Zero();
    Eigen::Matrix<double, cyclic_count, 1> cty = Eigen::Matrix<double, cyclic_count, 1>::Zero();
    if (dense_.rows() > 0) {  // only the cyclic columns change
      const double kc = k();
      for (Eigen::Index i = 0; i < dense_.rows(); ++i) {
        const Sample x = samples_[static_cast<std::size_t>(i) * stride_];
        const auto [cu, su] = cos_sin(kc * x.c);
        const auto [cv, sv] = cos_sin(kc * x.n);
        dense_(i, cyclic_u_a) = x.c * su;
        dense_(i, cyclic_u_b) = x.c * cu;
        dense_(i, cyclic_v_a) = x.n * sv;
        dense_(i, cyclic_v_b) = x.n * cv;
      }
      const auto cyc = dense_.middleCols<cyclic_count>(cyclic_first);
      cross.noalias() = cyc.transpose() * dense_;
      cty.noalias() = cyc.transpose() * dense_y_;
    } else {
      for_each_block(m_, samples_, stride_, k(), [&](const auto& b, const auto& y, std::size_t) {
        const auto cyc = b.template middleCols<cyclic_count>(cyclic_first);
        cross.noalias() += cyc.transpose() * b;
        cty.noalias() += cyc.transpose() * y;
      });
    }
    ata_.middleRows<cyclic_count>(cyclic_first) = cross;
    ata_.middleCols<cyclic_count>(cyclic_first) = cross.transpose();
    aty_.segment<cyclic_count>(cyclic_first) = cty;
  }

  // A design of at most this many rows (the period search's decimated one: its size is set by
  // the radius and the shortest period, not by the run's length) is also kept dense, so that a
  // trial period recomputes only its four cyclic columns.
  static constexpr std::size_t dense_max_rows = 8192;
  static constexpr std::size_t gram_lanes = term_count + 2;  // the columns, y and a 0
  std::vector<double> gram_ = std::vector<double>(gram_lanes * gram_lanes, 0.0);
  std::vector<double> w_;  // one block's rows [b y 0]
  Model m_;
  const Samples& samples_;
  std::size_t stride_;
  Block dense_;
  Eigen::VectorXd dense_y_;
  double period_mm_;
  Gram ata_;
  TermVector aty_;
  double yty_ = 0.0;
  // solve_grid's e^{i k c}, e^{i k n} of each dense row (cos, sin, cos, sin), at phase_k_.
  std::vector<double> phase_;
  double phase_k_ = 0.0;
  int phase_steps_ = 0;
};

// The minimum of f in [a, b] to about tol (Brent, "Algorithms for Minimization without
// Derivatives", 1973, ch. 5: golden section steps, and parabolic ones where they are safe).
template <class F>
double brent_min(double a, double b, double tol, F f) {
  const double c = (3.0 - std::sqrt(5.0)) / 2;
  double x = a + c * (b - a), w = x, v = x, fx = f(x), fw = fx, fv = fx, d = 0.0, e = 0.0;
  for (int iter = 0; iter < 100; ++iter) {
    const double m = (a + b) / 2, t2 = 2 * tol;
    if (std::abs(x - m) <= t2 - (b - a) / 2) break;
    bool golden = true;
    if (std::abs(e) > tol) {  // try the parabola through x, w, v
      double r = (x - w) * (fx - fv), q = (x - v) * (fx - fw), p = (x - v) * q - (x - w) * r;
      q = 2 * (q - r);
      if (q > 0) p = -p;
      q = std::abs(q);
      const double e_prev = e;
      e = d;
      if (std::abs(p) < std::abs(q * e_prev / 2) && p > q * (a - x) && p < q * (b - x)) {
        d = p / q;
        const double u = x + d;
        if (u - a < t2 || b - u < t2) d = x < m ? tol : -tol;
        golden = false;
      }
    }
    if (golden) {
      e = (x < m ? b : a) - x;
      d = c * e;
    }
    const double u = std::abs(d) >= tol ? x + d : x + (d > 0 ? tol : -tol);
    const double fu = f(u);
    if (fu <= fx) {
      (u < x ? b : a) = x;
      v = w, fv = fw, w = x, fw = fx, x = u, fx = fu;
    } else {
      (u < x ? a : b) = u;
      if (fu <= fw || w == x) {
        v = w, fv = fw, w = u, fw = fu;
      } else if (fu <= fv || v == x || v == w) {
        v = u, fv = fu;
      }
    }
  }
  return x;
}

// The cyclic period that leaves the least residual. The residual dips where the trial period
// keeps the phase along the whole travel 2R: a period off by dp drifts by 2 pi 2R dp / p^2,
// half a cycle when dp / p = p / (4R). So the grid steps by p / (8R) (at most 800 steps), on
// a decimated copy of the samples (>= 8 samples per shortest period along the path), and the
// best grid point is refined by Brent's method (parabolic and golden section steps) on all samples.
// A bracket of that refinement, [lo, hi] in log p.
struct Bracket {
  double lo, hi;
  // Its wave numbers k = 2 pi R / p: their middle and half their range.
  double k0(double r_mm) const { return pi * r_mm * (std::exp(-lo) + std::exp(-hi)); }
  double half_width_k(double r_mm) const { return pi * r_mm * (std::exp(-lo) - std::exp(-hi)); }
};
// The grid's bracket, [best / e^step, best * e^step], and a narrower one within it about the
// decimated design's own minimum (the refinement's trials on the grid's ~5,000 rows): the full
// samples' minimum lies within a few of that minimum's standard deviations of it, and the
// series of the one-pass refinement need about half the terms over the narrower bracket
// (CyclicSeries::terms_for: 18 -> 9 at R = 100 mm; issue 32). Its edges are checked after the
// refinement (at_edge): a minimum found there is refined again over the grid's bracket.
struct Brackets {
  Bracket grid, narrow;
  // x = log p found in `narrow` lies at one of its edges that the grid's bracket does not share.
  bool at_edge(double x) const {
    constexpr double margin = 4 * refine_tol;
    return (narrow.lo > grid.lo && x - narrow.lo < margin) ||
           (narrow.hi < grid.hi && narrow.hi - x < margin);
  }
  static constexpr double refine_tol = 1e-7;  // in log p (a 4 nm shift of a 40 mm period)
};

// The decimated minimum's standard deviation in log p, from the residual's curvature there:
// near its minimum x1 the residual is f1 + a (x - x1)^2, and with the residuals' variance s^2 =
// f1 / (rows - terms) the least-squares x moves by s / sqrt(a) (one standard deviation: where the
// residual has grown by s^2). Sixteen of those (or the grid's step, if less), not less than
// 100 times the refinement's tolerance; none (the grid's bracket) without a clear minimum.
template <class F>
double narrowed_half_width(F rss, double x1, double step, double rows) {
  // A grid step below 100 tolerances (a small p_min on a large radius, or a narrow search
  // range) keeps the grid's bracket: nothing to narrow, and std::clamp below needs its low bound
  // under its high. Checked first, before the three trials of the curvature.
  if (!(step > 100 * Brackets::refine_tol)) return step;
  const double h = step / 4;
  const double f1 = rss(x1), fp = rss(x1 + h), fm = rss(x1 - h);
  const double a = (fp + fm - 2 * f1) / (2 * h * h);
  const double var = f1 / std::max(1.0, rows - static_cast<double>(term_count));
  if (!(a > 0) || !(var > 0) || !std::isfinite(a)) return step;
  return std::clamp(16 * std::sqrt(var / a), 100 * Brackets::refine_tol, step);
}

Brackets search_grid(const Model& m, const Samples& samples, const Setup& setup) {
  const double p_min = setup.cyclic_search_min_mm, p_max = setup.cyclic_search_max_mm;
  const double path_per_sample_mm =
      2 * pi * setup.radius_mm / std::max(1.0, static_cast<double>(samples.size()) / 2.0);
  const auto stride = static_cast<std::size_t>(
      std::clamp(std::floor(p_min / (8 * path_per_sample_mm)), 1.0,
                 std::max(1.0, static_cast<double>(samples.size()) / 2000.0)));
  Design coarse(m, samples, stride, p_min);
  const double min_step = std::log(p_max / p_min) / 800.0;
  double best_p = p_min, best_rss = 1e300, best_step = min_step;
  for (double p = p_min, step = min_step; p <= p_max * (1 + 1e-12); p *= std::exp(step)) {
    step = std::max(min_step, p / (8 * setup.radius_mm));
    if (const double rss = coarse.solve_grid(p).rss; rss < best_rss)
      best_rss = rss, best_p = p, best_step = step;
  }
  const Bracket grid{std::log(best_p) - best_step, std::log(best_p) + best_step};
  const auto rss = [&](double x) { return coarse.solve_grid(std::exp(x)).rss; };
  const double x1 = brent_min(grid.lo, grid.hi, Brackets::refine_tol, rss);
  const double rows = std::ceil(static_cast<double>(samples.size()) / static_cast<double>(stride));
  const double half = narrowed_half_width(rss, x1, best_step, rows);
  const Brackets out{grid, {std::max(grid.lo, x1 - half), std::min(grid.hi, x1 + half)}};
  return out;
}

// Brent's minimisation over log p in a bracket: near the minimum the residual is a smooth
// parabola in log p, which parabolic steps find in about a third of the 26 trials that golden
// section alone took (issue 32). Returns log p, located to Brackets::refine_tol. `rss_at(p)`:
// the residual of the fit with period p.
template <class F>
double refine_log_period(const Bracket& b, F rss_at) {
  return brent_min(b.lo, b.hi, Brackets::refine_tol, [&](double x) { return rss_at(std::exp(x)); });
}

// Sorts v by key in linear time when it is a rotation of a strictly increasing sequence, or the
// reverse of one: a trace that runs one way round the circle (ccw, or cw), the usual case.
// Anything else is sorted by std::sort; the result is the same either way.
template <class T, class Key>
void sort_circular(std::vector<T>& v, Key key) {
  const auto not_rising = [&](const T& a, const T& b) { return !(key(a) < key(b)); };
  for (int pass = 0; pass < 2; ++pass) {
    if (pass == 1) std::reverse(v.begin(), v.end());
    const auto descent = std::adjacent_find(v.begin(), v.end(), not_rising);
    if (descent == v.end()) return;
    std::rotate(v.begin(), descent + 1, v.end());
    if (std::adjacent_find(v.begin(), v.end(), not_rising) == v.end()) return;
  }
  std::sort(v.begin(), v.end());
}

double mod360(double x) { return fmod_near(fmod_near(x, 360.0) + 360.0, 360.0); }

// The sorted order of key(0 .. n - 1) without sorting or holding them, when they are a rotation
// of a strictly rising sequence or of a strictly falling one (a trace that runs one way round
// the circle): the k-th smallest is key(at(k)). Found in one pass counting the cyclic pairs out
// of order: exactly one means such a rotation. Sorting the keys gives the same sequence.
struct CircularOrder {
  std::size_t n = 0, start = 0;
  bool falling = false;
  std::size_t at(std::size_t k) const {
    if (!falling) return start + k < n ? start + k : start + k - n;
    return k <= start ? start - k : start + n - k;
  }
};
template <class Key>
std::optional<CircularOrder> circular_order(std::size_t n, Key key) {
  if (n == 0) return std::nullopt;
  if (n == 1) return CircularOrder{1, 0, false};
  std::size_t not_rising = 0, not_falling = 0, last_not_rising = 0, last_not_falling = 0;
  double prev = key(0);
  const double first = prev;
  for (std::size_t i = 0; i < n; ++i) {
    const double next = i + 1 < n ? key(i + 1) : first;
    if (!(prev < next)) ++not_rising, last_not_rising = i;
    if (!(next < prev)) ++not_falling, last_not_falling = i;
    if (not_rising > 1 && not_falling > 1) return std::nullopt;
    prev = next;
  }
  if (not_rising == 1)
    return CircularOrder{n, last_not_rising + 1 < n ? last_not_rising + 1 : 0, false};
  if (not_falling == 1) return CircularOrder{n, last_not_falling, true};
  return std::nullopt;
}

// The smallest arc covering the angles: 360 minus the largest gap between sorted angles. A trace
// that runs one way round is read in its sorted order in place (nothing held: issue 32).
double coverage_deg(const TraceSource& t) {
  const auto key = [&](std::size_t j) { return mod360(t.angle_deg(j)); };
  if (const auto o = circular_order(t.size(), key)) {
    double below = key(o->at(0));
    double gap = below + 360.0 - key(o->at(t.size() - 1));
    for (std::size_t k = 1; k < t.size(); ++k) {
      const double x = key(o->at(k));
      gap = std::max(gap, x - below);
      below = x;
    }
    return 360.0 - gap;
  }
  std::vector<double> a;
  a.reserve(t.size());
  for (std::size_t j = 0; j < t.size(); ++j) a.push_back(key(j));
  sort_circular(a, [](double x) { return x; });
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
  if (setup.vibration_segment_samples < 256)
    throw InputError(fmt::format("circle: vibration segment of {} samples, at least 256 needed",
                                 setup.vibration_segment_samples));
}

// Returns the trace's arc (coverage_deg), which the ISO values report.
double validate_trace(const TraceSource& t) {
  const char* name = name_of(t.direction());
  if (t.size() != t.deviation_count())
    throw InputError(fmt::format("circle: {} trace has {} angles but {} deviations", name, t.size(),
                                 t.deviation_count()));
  if (t.size() < min_samples)
    throw InputError(fmt::format("circle: {} trace has {} samples, at least {} needed", name,
                                 t.size(), min_samples));
  for (std::size_t i = 0; i < t.size(); ++i)
    if (!std::isfinite(t.angle_deg(i)) || !std::isfinite(t.deviation_um(i)))
      throw InputError(fmt::format("circle: {} trace sample {} is not finite (angle {}, {} um)",
                                   name, i, t.angle_deg(i), t.deviation_um(i)));
  const double arc = coverage_deg(t);
  if (arc < 180.0 - 1e-9)
    throw InputError(
        fmt::format("circle: {} trace covers {:.1f} degrees, at least 180 needed", name, arc));
  return arc;
}

// Returns the smallest arc of the traces (validate_trace).
double validate(const Setup& setup, std::span<const TraceSource> traces) {
  if (traces.empty()) throw InputError("circle: no trace given");
  if (traces.size() > 2)
    throw InputError(fmt::format("circle: {} traces given, at most 2 (cw, ccw)", traces.size()));
  if (traces.size() == 2 && traces[0].direction() == traces[1].direction())
    throw InputError(fmt::format("circle: two traces in the same direction ({})",
                                 name_of(traces[0].direction())));
  validate_setup(setup);
  double arc_deg = 360.0;
  for (const auto& t : traces) arc_deg = std::min(arc_deg, validate_trace(t));
  return arc_deg;
}

// Least-squares circle, linearised as the bar length itself (dr = r0 + cu cos + cv sin, the
// first-order form above; the exact circle differs by O(e^2 / R)); the radial deviations about
// its centre, from the nominal radius, are y - cu cos - cv sin.
struct Circle {
  double cu = 0, cv = 0;
  double residual(const Sample& x) const { return x.y - cu * x.c - cv * x.n; }
};

// The sums of the least-squares circle: C'C and C'y, C the columns (1, cos, sin), sample by
// sample (the terms as a * a' adds them).
struct CircleSums {
  Eigen::Matrix3d ata = Eigen::Matrix3d::Zero();
  Eigen::Vector3d aty = Eigen::Vector3d::Zero();
  void add(const Sample& x) {
    const std::array<double, 3> a = {1.0, x.c, x.n};
    for (int j = 0; j < 3; ++j)
      for (int i = 0; i < 3; ++i)
        ata(i, j) += a[static_cast<std::size_t>(i)] * a[static_cast<std::size_t>(j)];
    for (int i = 0; i < 3; ++i) aty(i) += a[static_cast<std::size_t>(i)] * x.y;
  }
  Circle circle() const {
    const Eigen::Vector3d sol = ata.ldlt().solve(aty);
    return {sol[1], sol[2]};
  }
};

struct Range {
  double lo = 1e300, hi = -1e300;
  void add(double x) { lo = std::min(lo, x), hi = std::max(hi, x); }
  double pv() const { return hi - lo; }
};

// Largest |r_a(theta) - r_b(theta)|, r_b interpolated (periodically) at the angles of a. The
// points of b in the order of their angles: when b runs one way round (circular_order), read
// in place in that order (nothing held a sample: issue 32), else sorted into a vector.
double hysteresis(const Circle& c, const Samples& samples, const Span& a, const Span& b) {
  const std::size_t nb = b.end - b.begin;
  const auto angle_b = [&](std::size_t j) { return mod360(b.trace->angle_deg(j)); };
  const auto order = circular_order(nb, angle_b);
  std::vector<std::pair<double, double>> held;  // only when b does not run one way round
  if (!order) {
    held.reserve(nb);
    for (std::size_t i = b.begin; i < b.end; ++i)
      held.emplace_back(angle_b(i - b.begin), c.residual(samples.plain(i)));
    sort_circular(held, [](const auto& p) { return p.first; });
  }
  // The k-th point in angle order: its angle, and (computed when needed, the last two kept)
  // its residual.
  const auto angle_at = [&](std::size_t k) {
    return order ? angle_b(order->at(k)) : held[k].first;
  };
  std::array<std::pair<std::size_t, double>, 2> recent{{{SIZE_MAX, 0.0}, {SIZE_MAX, 0.0}}};
  const auto residual_at = [&](std::size_t k) {
    if (!order) return held[k].second;
    for (const auto& r : recent)
      if (r.first == k) return r.second;
    const double r = c.residual(samples.plain(b.begin + order->at(k)));
    recent[1] = recent[0];
    recent[0] = {k, r};
    return r;
  };
  // pts[k] < (t, -1e300), as the pairs compare.
  const auto below = [&](std::size_t k, double t) {
    const double x = angle_at(k);
    return x < t || (x == t && residual_at(k) < -1e300);
  };
  double h = 0.0;
  // The lower bound of each angle of a, looked for first a few places on from the last one
  // (a's angles mostly rise or fall through pts in order), else by bisection: the same place
  // either way, without a bisection's mispredicted branches on every sample (issue 32).
  std::size_t last = 0;
  const auto lower_bound = [&](double t) {
    const auto is_bound = [&](std::size_t j) {
      return (j == 0 || below(j - 1, t)) && (j == nb || !below(j, t));
    };
    for (std::size_t j = last > 2 ? last - 2 : 0; j <= std::min(nb, last + 2); ++j)
      if (is_bound(j)) return last = j;
    std::size_t lo = 0, len = nb;  // std::lower_bound's bisection
    while (len > 0) {
      const std::size_t half = len / 2;
      if (below(lo + half, t))
        lo += half + 1, len -= half + 1;
      else
        len = half;
    }
    return last = lo;
  };
  for (std::size_t i = a.begin; i < a.end; ++i) {
    const double t = mod360(a.trace->angle_deg(i - a.begin));
    const std::size_t hi = lower_bound(t);
    const std::size_t k1 = hi == nb ? 0 : hi, k0 = hi == 0 ? nb - 1 : hi - 1;
    const double a0 = angle_at(k0), a1 = angle_at(k1);
    double span = a1 - a0;
    if (span <= 0) span += 360.0;
    double off = t - a0;
    if (off < 0) off += 360.0;
    if (span > 10.0) continue;  // outside the other trace's arc
    const double r0 = residual_at(k0), r1 = residual_at(k1);
    const double rbi = r0 + (r1 - r0) * (span > 0 ? off / span : 0.0);
    h = std::max(h, std::abs(c.residual(samples.plain(i)) - rbi));
  }
  return h;
}

// The ISO 230-4 values, from two passes over the samples that are the fit's own (issue 32:
// each pass of their own rebuilt every record): the circles of each trace and of all of them
// from the design's pass (add_circle), then each trace's range about its circle and the
// common circle's from the residual's pass (add_range). The common sums run on from the first
// trace's, the same sums in the same order as a pass of their own; the ranges are minima and
// maxima, the same in any order.
class IsoPasses {
 public:
  IsoPasses(const Samples& samples, double arc_deg) : samples_(samples), own_(2) {
    iso_.arc_deg = arc_deg;
  }

  // Every sample once, in order (the design's pass, stride 1).
  void add_circle(std::size_t at, const Sample& x) {
    if (at < split()) {
      own_[0].add(x);
      return;
    }
    if (!all_from_first_) all_ = own_[0], all_from_first_ = true;
    own_[1].add(x);
    all_.add(x);
  }
  // After the first pass: the circles, and H (its own reading of the traces).
  void circles() {
    if (!all_from_first_) all_ = own_[0], all_from_first_ = true;
    common_ = all_.circle();
    for (std::size_t t = 0; t < traces(); ++t) circle_[t] = own_[t].circle();
    const auto& spans = samples_.spans();
    if (spans.size() == 2) iso_.H_um = hysteresis(common_, samples_, spans[0], spans[1]);
  }
  // Every sample once, in any order (the residual's pass).
  void add_range(std::size_t at, const Sample& x) {
    const std::size_t t = at < split() ? 0 : 1;
    range_[t].add(circle_[t].residual(x));
    f_.add(common_.residual(x));
  }
  Iso230_4 values() const {
    Iso230_4 iso = iso_;
    for (std::size_t t = 0; t < traces(); ++t)
      (samples_.spans()[t].trace->direction() == Direction::cw ? iso.G_cw_um : iso.G_ccw_um) =
          range_[t].pv();
    iso.G_bi_um = f_.pv();
    iso.centre_u_um = common_.cu;
    iso.centre_v_um = common_.cv;
    iso.F_max_um = f_.hi, iso.F_min_um = f_.lo;
    return iso;
  }

 private:
  std::size_t split() const { return samples_.spans()[0].end; }
  std::size_t traces() const { return samples_.spans().size(); }
  const Samples& samples_;
  Iso230_4 iso_;
  std::vector<CircleSums> own_;
  CircleSums all_;
  bool all_from_first_ = false;
  Circle common_;
  std::array<Circle, 2> circle_{};
  std::array<Range, 2> range_{};
  Range f_;
};

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

// The ranked diagnostics from the fitted coefficients. Each one's peak-to-valley and the G of
// the traces without it (the LSQ circle refitted) come from the pass over the samples that
// makes the residual, for all of them together (observe; finish for those found in the
// residual): the circle of y - contribution needs C'(y - contribution), C the circle's columns
// (cos, sin, 1), and for a fitted term C' times its columns is in the Gram matrix already.
class Reporter {
 public:
  Reporter(Result& res, const Model& reported, const Design& d, const Eigen::VectorXd& coef)
      : res_(res), m_(reported), d_(d), c_(coef) {}

  void add(std::string key, std::string name, double value, std::string unit,
           std::initializer_list<int> terms) {
    for (int k : terms)
      if (!on(k)) return;  // off, or dropped as not separable
    pending_.push_back(
        {{std::move(key), std::move(name), value, std::move(unit), 0.0, 0.0, 0.0, {}},
         std::vector<int>(terms),
         nullptr});
  }
  // A diagnostic found in the residual (stick-slip, vibration): its contribution is given, one
  // value per sample (kept by the caller until finish).
  void add(const dynamics::Found& f) {
    pending_.push_back({{f.key, f.name, f.value, f.unit, 0.0, 0.0, 0.0, f.frequency_hz}, {}, &f});
  }
  bool on(int k) const { return m_.on[static_cast<std::size_t>(k)]; }
  double c(int k) const { return c_[k]; }

  // PV of each contribution, its share of G, and what G would be without it (docs/circle.md).
  // The fitted diagnostics' contributions, over one block of the design (the caller's pass
  // over the samples: report() first, then every block once).
  template <class B, class Y>
  void observe(const B& b, const Y& y) {
    if (!ldlt_) {
      ldlt_.emplace(d_.ata().topLeftCorner<3, 3>());
      for (auto& p : pending_) {
        Eigen::Vector3d ct_contrib = Eigen::Vector3d::Zero();
        for (int k : p.terms) ct_contrib += c_[k] * d_.ata().block<3, 1>(0, k);
        p.centre = ldlt_->solve(d_.aty().head<3>() - ct_contrib);  // circle without it
      }
    }
    Eigen::VectorXd contrib(b.rows()), without(b.rows());
    for (auto& p : pending_) {
      if (p.found) continue;
      contrib.setZero();
      for (int k : p.terms) contrib += c_[k] * b.col(k);
      without = y - contrib - p.centre[0] * b.col(centre_u) - p.centre[1] * b.col(centre_v);
      p.contrib.add(contrib.minCoeff()), p.contrib.add(contrib.maxCoeff());
      p.without.add(without.minCoeff()), p.without.add(without.maxCoeff());
    }
  }

  // Those found in the residual (their contributions are given, no basis is needed), then all
  // of them into the result, in two passes for all of them: C' times each contribution, then
  // each one's ranges.
  void finish(const Samples& samples) {
    if (!ldlt_) ldlt_.emplace(d_.ata().topLeftCorner<3, 3>());
    std::vector<Pending*> found;
    for (auto& p : pending_)
      if (p.found) found.push_back(&p);
    if (!found.empty()) {
      std::vector<Eigen::Vector3d> ct_contrib(found.size(), Eigen::Vector3d::Zero());
      for (std::size_t i = 0; i < samples.size(); ++i) {
        const Sample x = samples.plain(i);
        for (std::size_t f = 0; f < found.size(); ++f)
          ct_contrib[f] += Eigen::Vector3d(x.c, x.n, 1.0) * found[f]->found->contribution[i];
      }
      for (std::size_t f = 0; f < found.size(); ++f)
        found[f]->centre = ldlt_->solve(d_.aty().head<3>() - ct_contrib[f]);
      for (std::size_t i = 0; i < samples.size(); ++i) {
        const Sample x = samples.plain(i);
        for (Pending* p : found) {
          const double contrib = p->found->contribution[i];
          p->contrib.add(contrib);
          p->without.add(x.y - contrib - p->centre[0] * x.c - p->centre[1] * x.n);
        }
      }
    }
    const double g_bi = res_.iso.G_bi_um;
    for (auto& p : pending_) {
      p.dg.pv_um = p.contrib.pv();
      p.dg.share_pct = g_bi > 0 ? 100.0 * p.dg.pv_um / g_bi : 0.0;
      p.dg.g_reduction_um = g_bi - p.without.pv();
      res_.diagnostics.push_back(std::move(p.dg));
    }
    pending_.clear();
  }

 private:
  struct Pending {
    Diagnostic dg;
    std::vector<int> terms;        // a fitted diagnostic's terms, or
    const dynamics::Found* found;  // one found in the residual
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    Range contrib, without;  // of its contribution; of y without it about its circle
  };
  Result& res_;
  const Model& m_;
  const Design& d_;
  const Eigen::VectorXd& c_;
  std::vector<Pending> pending_;
  std::optional<Eigen::LDLT<Eigen::Matrix3d>> ldlt_;  // of the circle's columns C'C
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
  return analyse(setup, traces, fit_records_held_max_samples);
}

Result analyse(const Setup& setup, std::span<const Trace> traces,
               std::size_t records_held_max_samples) {
  return analyse(setup, traces, records_held_max_samples, PeriodRefinement::one_pass_series);
}

Result analyse(const Setup& setup, std::span<const Trace> traces,
               std::size_t records_held_max_samples, PeriodRefinement refinement) {
  std::vector<TraceSource> sources;
  for (const auto& t : traces) sources.emplace_back(t);
  return analyse(setup, sources, records_held_max_samples, PageOptions{}, refinement);
}

Result analyse(const Setup& setup, std::span<const TraceSource> traces,
               std::size_t records_held_max_samples, PageOptions pages) {
  return analyse(setup, traces, records_held_max_samples, pages, PeriodRefinement::one_pass_series);
}

Result analyse(const Setup& setup, std::span<const TraceSource> traces,
               std::size_t records_held_max_samples, PageOptions pages,
               PeriodRefinement refinement) {
  const double arc_deg = validate(setup, traces);
  Result res;
  // Deviations from the nominal radius: the bar reads 0 at its calibrated length.
  const double offset_um =
      1e3 * (setup.calibrated_radius_mm.value_or(setup.radius_mm) - setup.radius_mm);
  Samples samples(traces, offset_um, setup.spike_decay_deg * deg, records_held_max_samples);
  const auto& spans = samples.spans();
  IsoPasses iso(samples, arc_deg);
  const auto add_circle = [&](std::size_t at, const Sample& x) { iso.add_circle(at, x); };

  Model m = choose_terms(setup, traces.size() == 2, arc_deg, res.notes);
  m.split = spans[0].end;
  m.s_before = sign_of(spans[0].trace->direction());
  m.s_after = sign_of(spans.back().trace->direction());
  double period_mm = setup.cyclic_period_mm.value_or(10.0);
  std::optional<Design> fitted;
  if (m.on[cyclic_first] && !setup.cyclic_period_mm) {
    Brackets brackets = search_grid(m, samples, setup);
    if (refinement == PeriodRefinement::one_pass_series_from_an_edge)
      brackets.narrow = {brackets.grid.lo, brackets.grid.lo + 100 * Brackets::refine_tol};
    period_mm = std::exp((brackets.narrow.lo + brackets.narrow.hi) / 2);
    if (refinement == PeriodRefinement::pass_per_trial) {
      fitted.emplace(m, samples, 1, period_mm, nullptr, add_circle);
      const auto rss = [&](double p) { return fitted->solve(p).rss; };
      double x = refine_log_period(brackets.narrow, rss);
      if (brackets.at_edge(x)) x = refine_log_period(brackets.grid, rss);
      period_mm = std::exp(x);
    } else {
      // The refinement's trials, and the normal equations at the period found, from sums made
      // in the design's own pass (CyclicSeries): the search costs that pass's extra sums, and
      // one more such pass when the minimum falls on the narrow bracket's edge.
      const auto refine = [&](const Bracket& b, auto&& each) {
        CyclicSeries series(b.k0(m.r_mm), b.half_width_k(m.r_mm) * (1 + 1e-6));
        fitted.emplace(m, samples, 1, period_mm, &series, each);
        const double x = refine_log_period(b, [&](double p) {
          return fitted->solve_with(series.rows(m.wave_number(p), fitted->ata())).rss;
        });
        fitted->use_cyclic_rows(series.rows(m.wave_number(std::exp(x)), fitted->ata()),
                                std::exp(x));
        return x;
      };
      double x = refine(brackets.narrow, add_circle);
      if (brackets.at_edge(x)) x = refine(brackets.grid, NoHook{});  // the circles summed once
      period_mm = std::exp(x);
    }
  } else {
    fitted.emplace(m, samples, 1, period_mm, nullptr, add_circle);
  }
  iso.circles();
  Design& full = *fitted;
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
  const std::string ax = axis_names(setup.plane);

  // Stick-slip and vibration live in what the geometric model leaves.
  std::vector<dynamics::TraceResidual> residuals;
  for (const auto& sp : spans) {
    residuals.push_back({.s = sign_of(sp.trace->direction()),
                         .trace = sp.trace,
                         .r_um = PagedDoubles(sp.end - sp.begin, pages)});
  }
  // One pass: the residual, and the fitted diagnostics' contributions.
  Reporter rep(res, reported, full, sol.coef);
  report(rep, setup, ax, period_mm);
  for_each_block(
      m, samples, 1, full.k(),
      [&](const auto& b, const auto& y, std::size_t first) {
        rep.observe(b, y);
        const Eigen::VectorXd r = y - b * sol.coef;
        for (Eigen::Index i = 0; i < r.size(); ++i) {
          const std::size_t at = first + static_cast<std::size_t>(i);
          const std::size_t t = at < spans[0].end ? 0 : 1;
          residuals[t].r_um.set(at - spans[t].begin, r[i]);
        }
      },
      [&](std::size_t at, const Sample& x) { iso.add_range(at, x); });
  res.iso = iso.values();
  // The fit's records (40 bytes a sample, if held) are done with: what follows needs the
  // residual, and rep.finish rebuilds the little it needs from the traces. Freed before the
  // spectra, the peak of the analysis at 1 kHz (issue 32).
  const std::size_t sample_count = samples.size();
  samples.release();
  const dynamics::Settings dyn{.radius_mm = setup.radius_mm,
                               .feed_mm_per_min = setup.feed_mm_per_min,
                               .window_deg = setup.stick_slip_window_deg,
                               .segment_samples = setup.vibration_segment_samples,
                               .pages = pages,
                               .u = ax[0],
                               .v = ax[1]};
  const dynamics::Dynamics in_residual =
      dynamics::vibration_and_stick_slip(dyn, residuals, res.notes);
  double ss = 0.0;  // what is left after the geometric model and a vibration
  for (const auto& tr : residuals)
    for (std::size_t j = 0; j < tr.r_um.size(); ++j) ss += tr.r_um[j] * tr.r_um[j];
  res.residual_rms_um = std::sqrt(ss / static_cast<double>(sample_count));
  residuals.clear();
  residuals.shrink_to_fit();

  if (in_residual.vibration) rep.add(*in_residual.vibration);
  for (const auto& f : in_residual.stick_slip) rep.add(f);
  rep.finish(samples);
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
