// Positioning-test evaluation. Notation of ISO 230-2: target i = 1..m, run j = 1..n,
// x_ij = measured position - target position (positional deviation), ↑ / ↓ = approach in
// the positive / negative direction. The per-target statistics are the same in all the
// standards; the standards differ in coverage (2 s since ISO 230-2:1997, 3 s before) and in
// which axis values they define. Sources for each formula: docs/iso230-2.md.
#include "cal/analysis/iso230_2.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <stdexcept>

#include "cal/analysis/error.hpp"

namespace cal::iso230_2 {
namespace {

constexpr std::array kStandards{
    StandardInfo{Standard::iso230_2_2014, "iso230-2:2014", "ISO 230-2:2014",
                 "4th edition; definitions as in the 2006 edition"},
    StandardInfo{Standard::iso230_2_2006, "iso230-2:2006", "ISO 230-2:2006",
                 "3rd edition; definitions as in 1997, adds the uncertainty annex"},
    StandardInfo{Standard::iso230_2_1997, "iso230-2:1997", "ISO 230-2:1997",
                 "2nd edition; introduced 2 s coverage (R = 4 s) and E, M"},
    StandardInfo{Standard::iso230_2_1988, "iso230-2:1988", "ISO 230-2:1988",
                 "1st edition; 3 s coverage (R = 6 s), as BS 3800 and VDI/DGQ 3441"},
    StandardInfo{Standard::vdi_3441_1977, "vdi3441", "VDI/DGQ 3441:1977",
                 "position uncertainty P with 6 s position scatter and reversal span U"},
    StandardInfo{Standard::jis_b6190_2_2008, "jis-b6190-2:2008", "JIS B 6190-2:2008",
                 "Japanese adoption of ISO 230-2:2006; same definitions"},
    StandardInfo{Standard::gbt_17421_2_2016, "gb/t17421.2-2016", "GB/T 17421.2-2016",
                 "Chinese adoption of ISO 230-2:2006; same definitions"},
    StandardInfo{Standard::gbt_17421_2_2000, "gb/t17421.2-2000", "GB/T 17421.2-2000",
                 "Chinese adoption of ISO 230-2:1997; same definitions"},
};

// Two targets closer than this are the same target (the CSV may round differently).
constexpr double kSameTargetMm = 1e-6;

struct Samples {
  std::map<int, double> up, down;  // run -> deviation
};

double mean(const std::map<int, double>& x) {
  double s = 0;
  for (const auto& [run, v] : x) s += v;
  return s / static_cast<double>(x.size());
}

// Estimator of the standard uncertainty (ISO 230-2) / standard deviation (VDI 3441, ISO
// 230-2:1988): s = sqrt(1/(n-1) sum (x_j - x̄)^2).
double stddev(const std::map<int, double>& x, double m) {
  if (x.size() < 2) return 0.0;  // one run (axis over 2000 mm): no estimate, not used
  double s = 0;
  for (const auto& [run, v] : x) s += (v - m) * (v - m);
  return std::sqrt(s / static_cast<double>(x.size() - 1));
}

void check_measurement(const Measurement& m, std::size_t row) {
  if (!std::isfinite(m.target_mm) || !std::isfinite(m.deviation_um)) {
    throw InputError(fmt::format("measurement {}: target {} mm, deviation {} um: not a number",
                                 row + 1, m.target_mm, m.deviation_um));
  }
  if (m.run < 1) {
    throw InputError(fmt::format("measurement {}: run = {} must be >= 1", row + 1, m.run));
  }
}

std::vector<std::pair<double, Samples>> group(std::span<const Measurement> data) {
  // Sort row indices by target, then sweep: O(N log N) rather than a search per row.
  std::vector<std::size_t> order(data.size());
  for (std::size_t k = 0; k < data.size(); ++k) {
    check_measurement(data[k], k);
    order[k] = k;
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return data[a].target_mm < data[b].target_mm;
  });
  std::vector<std::pair<double, Samples>> g;
  for (std::size_t k : order) {
    const auto& m = data[k];
    if (g.empty() || m.target_mm - g.back().first >= kSameTargetMm) g.push_back({m.target_mm, {}});
    auto& runs = m.direction == Direction::up ? g.back().second.up : g.back().second.down;
    if (!runs.emplace(m.run, m.deviation_um).second) {
      throw InputError(fmt::format("target {} mm, run {}, direction {} is measured twice",
                                   m.target_mm, m.run, to_string(m.direction)));
    }
  }
  return g;
}

void check_runs(double target_mm, const std::map<int, double>& x, Direction d, int min_runs) {
  if (static_cast<int>(x.size()) < min_runs) {
    throw InputError(fmt::format(
        "target {} mm has {} run(s) in direction {}: at least {} are needed{}", target_mm, x.size(),
        to_string(d), min_runs,
        min_runs == 2 ? " for a standard uncertainty (ISO 230-2 asks for 5; one run in each "
                        "direction is allowed by ISO 230-2:2014 on an axis over 2000 mm)"
                      : ""));
  }
}

// Per-target x̄↑ ± k s↑ bands etc. A helper so that each standard states only its coverage.
struct Band {
  double lo, hi;
};
Band band(double mean_um, double s_um, double k) {
  return {mean_um - k * s_um, mean_um + k * s_um};
}

template <typename F>
std::vector<double> per_target(const std::vector<TargetStats>& t, F f) {
  std::vector<double> v;
  v.reserve(t.size());
  for (const auto& s : t) v.push_back(f(s));
  return v;
}

double max_of(const std::vector<double>& v) { return *std::max_element(v.begin(), v.end()); }
double min_of(const std::vector<double>& v) { return *std::min_element(v.begin(), v.end()); }
double mean_of(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return s / static_cast<double>(v.size());
}

class Builder {
 public:
  explicit Builder(Evaluation& e) : e_(e) {}
  const std::vector<double>& target(std::string key, std::string symbol, std::string desc,
                                    std::vector<double> v) {
    e_.per_target.push_back({std::move(key), std::move(symbol), std::move(desc), std::move(v)});
    return e_.per_target.back().values_um;
  }
  void axis(std::string key, std::string symbol, std::string desc, double v) {
    e_.axis.push_back({std::move(key), std::move(symbol), std::move(desc), v});
  }

