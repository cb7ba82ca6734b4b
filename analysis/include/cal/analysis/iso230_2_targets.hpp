#pragma once
// ISO 230-2 target positions and test cycles: the ordered moves the machine makes.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace cal::iso230_2 {

enum class Direction { up, down };  // up = towards increasing position ("positive", ↑)
std::string_view to_string(Direction d);

enum class Cycle {
  linear,       // ISO 230-2 standard test cycle: all targets up, over-run, all down, over-run
  pendulum,     // at each target, up and down approaches alternate `runs` times, then next target
  pilgrim_step  // each target approached up, then over-run and approached down, then next target
};
std::string_view to_string(Cycle c);
Cycle cycle_from_string(std::string_view name);  // linear | pendulum | pilgrim-step

// Bounds on a plan's size: far beyond any real test (ISO 230-2 asks for 5 targets per metre
// and 5 runs), small enough that a typo (count = 1e9) is an error, not gigabytes of moves.
inline constexpr int max_plan_targets = 10'000;
inline constexpr int max_plan_runs = 1'000;

// ISO 230-2 for linear axes over 2000 mm (ISO 230-2:2014, 6.2; the test over the whole travel):
// one approach in each direction is enough, at targets an average of 250 mm apart; the
// repeatability and the accuracy A are then not evaluated (they need two or more runs).
inline constexpr double kLongAxisMm = 2000.0;
inline constexpr double kLongAxisIntervalMm = 250.0;
bool is_long_axis(double first_mm, double last_mm);  // last - first > 2000 mm
// The fewest targets whose average interval is at most 250 mm: ceil(length / 250) + 1.
int long_axis_target_count(double first_mm, double last_mm);

struct TargetSpec {
  double first_mm = 0.0;
  double last_mm = 1000.0;
  // Nominal spacing, or the number of targets (including first and last). Neither: allowed
  // for an axis over 2000 mm only, which then gets long_axis_target_count targets.
  std::optional<double> interval_mm;
  std::optional<int> count;
  // Random offset of each inner target, as a fraction of the nominal interval, uniform in
  // [-f, +f]; ISO 230-2 asks for unequal spacing so that periodic errors (scale pitch,
  // ball-screw lead) are not sampled at one phase. 0 gives uniform spacing.
  double random_fraction = 0.0;
  std::uint64_t seed = 1;
  double round_to_mm = 0.001;  // targets land on the machine's programming resolution
};

struct CycleSpec {
  Cycle cycle = Cycle::linear;
  bool bidirectional = true;
  int runs = 5;             // per direction
  double overrun_mm = 5.0;  // beyond the end targets, so each approach comes from one side
};

enum class MoveKind { measure, overrun, reposition };

struct Move {
  MoveKind kind = MoveKind::measure;
  int run = 1;  // 1-based
  Direction direction = Direction::up;
  int target_index = 0;      // 1-based for measure moves, 0 otherwise
  double position_mm = 0.0;  // commanded position
};

struct Plan {
  std::vector<double> targets_mm;
  std::vector<Move> moves;
  std::vector<std::string> warnings;  // departures from the ISO 230-2 recommendations
  std::vector<std::string> notes;     // rules that apply (an axis over 2000 mm)
};

// Targets in increasing order; throws InputError for an empty or inverted range, a bad
// interval or count (more than max_plan_targets included), a random fraction outside [0, 0.5),
// or a rounding step that is not finite and >= 0.
std::vector<double> generate_targets(const TargetSpec& spec);

// The full plan. Throws InputError on bad specs (runs outside 1 .. max_plan_runs, overrun < 0 or
// not finite, ...); ISO 230-2
// recommendations not met (fewer than 5 runs per direction, fewer than 5 targets or than
// 5 per metre; over 2000 mm: an average interval over 250 mm) are warnings.
Plan make_plan(const TargetSpec& targets, const CycleSpec& cycle);

}  // namespace cal::iso230_2
