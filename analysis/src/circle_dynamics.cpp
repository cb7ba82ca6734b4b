// Stick-slip and vibration from the residual of the geometric model (see circle_dynamics.hpp
// and docs/circle.md). Both are caldaq's own definitions: the public material found says what
// they look like on a trace, not how a ballbar program measures them.
//
// Vibration. A machine vibrating at f Hz along a fixed direction at angle phi of the plane moves
// the tool by A sin(2 pi f t) (cos phi, sin phi); the bar sees the radial part,
// A sin(2 pi f t) cos(theta - phi), and theta = theta_0 + s 2 pi f0 t runs at the feed, so the
// trace holds the two lines f - f0 and f + f0 (A / 2 each); a radial vibration (the bar, the
// spindle) holds the line f itself. So the residual is fitted, per trace, by sines and cosines at
// f - f0, f and f + f0, with f found from the spectrum: the Hann-windowed periodogram of the
// residual (resampled to an even time step, zero-padded to a power of two at least twice its
// length), averaged over the traces, its largest bin between 10 f0 and 0.9 times the Nyquist
// frequency, the band of +-(f0 + 2.5 / T) about it (T the trace's duration: the window's main
// lobe is +-2 / T), its power centroid as the first estimate, then the fit's best frequency
// within +-1 / T of it. It is reported when the band holds at least 10 times the power that the
// rest of the band's noise would put there (the median bin power / ln 2 per bin: the median of
// an exponential variable) in the average, and at least 4 times in every trace (a vibration does
// not depend on the direction of travel); when its mean power per bin is at least 10 times that
// of its neighbourhood (three band widths each side: a local error locked to the position, such
// as the mean lag of a stick-slip about the reversals, puts a comb of harmonics of f0 there, a
// vibration one line); and when its rms is at least 0.01 um.
//
// Stick-slip. Friction makes an axis stick and jump when it moves slowly (Ballbar plot-analysis
// texts: "when [an axis] is fed at a very low rate"): on a circle, where it reverses. The
// residual is high-passed (minus its centred moving median over 4 degrees of travel, so the
// geometric terms and the smooth leftovers of a reversal are gone, and a single outlying sample
// at a reversal, e.g. a backlash step the fit puts a sample late, stays where it is instead of
// spreading over its neighbours) and its mean square is
// compared between the samples 1 to W degrees from a reversal of the axis (the axis' speed is
// below F sin W there; the first degree, where a backlash step or a reversal spike leaves what
// the model did not take, is not counted) and the samples more than W degrees from every
// reversal: the stick-slip is the rms in excess, sqrt(ms_in - ms_out), reported when ms_in is at
// least twice ms_out and the excess at least 0.01 um. Noise has the same mean square in and out,
// so it does not count.
#include "circle_dynamics.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <numeric>
#include <optional>
#include <utility>

#include "cal/analysis/angle_reduce.hpp"
#include "cal/analysis/even_resample.hpp"
#include "cal/analysis/line_trials.hpp"
#include "cal/analysis/moving_median.hpp"
#include "cal/analysis/power_spectrum.hpp"