 private:
  Evaluation& e_;
};

// ISO 230-2 (1997, 2006, 2014 and their national adoptions) with coverage k = 2, and the
// 1988 edition with k = 3. `k` multiplies s in the bands; repeatability is 2k s.
//   x̄i↑ = (1/n) Σj xij↑                    (mean unidirectional positional deviation)
//   x̄i = (x̄i↑ + x̄i↓) / 2                  (mean bidirectional positional deviation)
//   Bi = x̄i↑ − x̄i↓;  B = max|Bi|;  B̄ = (1/m) Σi Bi   (reversal values)
//   Ri↑ = 2k si↑;  Ri = max(k si↑ + k si↓ + |Bi|; Ri↑; Ri↓);  R↑ = max Ri↑;  R = max Ri
//   E↑ = max x̄i↑ − min x̄i↑;  E = max(x̄i↑; x̄i↓) − min(x̄i↑; x̄i↓)
//   M = max x̄i − min x̄i
//   A↑ = max(x̄i↑ + k si↑) − min(x̄i↑ − k si↑);  A = max over both directions − min
void iso(Evaluation& e, double k, bool has_e_and_m) {
  Builder b(e);
  const auto& t = e.targets;
  // One approach per direction (axis over 2000 mm): no s, so no repeatability and no A.
  const bool with_s = !e.single_run_long_axis;
  const std::string ks = k == 2.0 ? "2" : "3", rs = k == 2.0 ? "4" : "6";
  b.target("mean_up", "x̄i↑", "mean unidirectional positional deviation, up",
           per_target(t, [](auto& s) { return s.mean_up_um; }));
  std::vector<double> r_up, hi_all, lo_all;
  if (with_s) {
    b.target("s_up", "si↑", "estimator of the unidirectional standard uncertainty, up",
             per_target(t, [](auto& s) { return s.s_up_um; }));
    r_up = b.target("R_i_up", "Ri↑", "unidirectional repeatability, up (" + rs + " si↑)",
                    per_target(t, [k](auto& s) { return 2 * k * s.s_up_um; }));
    hi_all = per_target(t, [k](auto& s) { return band(s.mean_up_um, s.s_up_um, k).hi; });
    lo_all = per_target(t, [k](auto& s) { return band(s.mean_up_um, s.s_up_um, k).lo; });
  }
  std::vector<double> means_up = per_target(t, [](auto& s) { return s.mean_up_um; });
  if (with_s) b.axis("R_up", "R↑", "unidirectional repeatability of the axis, up", max_of(r_up));
  if (has_e_and_m) {
    b.axis("E_up", "E↑", "unidirectional systematic positional deviation, up",
           max_of(means_up) - min_of(means_up));
  }
  if (with_s)
    b.axis("A_up", "A↑", "unidirectional accuracy of positioning, up (±" + ks + " s)",
           max_of(hi_all) - min_of(lo_all));
  if (!e.bidirectional) return;

  b.target("mean_down", "x̄i↓", "mean unidirectional positional deviation, down",
           per_target(t, [](auto& s) { return s.mean_down_um; }));
  std::vector<double> r_down, r_bi, hi_down, lo_down;
  if (with_s) {
    b.target("s_down", "si↓", "estimator of the unidirectional standard uncertainty, down",
             per_target(t, [](auto& s) { return s.s_down_um; }));
    r_down = b.target("R_i_down", "Ri↓", "unidirectional repeatability, down (" + rs + " si↓)",
                      per_target(t, [k](auto& s) { return 2 * k * s.s_down_um; }));
  }
  const auto mean_bi = b.target("mean_bi", "x̄i", "mean bidirectional positional deviation",
                                per_target(t, [](auto& s) { return s.mean_bi_um; }));
  const auto rev = b.target("B_i", "Bi", "reversal value (x̄i↑ − x̄i↓)",
                            per_target(t, [](auto& s) { return s.reversal_um; }));
  if (with_s) {
    r_bi = b.target(
        "R_i_bi", "Ri",
        "bidirectional repeatability, max(" + ks + " si↑ + " + ks + " si↓ + |Bi|; Ri↑; Ri↓)",
        per_target(t, [k](auto& s) {
          return std::max({k * s.s_up_um + k * s.s_down_um + std::abs(s.reversal_um),
                           2 * k * s.s_up_um, 2 * k * s.s_down_um});
        }));
    hi_down = per_target(t, [k](auto& s) { return band(s.mean_down_um, s.s_down_um, k).hi; });
    lo_down = per_target(t, [k](auto& s) { return band(s.mean_down_um, s.s_down_um, k).lo; });
  }
  std::vector<double> means_down = per_target(t, [](auto& s) { return s.mean_down_um; });
  std::vector<double> abs_rev = per_target(t, [](auto& s) { return std::abs(s.reversal_um); });

  b.axis("B", "B", "reversal value of the axis, max |Bi|", max_of(abs_rev));
  b.axis("B_mean", "B̄", "mean reversal value of the axis, (1/m) Σ Bi", mean_of(rev));
  if (with_s) {
    b.axis("R_down", "R↓", "unidirectional repeatability of the axis, down", max_of(r_down));
    b.axis("R_bi", "R", "bidirectional repeatability of the axis, max Ri", max_of(r_bi));
  }
  if (has_e_and_m) {
    b.axis("E_down", "E↓", "unidirectional systematic positional deviation, down",
           max_of(means_down) - min_of(means_down));
    b.axis("E_bi", "E", "bidirectional systematic positional deviation",
           std::max(max_of(means_up), max_of(means_down)) -
               std::min(min_of(means_up), min_of(means_down)));
    b.axis("M", "M", "range of the mean bidirectional positional deviation",
           max_of(mean_bi) - min_of(mean_bi));
  }
  if (with_s) {
    b.axis("A_down", "A↓", "unidirectional accuracy of positioning, down (±" + ks + " s)",
           max_of(hi_down) - min_of(lo_down));
    b.axis("A_bi", "A", "bidirectional accuracy of positioning (±" + ks + " s)",
           std::max(max_of(hi_all), max_of(hi_down)) - std::min(min_of(lo_all), min_of(lo_down)));
  }
}

// VDI/DGQ 3441 (1977), bidirectional only:
//   Uj = |x̄j↑ − x̄j↓|               reversal span (Umkehrspanne)
//   Psj = 6 s̄j, s̄j = (sj↑ + sj↓)/2   position scatter (Positionsstreubreite)
//   x̄j = (x̄j↑ + x̄j↓)/2
//   Pa = max x̄j − min x̄j            position deviation (Positionsabweichung)
//   P = max(x̄j + (Uj + Psj)/2) − min(x̄j − (Uj + Psj)/2)   position uncertainty
//   Ps max, Ps mean, U max, U mean.
void vdi3441(Evaluation& e) {
  if (!e.bidirectional) {
    throw InputError("VDI/DGQ 3441 evaluates bidirectional tests: the data has no down runs");
  }
  Builder b(e);
  const auto& t = e.targets;
  const auto& mean_bi = b.target("mean_bi", "x̄j", "mean of both directions",
                                 per_target(t, [](auto& s) { return s.mean_bi_um; }));
  const auto& u = b.target("U_j", "Uj", "reversal span |x̄j↑ − x̄j↓|",
                           per_target(t, [](auto& s) { return std::abs(s.reversal_um); }));
  const auto& ps = b.target("Ps_j", "Psj", "position scatter 6 (sj↑ + sj↓)/2",
                            per_target(t, [](auto& s) { return 3.0 * (s.s_up_um + s.s_down_um); }));
  std::vector<double> hi, lo;
  for (std::size_t j = 0; j < t.size(); ++j) {
    hi.push_back(mean_bi[j] + (u[j] + ps[j]) / 2);
    lo.push_back(mean_bi[j] - (u[j] + ps[j]) / 2);
  }
  b.axis("P", "P", "position uncertainty", max_of(hi) - min_of(lo));
  b.axis("Pa", "Pa", "position deviation, max x̄j − min x̄j", max_of(mean_bi) - min_of(mean_bi));
  b.axis("Ps_max", "Ps max", "largest position scatter", max_of(ps));
  b.axis("Ps_mean", "Ps mean", "mean position scatter", mean_of(ps));
  b.axis("U_max", "U max", "largest reversal span", max_of(u));
  b.axis("U_mean", "U mean", "mean reversal span", mean_of(u));
}

}  // namespace

