// The quality gate of a run's stops (see stop_quality.hpp).
#include "cal/analysis/stop_quality.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace cal::quality {
namespace {

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  if (v.size() % 2 == 1) return *mid;
  const double upper = *mid;
  return (*std::max_element(v.begin(), mid) + upper) / 2;
}

std::string where(const Stop& s) {
  return fmt::format("run {}{} at {:g} mm", s.run, s.direction == '+' ? " up" : " down",
                     s.nominal_mm);
}

// Each stop's residual against its target's other runs in the same direction (the median of
// the group: one wrong run of three or more does not drag the others); nullopt-like NaN for a
// stop alone in its group.
std::vector<double> residuals_over_runs(std::span<const Stop> stops) {
  std::map<std::pair<int, char>, std::vector<std::size_t>> groups;
  for (std::size_t k = 0; k < stops.size(); ++k)
    groups[{stops[k].target_index, stops[k].direction}].push_back(k);
  std::vector<double> r(stops.size(), std::nan(""));
  for (const auto& [key, members] : groups) {
    if (members.size() < 2) continue;
    std::vector<double> v;
    for (const auto k : members) v.push_back(stops[k].value);
    const double m = median(v);
    for (const auto k : members) r[k] = stops[k].value - m;
  }
  return r;
}

// One run both ways: a target's up - down against the run's typical reversal (the median
// over the targets); both stops of the pair carry the excess (which one is wrong is not
// known).
std::vector<double> residuals_up_down(std::span<const Stop> stops) {
  std::map<int, std::pair<int, int>> pairs;  // target -> (up stop, down stop), -1 when missing
  for (std::size_t k = 0; k < stops.size(); ++k) {
    auto& p = pairs.try_emplace(stops[k].target_index, -1, -1).first->second;
    (stops[k].direction == '+' ? p.first : p.second) = static_cast<int>(k);
  }
  std::vector<double> reversal;
  for (const auto& [t, p] : pairs)
    if (p.first >= 0 && p.second >= 0)
      reversal.push_back(stops[static_cast<std::size_t>(p.first)].value -
                         stops[static_cast<std::size_t>(p.second)].value);
  const double typical = median(reversal);
  std::vector<double> r(stops.size(), std::nan(""));
  for (const auto& [t, p] : pairs) {
    if (p.first < 0 || p.second < 0) continue;
    const auto up = static_cast<std::size_t>(p.first), down = static_cast<std::size_t>(p.second);
    r[up] = r[down] = stops[up].value - stops[down].value - typical;
  }
  return r;
}

}  // namespace

Assessment assess(std::span<const Stop> stops, std::string_view unit) {
  Assessment a;
  std::map<std::pair<int, char>, int> per_group;
  bool up = false, down = false;
  for (const auto& s : stops) {
    ++per_group[{s.target_index, s.direction}];
    (s.direction == '+' ? up : down) = true;
  }
  int runs = 0;
  for (const auto& [key, n] : per_group) runs = std::max(runs, n);
  std::vector<double> r;
  if (runs >= 2) {
    a.basis = "runs";
    r = residuals_over_runs(stops);
  } else if (up && down) {
    a.basis = "up/down";
    r = residuals_up_down(stops);
  } else {
    a.summary = "not checked: one run in one direction (nothing to compare a stop with)";
    return a;
  }
  std::map<int, double> spread;  // target -> its largest |residual|
  for (std::size_t k = 0; k < stops.size(); ++k)
    if (!std::isnan(r[k]))
      spread[stops[k].target_index] = std::max(spread[stops[k].target_index], std::abs(r[k]));
  if (spread.size() < 3) {
    a.summary = fmt::format("not checked: {} target(s) with a {} comparison (3 needed)",
                            spread.size(), a.basis);
    return a;
  }
  std::vector<double> spreads;
  for (const auto& [t, s] : spread) spreads.push_back(s);
  a.checked = true;
  a.median_spread = median(spreads);
  a.limit = std::max(kOutlierFactor * a.median_spread, kFloor);
  const std::string rule =
      fmt::format("limit {:.3f} {} = max({:g} x the median spread {:.3f} {}, {:g} {})", a.limit,
                  unit, kOutlierFactor, a.median_spread, unit, kFloor, unit);
  for (std::size_t k = 0; k < stops.size(); ++k) {
    if (std::isnan(r[k]) || std::abs(r[k]) <= a.limit) continue;
    const auto& s = stops[k];
    const std::string what =
        a.basis == "runs"
            ? fmt::format("{:+.3f} {} from the median of its target's runs", r[k], unit)
            : fmt::format("up - down {:+.3f} {} from the run's typical reversal", r[k], unit);
    a.suspects.push_back({k, r[k], fmt::format("{}: {} ({})", where(s), what, rule)});
  }
  if (a.suspects.empty()) {
    a.summary = fmt::format("ok: every stop within {:.3f} {} of its target's {} ({})", a.limit,
                            unit, a.basis == "runs" ? "other runs" : "up/down", rule);
  } else {
    std::string list;
    for (const auto& x : a.suspects) list += (list.empty() ? "" : ", ") + where(stops[x.stop]);
    a.summary = fmt::format("suspect: {} stop(s) beyond the run's repeatability: {} ({})",
                            a.suspects.size(), list, rule);
  }
  return a;
}

}  // namespace cal::quality