namespace cal::circle::dynamics {
namespace {

constexpr double pi = std::numbers::pi;
constexpr double deg = pi / 180.0;
constexpr std::size_t min_window_samples = 20;

double omega_rad_s(const Settings& s) { return s.feed_mm_per_min / 60.0 / s.radius_mm; }

// One trace ordered by travel (s theta rising), with its sample times.
struct Timed {
  std::size_t n = 0;
  std::vector<std::size_t> sorted;  // travel order -> index in the trace; empty: the identity
  const TraceResidual* trace = nullptr;
  double first = 0.0, w = 1.0;  // s theta of the first sample in travel; the angular speed
  double duration_s = 0.0, step_s = 0.0;
  std::size_t order(std::size_t k) const { return sorted.empty() ? k : sorted[k]; }
  // The time of sample i (in the trace's order), 0 at the first in travel: computed when asked
  // rather than kept, 8 bytes a sample less at the spectra's peak (issue 32).
  double time_s(std::size_t i) const { return (trace->s * trace->theta_rad(i) - first) / w; }
};

// The median of the positive steps between samples: the element of rank count / 2 (nth_element's),
// from a count of each distinct step. A trace from time has a handful of distinct steps
// (rounding), so nothing is held a sample (issue 32); past `max_distinct` the count stops and
// the caller takes the steps one by one.
class StepMedian {
 public:
  static constexpr std::size_t max_distinct = 4096;
  StepMedian() = default;
  // Not copied or assigned: last_ points into this object's own map (a copy's would point into
  // the source's, and a temporary's after it is gone).
  StepMedian(const StepMedian&) = delete;
  StepMedian& operator=(const StepMedian&) = delete;
  void clear() {
    counts_.clear();
    last_ = counts_.end();
    count_ = 0;
  }
  void add(double d) {
    if (!(d > 0) || overflowed()) return;
    // The step of the last sample counted again without a search of the map (a trace from time
    // repeats a step many times over: the map's search was most of this pass, issue 32).
    if (last_ == counts_.end() || last_->first != d) last_ = counts_.try_emplace(d, 0).first;
    ++last_->second, ++count_;
  }
  bool overflowed() const { return counts_.size() > max_distinct; }
  double median() const {
    std::size_t rank = count_ / 2;
    for (const auto& c : counts_) {
      if (rank < c.second) return c.first;
      rank -= c.second;
    }
    return 0.0;  // no positive step
  }

 private:
  std::map<double, std::size_t> counts_;
  std::map<double, std::size_t>::iterator last_ = counts_.end();
  std::size_t count_ = 0;
};

Timed timed(const TraceResidual& t, double w) {
  Timed out;
  const std::size_t n = out.n = t.r_um.size();
  out.trace = &t;
  out.w = w;
  if (n == 0) return out;
  // A trace from time is in travel order already: one pass checks that and counts the steps,
  // each sample's angle computed once (it was four times, in two passes: issue 32), and no
  // permutation is kept (8 bytes a sample). The times are time_s's, by the same operations.
  StepMedian steps;
  out.first = t.s * t.theta_rad(0);
  double key = out.first, before_s = 0.0;  // s theta and time of the last sample
  bool in_order = true;
  for (std::size_t i = 1; i < n; ++i) {
    const double k = t.s * t.theta_rad(i);
    if (k < key) {
      in_order = false;
      break;
    }
    const double at_s = (k - out.first) / w;
    steps.add(at_s - before_s);
    key = k, before_s = at_s;
  }
  const auto step = [&](std::size_t i) {
    return out.time_s(out.order(i)) - out.time_s(out.order(i - 1));
  };
  if (in_order) {
    out.duration_s = before_s;
  } else {  // sorted, and the steps counted in travel order
    const auto before = [&](std::size_t a, std::size_t b) {
      return t.s * t.theta_rad(a) < t.s * t.theta_rad(b);
    };
    out.sorted.resize(n);
    std::iota(out.sorted.begin(), out.sorted.end(), std::size_t{0});
    std::stable_sort(out.sorted.begin(), out.sorted.end(), before);
    out.first = t.s * t.theta_rad(out.order(0));
    out.duration_s = out.time_s(out.order(n - 1));
    steps.clear();
    for (std::size_t i = 1; i < n && !steps.overflowed(); ++i) steps.add(step(i));
  }
  if (!steps.overflowed()) {
    out.step_s = steps.median();
    return out;
  }
  // Very many distinct steps: held, one a sample.
  std::vector<double> all;
  for (std::size_t i = 1; i < n; ++i)
    if (const double d = step(i); d > 0) all.push_back(d);
  if (!all.empty()) {
    std::nth_element(all.begin(), all.begin() + all.size() / 2, all.end());
    out.step_s = all[all.size() / 2];
  }
  return out;
}

// The residual at the times k dt, k = 0, 1, 2, ..., linearly interpolated in travel order
// (even_resample.hpp): each sample's time and value are read once, when the walk reaches it,
// not once for each time between it and the next and again for the walk (issue 32); the values
// are those of the same walk reading them anew, bit for bit.
auto resampled(const TraceResidual& t, const Timed& tm, double dt) {
  return EvenResampler(
      tm.n, dt, [&tm](std::size_t j) { return tm.time_s(tm.order(j)); },
      [&t, &tm](std::size_t j) { return t.r_um[tm.order(j)]; });
}

// |X_k|^2 of the Hann-windowed, mean-removed series zero-padded to npad, k = 0 .. npad / 2, for
// the Welch segments of a run one after another: the transform (its twiddle table), the window
// and the buffer are made once and kept from one segment to the next. Made afresh for each
// segment, the tables' sines and cosines and the buffers' page faults cost more than the
// transform itself (21 % of a 16-minute 10 kHz replay, issue 32). The transform is
// cal::PowerSpectrum, in place in the padded series: Eigen's kissfft made its plan on each
// analysis and held three more arrays of 1 - 2 MB, each page a fault on first use, and its
// arithmetic was some 20 % slower (issue 32, docs/benchmarks.md, tenth pass (b); the spectra
// agree with kissfft's within 1e-15 of their peak and with the direct DFT likewise,
// tests/analysis/power_spectrum_test.cpp).
class Periodograms {
 public:
  explicit Periodograms(std::size_t npad) : spectrum_(npad), padded_(npad) {}