std::span<const StandardInfo> standards() { return kStandards; }

const StandardInfo& info(Standard s) {
  for (const auto& i : kStandards)
    if (i.id == s) return i;
  throw std::logic_error("unknown standard enumerator");
}

Standard standard_from_string(std::string_view key) {
  std::string known;
  for (const auto& i : kStandards) {
    if (i.key == key) return i.id;
    known += (known.empty() ? "" : ", ") + std::string(i.key);
  }
  if (key == "iso230-2") return Standard::iso230_2_2014;  // the current edition
  if (key == "vdi3441:1977") return Standard::vdi_3441_1977;
  throw InputError(fmt::format("unknown standard '{}': expected one of iso230-2, {}", key, known));
}

const AxisResult& Evaluation::at(std::string_view key) const {
  for (const auto& r : axis)
    if (r.key == key) return r;
  throw std::out_of_range(fmt::format("{} defines no axis result '{}'", standard.title, key));
}

const PerTarget& Evaluation::per_target_at(std::string_view key) const {
  for (const auto& r : per_target)
    if (r.key == key) return r;
  throw std::out_of_range(fmt::format("{} defines no per-target result '{}'", standard.title, key));
}

std::vector<TargetStats> target_stats(std::span<const Measurement> data) {
  return target_stats(data, 2);
}

