#pragma once
// Evaluation of the positioning test of a numerically controlled axis: ISO 230-2 (2014,
// 2006, 1997, 1988), VDI/DGQ 3441, and the national adoptions JIS B 6190-2 and GB/T
// 17421.2. ASME B5.54 is not implemented: its definitions are not public (see
// docs/iso230-2.md). Formulas and sources: docs/iso230-2.md and iso230_2.cpp.
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cal/analysis/iso230_2_targets.hpp"

namespace cal::iso230_2 {

// One positional deviation x_ij: measured position minus target position.
struct Measurement {
  double target_mm = 0.0;
  int run = 1;  // j, 1-based
  Direction direction = Direction::up;
  double deviation_um = 0.0;
};

enum class Standard {
  iso230_2_2014,
  iso230_2_2006,
  iso230_2_1997,
  iso230_2_1988,
  vdi_3441_1977,
  jis_b6190_2_2008,
  gbt_17421_2_2016,
  gbt_17421_2_2000,
};

struct StandardInfo {
  Standard id;
  std::string_view key;    // the name used on the command line and in JSON
  std::string_view title;  // e.g. "ISO 230-2:2014"
  std::string_view note;   // how it relates to the others
};

std::span<const StandardInfo> standards();
const StandardInfo& info(Standard s);
// Throws InputError listing the known keys.
Standard standard_from_string(std::string_view key);

// Statistics of one target, the same in every standard (means and n-1 standard deviations).
struct TargetStats {
  double target_mm = 0.0;
  int runs_up = 0, runs_down = 0;
  double mean_up_um = 0, mean_down_um = 0;  // x̄i↑, x̄i↓
  double s_up_um = 0, s_down_um = 0;        // si↑, si↓ (estimators, n - 1 in the denominator)
  double mean_bi_um = 0;                    // x̄i = (x̄i↑ + x̄i↓) / 2
  double reversal_um = 0;                   // Bi = x̄i↑ - x̄i↓ (signed)
};

// A value per target, in the order of the targets.
struct PerTarget {
  std::string key;     // stable identifier, e.g. "R_i_bi"
  std::string symbol;  // as printed by the standard, e.g. "Ri"
  std::string description;
  std::vector<double> values_um;
};

// A value of the axis.
struct AxisResult {
  std::string key;  // stable identifier, e.g. "A_bi", "P", "Ps_max"
  std::string symbol;
  std::string description;
  double value_um = 0.0;
};

struct Evaluation {
  StandardInfo standard;
  bool bidirectional = true;
  int runs = 0;  // the number of runs per direction (the smallest over the targets)
  std::vector<TargetStats> targets;
  std::vector<PerTarget> per_target;
  std::vector<AxisResult> axis;
  std::vector<std::string> warnings;
  std::vector<std::string> notes;  // rules applied (an axis over 2000 mm)
  // An axis over 2000 mm measured with one approach per direction (ISO 230-2:2014, 6.2): only
  // the means, the reversal, E and M are evaluated; no s, repeatability or accuracy A.
  bool single_run_long_axis = false;

  // Throws std::out_of_range naming the key when the standard does not define it.
  const AxisResult& at(std::string_view key) const;
  const PerTarget& per_target_at(std::string_view key) const;
};

// The statistics per target. Throws InputError for: no data, non-finite values, a run
// number < 1, a (target, run, direction) measured twice, a target with fewer than 2 runs
// in a direction, or a target measured in only one direction while others have both.
// evaluate() accepts one run per direction on an axis over 2000 mm under ISO 230-2:2014
// (6.2 of the standard) and evaluates what that allows; other standards and shorter axes
// need 2 runs or more.
std::vector<TargetStats> target_stats(std::span<const Measurement> data);
// The same with fewer runs allowed: min_runs = 1 for an axis over 2000 mm (s is then 0).
std::vector<TargetStats> target_stats(std::span<const Measurement> data, int min_runs);

Evaluation evaluate(std::span<const Measurement> data, Standard standard);

}  // namespace cal::iso230_2