  // The periodogram of x divided by `segments` added to p (npad / 2 + 1 values): one of the
  // Welch average's terms.
  void add(const std::vector<double>& x, double segments, std::vector<double>& p) {
    const auto n = x.size();
    if (window_.size() != n) {
      window_.resize(n);
      for (std::size_t i = 0; i < n; ++i)
        window_[i] = 0.5 - 0.5 * std::cos(2 * pi * static_cast<double>(i) /
                                          static_cast<double>(std::max<std::size_t>(1, n - 1)));
    }
    const double mean = std::accumulate(x.begin(), x.end(), 0.0) / static_cast<double>(n);
    for (std::size_t i = 0; i < n; ++i) padded_[i] = (x[i] - mean) * window_[i];
    // The transform works in the buffer: the padding is written again for each segment.
    std::fill(padded_.begin() + static_cast<std::ptrdiff_t>(n), padded_.end(), 0.0);
    spectrum_.add(padded_, segments, p);
  }

 private:
  PowerSpectrum spectrum_;
  std::vector<double> window_, padded_;
};

struct BandTest {
  double snr = 0.0;  // band power over what the noise floor would put in the band
  double centroid_hz = 0.0;
};

// `rest` is scratch (up to a spectrum's length): kept by the caller from one test to the next, a
// fresh 1 MB on each was page faults (issue 32).
BandTest band_test(const std::vector<double>& p, std::size_t lo, std::size_t hi, std::size_t b0,
                   std::size_t b1, double df, std::vector<double>& rest) {
  rest.clear();
  double band = 0.0, moment = 0.0;
  for (std::size_t k = lo; k <= hi; ++k) {
    if (k >= b0 && k <= b1) {
      band += p[k];
      moment += p[k] * static_cast<double>(k) * df;
    } else {
      rest.push_back(p[k]);
    }
  }
  BandTest out;
  if (rest.empty() || !(band > 0)) return out;
  std::nth_element(rest.begin(), rest.begin() + rest.size() / 2, rest.end());
  const double per_bin = rest[rest.size() / 2] / std::log(2.0);
  const double expected = per_bin * static_cast<double>(b1 - b0 + 1);
  out.snr = expected > 0 ? band / expected : 1e300;
  out.centroid_hz = moment / band;
  return out;
}

// Sines and cosines at f - f0, f, f + f0 fitted per trace, or per segment of a trace cut for
// the spectrum (its own amplitudes and phases in each, the frequency common: the fit's
// resolution is then that of the spectrum, and it holds 48 numbers a segment, nothing a
// sample): the explained sum of squares of several trial frequencies from one pass over the
// samples (cal::LineTrials: three sin_cos a sample whatever the number of trials; a pass a
// trial, each with four library sines and cosines a sample, made a run with a vibration cost
// 15x one without, issue 32), the normal equations of the best kept; and the fitted
// contribution in each trace's order and the fitted power of each of the three lines, summed
// over the traces, at the frequency found.
struct LineFit {
  const std::vector<TraceResidual>& traces;
  const std::vector<Timed>& tms;
  double f0_hz;
  std::vector<std::size_t> segments;  // per trace: 1, or its spectrum's segment count
  double segment_s = 0.0;             // the fit's segments' duration (segments > 1)
  PageOptions pages;                  // of the contributions