std::vector<TargetStats> target_stats(std::span<const Measurement> data, int min_runs) {
  if (data.empty()) throw InputError("no measurements");
  const auto groups = group(data);
  const bool any_down = std::any_of(groups.begin(), groups.end(),
                                    [](const auto& g) { return !g.second.down.empty(); });
  const bool any_up =
      std::any_of(groups.begin(), groups.end(), [](const auto& g) { return !g.second.up.empty(); });
  std::vector<TargetStats> out;
  for (const auto& [target, s] : groups) {
    TargetStats ts;
    ts.target_mm = target;
    if (any_up) check_runs(target, s.up, Direction::up, min_runs);
    if (any_down) check_runs(target, s.down, Direction::down, min_runs);
    // A down-only test is evaluated like an up-only one: its values sit in the "up" slots.
    const auto& first = any_up ? s.up : s.down;
    ts.runs_up = static_cast<int>(first.size());
    ts.mean_up_um = mean(first);
    ts.s_up_um = stddev(first, ts.mean_up_um);
    ts.mean_bi_um = ts.mean_up_um;
    if (any_up && any_down) {
      ts.runs_down = static_cast<int>(s.down.size());
      ts.mean_down_um = mean(s.down);
      ts.s_down_um = stddev(s.down, ts.mean_down_um);
      ts.mean_bi_um = (ts.mean_up_um + ts.mean_down_um) / 2;
      ts.reversal_um = ts.mean_up_um - ts.mean_down_um;
    }
    out.push_back(ts);
  }
  return out;
}

