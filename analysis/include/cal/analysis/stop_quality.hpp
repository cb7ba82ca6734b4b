#pragma once
// The quality gate of a run's stops (issue 26; the rule: docs/iso230-2.md, "Suspect stops").
// Per target, the stops are compared with what the run repeats elsewhere: a stop far outside
// the run's own repeatability (a sample of another stop, a glitch) is suspect, and so is its
// run; builders refuse suspect runs unless told. Pure: no I/O.
#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace cal::quality {

// One captured stop, in the run's unit (um, or urad for angular kinds).
struct Stop {
  int target_index = 0;  // 0-based, as in the plan
  int run = 1;           // 1-based run j
  char direction = '+';  // '+' up, '-' down
  double nominal_mm = 0.0;
  double value = 0.0;
};

// A stop beyond the limit: index into the stops given, its residual and why, in words.
struct Suspect {
  std::size_t stop = 0;
  double residual = 0.0;
  std::string reason;
};

struct Assessment {
  // false: nothing to compare a stop with (one run in one direction, fewer than 3 targets).
  bool checked = false;
  // "runs": each stop against the median of its target and direction over the runs;
  // "up/down": one run both ways, each target's up - down against the median over targets.
  std::string basis;
  double median_spread = 0.0;  // the median over the targets of their largest |residual|
  double limit = 0.0;          // max(kOutlierFactor * median_spread, kFloor)
  std::vector<Suspect> suspects;
  std::string summary;  // "ok (...)", "suspect: ...", "not checked: ..."
};

// Five times the run's typical spread: far beyond the scatter of a repeatable run (for
// normal scatter, a residual that large is a few in a million), far below the 0.2 to 0.5 um a
// wrong sample makes.
inline constexpr double kOutlierFactor = 5.0;
// No stop is suspect by less than this (in the run's unit): a simulated run's ~0.001 um
// spread would otherwise make the indicator's 0.01 um digit an outlier.
inline constexpr double kFloor = 0.05;

Assessment assess(std::span<const Stop> stops, std::string_view unit = "um");

}  // namespace cal::quality