  using Row = Eigen::Matrix<double, 6, 1>;
  using Gram6 = Eigen::Matrix<double, 6, 6>;
  struct Normal {  // one piece's normal equations
    Gram6 ata;
    Row aty;
  };
  // The best trial so far: its frequency, explained sum of squares and normal equations (per
  // trace, per piece).
  struct Best {
    double f_hz = 0.0, explained = -1.0;
    std::vector<std::vector<Normal>> normal;
  };

  std::size_t segment(std::size_t i, double t_s) const {
    if (segments[i] == 1) return 0;
    const auto k = static_cast<std::size_t>(std::max(0.0, t_s / segment_s));
    return std::min(segments[i] - 1, k);
  }

  // One piece's solution and the sum of squares it explains.
  static Row solve(const Normal& n, double& explained) {
    const Row x = n.ata.ldlt().solve(n.aty);
    explained += x.dot(n.aty);
    return x;
  }

  // The trials centre + k step, k = -reach .. reach (0 only if `centre`), in one pass; `best`
  // takes the first (k rising) that explains more than it.
  void trials(double centre_hz, double step_hz, int reach, bool centre, Best& best) const {
    std::vector<LineTrials> sums;
    for (std::size_t i = 0; i < traces.size(); ++i) {
      sums.emplace_back(f0_hz, centre_hz, step_hz, reach, centre, segments[i]);
      const auto& y = traces[i].r_um;
      for (std::size_t j = 0; j < y.size(); ++j) {
        const double t_s = tms[i].time_s(j);
        sums.back().add(segment(i, t_s), t_s, y[j]);
      }
    }
    if (sums.empty()) return;
    for (const int k : sums.front().offsets()) {
      std::vector<std::vector<Normal>> normal(traces.size());
      double explained = 0.0;
      for (std::size_t i = 0; i < traces.size(); ++i)
        for (std::size_t g = 0; g < segments[i]; ++g) {
          const auto s = sums[i].sums(k, g);
          Normal n;
          for (int a = 0, p = 0; a < 6; ++a)
            for (int b = 0; b <= a; ++b, ++p) n.ata(a, b) = n.ata(b, a) = s.lower[p];
          for (int a = 0; a < 6; ++a) n.aty[a] = s.ry[a];
          solve(n, explained);
          normal[i].push_back(n);
        }
      if (explained > best.explained)
        best = {centre_hz + k * step_hz, explained, std::move(normal)};
    }
  }