Evaluation evaluate(std::span<const Measurement> data, Standard standard) {
  Evaluation e;
  e.standard = info(standard);
  if (data.empty()) throw InputError("no measurements");
  double first = data.front().target_mm, last = first;
  for (const auto& m : data)
    first = std::min(first, m.target_mm), last = std::max(last, m.target_mm);
  // ISO 230-2:2014, 6.2: an axis over 2000 mm may be measured with one approach per direction.
  const bool long_axis = standard == Standard::iso230_2_2014 && is_long_axis(first, last);
  e.targets = target_stats(data, long_axis ? 1 : 2);
  e.bidirectional = std::any_of(data.begin(), data.end(),
                                [](const auto& m) { return m.direction == Direction::down; }) &&
                    std::any_of(data.begin(), data.end(),
                                [](const auto& m) { return m.direction == Direction::up; });
  int min_runs = e.targets.front().runs_up, max_runs = min_runs;
  for (const auto& t : e.targets) {
    for (int n : {t.runs_up, e.bidirectional ? t.runs_down : t.runs_up}) {
      min_runs = std::min(min_runs, n);
      max_runs = std::max(max_runs, n);
    }
  }
  e.runs = min_runs;
  if (min_runs != max_runs) {
    e.warnings.push_back(
        fmt::format("targets have between {} and {} runs per direction", min_runs, max_runs));
  }
  e.single_run_long_axis = long_axis && min_runs == 1;
  if (e.single_run_long_axis) {
    e.notes.push_back(fmt::format(
        "axis of {} mm (over {} mm) with one approach per direction: ISO 230-2:2014, 6.2, "
        "evaluates the means, the reversal, E and M; no repeatability and no accuracy A",
        last - first, kLongAxisMm));
  } else if (min_runs < 5) {
    e.warnings.push_back(
        fmt::format("{} runs per direction: {} asks for at least 5", min_runs, e.standard.title));
  }
  if (e.targets.size() < 5) {
    e.warnings.push_back(
        fmt::format("{} targets: {} asks for at least 5", e.targets.size(), e.standard.title));
  }
  switch (standard) {
    case Standard::iso230_2_2014:
    case Standard::iso230_2_2006:
    case Standard::iso230_2_1997:
    case Standard::jis_b6190_2_2008:
    case Standard::gbt_17421_2_2016:
    case Standard::gbt_17421_2_2000:
      iso(e, 2.0, true);
      break;
    case Standard::iso230_2_1988:
      iso(e, 3.0, false);
      break;
    case Standard::vdi_3441_1977:
      vdi3441(e);
      break;
  }
  return e;
}

}  // namespace cal::iso230_2