  // The best's fitted contribution in each trace's order and the fitted power of each of the
  // three lines, summed over the traces.
  void contribution(const Best& best, std::vector<PagedDoubles>& contribution,
                    std::array<double, 3>& line_power) const {
    for (std::size_t i = 0; i < traces.size(); ++i) {
      std::vector<Row> x;
      double explained = 0.0;
      for (const auto& n : best.normal[i]) {
        x.push_back(solve(n, explained));
        for (int k = 0; k < 3; ++k)
          line_power[static_cast<std::size_t>(k)] +=
              x.back()[2 * k] * x.back()[2 * k] + x.back()[2 * k + 1] * x.back()[2 * k + 1];
      }
      const auto& y = traces[i].r_um;
      contribution.emplace_back(y.size(), pages);
      for (std::size_t j = 0; j < y.size(); ++j) {
        const double t_s = tms[i].time_s(j);
        const auto r = LineTrials::row(best.f_hz, f0_hz, t_s);
        contribution.back().set(j, Eigen::Map<const Row>(r.data()).dot(x[segment(i, t_s)]));
      }
    }
  }
};

// Mean power per bin in [a, b] (clipped to [lo, hi]); 0 when empty.
double mean_power(const std::vector<double>& p, std::ptrdiff_t a, std::ptrdiff_t b, std::size_t lo,
                  std::size_t hi) {
  a = std::max<std::ptrdiff_t>(a, static_cast<std::ptrdiff_t>(lo));
  b = std::min<std::ptrdiff_t>(b, static_cast<std::ptrdiff_t>(hi));
  if (b < a) return 0.0;
  double sum = 0.0;
  for (auto k = a; k <= b; ++k) sum += p[static_cast<std::size_t>(k)];
  return sum / static_cast<double>(b - a + 1);
}

// The residual minus its centred moving median, in the trace's own order: at travel position i
// the median of every stride-th sample from i - m to i + m (clipped at the ends). Into h from
// `first`, one value a sample of the trace.
void high_pass(const TraceResidual& t, const Timed& tm, std::size_t m, std::size_t stride,
               PagedDoubles& h, std::size_t first) {
  const auto at = [&](std::size_t k) { return t.r_um[tm.order(k)]; };
  moving_median(t.r_um.size(), m, stride, at,
                [&](std::size_t i, double median) { h.set(first + tm.order(i), at(i) - median); });
}

// The strongest narrow-band component above 10 f0 when it stands out of the residual's noise in
// every trace; its fitted contribution is subtracted from `traces`. Notes say what was searched
// and why nothing was reported when a candidate was refused.
std::optional<Found> vibration(const Settings& s, std::vector<TraceResidual>& traces,
                               const std::vector<Timed>& tms, std::vector<std::string>& notes) {
  const double w = omega_rad_s(s), f0 = w / (2 * pi);
  double dt = 1e300, duration = 1e300;
  std::size_t longest = 0;
  for (const auto& tm : tms) {
    if (!(tm.step_s > 0)) return std::nullopt;
    dt = std::min(dt, tm.step_s);
    duration = std::min(duration, tm.duration_s);
  }
  // Each trace resampled to the step dt: n_i samples, one segment if n_i <= L (its whole
  // periodogram, padded to a power of two at least twice the longest), else segments of L
  // samples every L / 2 (Welch), each padded to 2 L: the spectra hold O(L), not O(n).
  const std::size_t cap = std::max<std::size_t>(s.segment_samples, 256);
  std::vector<std::size_t> lengths;
  for (const auto& tm : tms) {
    lengths.push_back(static_cast<std::size_t>(std::floor(tm.duration_s / dt)) + 1);
    longest = std::max(longest, std::min(cap, lengths.back()));
  }
  bool welch = false;
  for (std::size_t i = 0; i < tms.size(); ++i)
    if (lengths[i] > cap) {  // the band widths follow the segment's duration
      welch = true;
      duration = std::min(duration, static_cast<double>(cap - 1) * dt);
    }
  std::size_t npad = 1;
  while (npad < 2 * longest) npad *= 2;
  const double df = 1.0 / (static_cast<double>(npad) * dt);
  // Below 10 f0 lie the geometric terms; with segments, also below 10 / T_segment (a segment's
  // own trend and the window's main lobe about 0).
  const double lo_hz = welch ? std::max(10 * f0, 10.0 / duration) : 10 * f0;
  const auto lo = static_cast<std::size_t>(std::ceil(lo_hz / df));
  const auto hi = static_cast<std::size_t>(std::floor(0.45 / dt / df));
  if (hi < lo + 32) {
    notes.push_back(fmt::format(
        "vibration: the band from {} ({:.3f} Hz) to 0.9 times the Nyquist frequency ({:.1f} Hz) "
        "is too narrow to search",
        welch ? "10 times the feed's or the spectrum segment's frequency"
              : "10 times the feed's frequency",
        lo_hz, 0.45 / dt));
    return std::nullopt;
  }
  std::vector<std::vector<double>> ps;
  std::vector<std::size_t> segments;
  std::vector<double> mean(npad / 2 + 1, 0.0);
  // One segment's samples and the transform's buffers are kept from one segment (and trace) to
  // the next: made afresh, their page faults and zeros were a third of the spectra's time in a
  // long run (issue 32). Each segment's second half is the next one's first (Welch's overlap):
  // kept, not resampled again.
  std::vector<double> segment;
  std::optional<Periodograms> periodogram(npad);
  for (std::size_t i = 0; i < traces.size(); ++i) {
    const std::size_t n = lengths[i], len = std::min(n, cap), half = cap / 2;
    const std::size_t count = n <= cap ? 1 : (n - cap) / half + 1;
    segments.push_back(n <= cap ? 1 : n / cap);  // the line fit's: cap samples, the last longer
    // One segment's periodogram, or the average of them (0 + x / 1 is x: one segment's values).
    std::vector<double> p(npad / 2 + 1, 0.0);
    auto series = resampled(traces[i], tms[i], dt);
    overlapping_segments(series, count, len, half, segment, [&](const std::vector<double>& x) {
      periodogram->add(x, static_cast<double>(count), p);
    });
    for (std::size_t k = 0; k < mean.size(); ++k)
      mean[k] += p[k] / static_cast<double>(traces.size());
    ps.push_back(std::move(p));
  }
  periodogram.reset();  // its tables and buffers, before the line fit's
  // The band tests' scratch in the segment's memory, whose pages are already the process's
  // (a fresh 1 MB was page faults: issue 32); it grows if a band needs more.
  std::vector<double> rest = std::move(segment);
  const auto peak = static_cast<std::size_t>(
      std::max_element(mean.begin() + static_cast<std::ptrdiff_t>(lo),
                       mean.begin() + static_cast<std::ptrdiff_t>(hi) + 1) -
      mean.begin());
  const auto half = static_cast<std::size_t>(std::ceil((f0 + 2.5 / duration) / df));
  const std::size_t b0 = std::max(lo, peak > half ? peak - half : 0),
                    b1 = std::min(hi, peak + half);
  const BandTest all = band_test(mean, lo, hi, b0, b1, df, rest);
  if (all.snr < 10.0) return std::nullopt;
  // Narrow: the band stands out of its neighbourhood (three band widths each side). An error
  // that is locked to the position but local (steps, a stick-slip's mean lag about the
  // reversals) puts a comb of harmonics of f0 over the whole band instead of one line.
  const auto width = static_cast<std::ptrdiff_t>(b1 - b0 + 1);
  const auto sb0 = static_cast<std::ptrdiff_t>(b0), sb1 = static_cast<std::ptrdiff_t>(b1);
  const double around = 0.5 * (mean_power(mean, sb0 - 3 * width, sb0 - 1, lo, hi) +
                               mean_power(mean, sb1 + 1, sb1 + 3 * width, lo, hi));
  if (mean_power(mean, sb0, sb1, lo, hi) < 10.0 * around) {
    notes.push_back(fmt::format(
        "vibration: the strongest component above 10 f0, near {:.2f} Hz, is one of a comb of "
        "harmonics of the feed's frequency (an error locked to the position, not a vibration); "
        "not reported",
        all.centroid_hz));
    return std::nullopt;
  }
  for (std::size_t i = 0; i < ps.size(); ++i)
    if (band_test(ps[i], lo, hi, b0, b1, df, rest).snr < 4.0) {
      // Trace i lacks it, so (two traces) the other direction has it.
      notes.push_back(fmt::format(
          "vibration: a narrow-band component near {:.2f} Hz stands out in the {} trace only; "
          "not reported (a vibration does not depend on the direction of travel)",
          all.centroid_hz, traces[i].s > 0 ? "cw" : "ccw"));
      return std::nullopt;
    }
  // The spectra are done with: freed before the line fit keeps its own per-sample tables.
  ps = std::vector<std::vector<double>>();
  mean = std::vector<double>();  // (= {} would keep the capacity)
  rest = std::vector<double>();
  // The frequency that explains most, on a grid over +-1 / T, refined about the best point.
  const LineFit fit{traces, tms, f0, segments, static_cast<double>(cap) * dt, s.pages};
  LineFit::Best best;
  double step = 0.1 / duration;
  fit.trials(all.centroid_hz, step, 10, true, best);  // the centroid -+ 10 steps
  for (int round = 0; round < 3; ++round) {
    step /= 4;
    fit.trials(best.f_hz, step, 3, false, best);  // the best -+ 1, 2, 3 steps
  }
  if (best.normal.empty()) {  // no trial's sum of squares was a number (a singular fit)
    notes.push_back(fmt::format(
        "vibration: the lines near {:.2f} Hz could not be fitted; not reported", all.centroid_hz));
    return std::nullopt;
  }
  const double best_f = best.f_hz;
  std::vector<PagedDoubles> parts;
  std::array<double, 3> power{};
  fit.contribution(best, parts, power);
  if (parts.size() == 1) {
    notes.push_back(
        "vibration: one direction only, so a vibration cannot be told from an error locked to "
        "the position");
  }
  // One line (radial) or two (along a direction: f -+ f0) fit equally well with f shifted by f0;
  // the power-weighted mean of the three lines' frequencies is the vibration's either way.
  const double total = power[0] + power[1] + power[2];
  const double f_hz =
      total > 0 ? (power[0] * (best_f - f0) + power[1] * best_f + power[2] * (best_f + f0)) / total
                : best_f;
  Found out{.key = "vibration",
            .name = fmt::format("Vibration ({:.1f} Hz)", f_hz),
            .unit = "um",
            .frequency_hz = f_hz};
  double ss = 0.0;
  std::size_t n = 0;
  out.contribution = PagedDoubles(0, s.pages);
  for (std::size_t i = 0; i < parts.size(); ++i)
    for (std::size_t j = 0; j < parts[i].size(); ++j) {
      const double p = parts[i][j];
      ss += p * p;
      ++n;
      out.contribution.push_back(p);
      traces[i].r_um.set(j, traces[i].r_um[j] - p);
    }
  out.value = std::sqrt(ss / static_cast<double>(std::max<std::size_t>(1, n)));
  if (out.value < 0.01) {
    for (std::size_t i = 0; i < parts.size(); ++i)  // too small to matter: put it back
      for (std::size_t j = 0; j < parts[i].size(); ++j)
        traces[i].r_um.set(j, traces[i].r_um[j] + parts[i][j]);
    return std::nullopt;
  }
  return out;
}

// Per axis, the high-frequency residual concentrated where that axis moves slowly (about its
// reversals), in excess of the rest of the circle.
std::vector<Found> stick_slip(const Settings& s, const std::vector<TraceResidual>& traces,
                              const std::vector<Timed>& tms, std::vector<std::string>& notes) {
  const double w = omega_rad_s(s), core = 1.0 * deg, window = s.window_deg * deg;
  // The high-passed residual of every sample, the traces one after the other (as a Found's
  // contribution), each in its own order.
  std::size_t total = 0;
  for (const auto& t : traces) total += t.r_um.size();
  PagedDoubles hp(total, s.pages);
  for (std::size_t i = 0, first = 0; i < traces.size(); first += traces[i++].r_um.size()) {
    const auto& t = traces[i];
    const Timed& tm = tms[i];
    const double step_rad = tm.step_s * w;
    const std::size_t m =
        step_rad > 0
            ? std::max<std::size_t>(1, static_cast<std::size_t>(std::lround(2.0 * deg / step_rad)))
            : 1;
    // At most 41 samples of the window (every stride-th): the median of the local level needs
    // no more, and 2 x 36,000 samples at 0.01 degrees would otherwise cost 401 per sample.
    high_pass(t, tm, m, std::max<std::size_t>(1, (2 * m + 1) / 41), hp, first);
  }
  // Angular distance of theta from the nearest reversal of u (0, pi) or of v (+-pi / 2)
  // (|std::remainder|, without its call: angle_reduce.hpp).
  const auto from_u = [](double th) { return abs_remainder(th, pi); };
  const auto from_v = [](double th) { return abs_remainder(th - pi / 2, pi); };
  const auto each_sample = [&](auto&& f) {  // f(index in hp, theta)
    for (std::size_t i = 0, k = 0; i < traces.size(); ++i)
      for (std::size_t j = 0; j < traces[i].r_um.size(); ++j, ++k) f(k, traces[i].theta_rad(j));
  };
  // One pass for the mean squares in and out of the windows; a contribution is made only for
  // an axis that is reported.
  double out_ss = 0.0;
  std::size_t out_n = 0;
  std::array<double, 2> in_ss{};
  std::array<std::size_t, 2> in_n{};
  each_sample([&](std::size_t k, double th) {
    const double du = from_u(th), dv = from_v(th), sq = hp[k] * hp[k];
    if (du > window && dv > window) out_ss += sq, ++out_n;
    if (du >= core && du <= window) in_ss[0] += sq, ++in_n[0];
    if (dv >= core && dv <= window) in_ss[1] += sq, ++in_n[1];
  });
  std::vector<Found> found;
  if (out_n < min_window_samples) return found;
  const double ms_out = out_ss / static_cast<double>(out_n);
  std::vector<bool> of_u;  // found[i] is of the first axis
  for (const bool axis_u : {true, false}) {
    const std::size_t a = axis_u ? 0 : 1;
    if (in_n[a] < min_window_samples) continue;  // the arc does not pass a reversal of the axis
    const double ms_in = in_ss[a] / static_cast<double>(in_n[a]);
    if (ms_in < 2.0 * ms_out || std::sqrt(ms_in - ms_out) < 0.01) continue;
    const char axis = axis_u ? s.u : s.v;
    found.push_back({.key = fmt::format("stick_slip_{}", axis),
                     .name = fmt::format("Stick-slip {} (rms, 1-{:g} deg from its reversals)", axis,
                                         s.window_deg),
                     .unit = "um",
                     .value = std::sqrt(ms_in - ms_out)});
    of_u.push_back(axis_u);
  }
  // Each one's contribution: the high-passed residual in its axis' windows, 0 elsewhere. The
  // last one takes hp's memory (8 bytes a sample: issue 32).
  for (std::size_t f = 0; f < found.size(); ++f) {
    PagedDoubles c = f + 1 == found.size() ? std::move(hp) : hp.copy();
    each_sample([&](std::size_t k, double th) {
      const double d = of_u[f] ? from_u(th) : from_v(th);
      if (!(d >= core && d <= window)) c.set(k, 0.0);
    });
    found[f].contribution = std::move(c);
  }
  if (!found.empty())
    notes.push_back(
        "stick-slip is measured at one feed here: it grows as the feed falls, so compare a slow "
        "and a fast feed before blaming friction (an error locked to the position does not "
        "change with the feed)");
  return found;
}

}  // namespace

Dynamics vibration_and_stick_slip(const Settings& s, std::vector<TraceResidual>& traces,
                                  std::vector<std::string>& notes) {
  std::vector<Timed> tms;  // made once for both (issue 32); the vibration changes no angle
  for (const auto& t : traces) tms.push_back(timed(t, omega_rad_s(s)));
  Dynamics out;
  out.vibration = vibration(s, traces, tms, notes);
  out.stick_slip = stick_slip(s, traces, tms, notes);
  return out;
}

}  // namespace cal::circle::dynamics
