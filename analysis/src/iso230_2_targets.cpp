#include "cal/analysis/iso230_2_targets.hpp"

#include <fmt/format.h>

#include <cmath>
#include <random>

#include "cal/analysis/enum_names.hpp"
#include "cal/analysis/error.hpp"

namespace cal::iso230_2 {
namespace {

// Uniform in [-1, 1) from a 64-bit Mersenne Twister. std::mt19937_64's sequence is fixed by
// the C++ standard, unlike std::uniform_real_distribution's mapping, so plans are identical
// across compilers and library versions.
class SignedUniform {
 public:
  explicit SignedUniform(std::uint64_t seed) : rng_(seed) {}
  double operator()() { return 2.0 * static_cast<double>(rng_() >> 11) * 0x1.0p-53 - 1.0; }

 private:
  std::mt19937_64 rng_;
};

double round_to(double v, double step) { return step > 0 ? std::round(v / step) * step : v; }

void add(std::vector<Move>& moves, MoveKind kind, int run, Direction dir, int target,
         double pos_mm) {
  moves.push_back(Move{kind, run, dir, target, pos_mm});
}

void linear_moves(const std::vector<double>& t, const CycleSpec& c, std::vector<Move>& m) {
  const int n = static_cast<int>(t.size());
  const double low = t.front() - c.overrun_mm, high = t.back() + c.overrun_mm;
  add(m, MoveKind::reposition, 1, Direction::up, 0, low);
  for (int run = 1; run <= c.runs; ++run) {
    for (int i = 0; i < n; ++i) add(m, MoveKind::measure, run, Direction::up, i + 1, t[i]);
    if (!c.bidirectional) {
      add(m, MoveKind::reposition, run, Direction::down, 0, low);
      continue;
    }
    add(m, MoveKind::overrun, run, Direction::up, 0, high);
    for (int i = n - 1; i >= 0; --i) add(m, MoveKind::measure, run, Direction::down, i + 1, t[i]);
    add(m, MoveKind::overrun, run, Direction::down, 0, low);
  }
}

void pendulum_moves(const std::vector<double>& t, const CycleSpec& c, std::vector<Move>& m) {
  add(m, MoveKind::reposition, 1, Direction::up, 0, t.front() - c.overrun_mm);
  for (int i = 0; i < static_cast<int>(t.size()); ++i) {
    for (int run = 1; run <= c.runs; ++run) {
      // The first up approach of a target comes from the previous target (below it).
      if (run > 1) add(m, MoveKind::overrun, run, Direction::down, 0, t[i] - c.overrun_mm);
      add(m, MoveKind::measure, run, Direction::up, i + 1, t[i]);
      if (!c.bidirectional) continue;
      add(m, MoveKind::overrun, run, Direction::up, 0, t[i] + c.overrun_mm);
      add(m, MoveKind::measure, run, Direction::down, i + 1, t[i]);
    }
  }
}

void pilgrim_moves(const std::vector<double>& t, const CycleSpec& c, std::vector<Move>& m) {
  for (int run = 1; run <= c.runs; ++run) {
    add(m, MoveKind::reposition, run, Direction::up, 0, t.front() - c.overrun_mm);
    for (int i = 0; i < static_cast<int>(t.size()); ++i) {
      add(m, MoveKind::measure, run, Direction::up, i + 1, t[i]);
      add(m, MoveKind::overrun, run, Direction::up, 0, t[i] + c.overrun_mm);
      add(m, MoveKind::measure, run, Direction::down, i + 1, t[i]);
    }
  }
}

// The shown name first; the other spellings are accepted on input.
constexpr EnumName<Cycle> kCycleNames[] = {{Cycle::linear, "linear"},
                                           {Cycle::pendulum, "pendulum"},
                                           {Cycle::pilgrim_step, "pilgrim-step"},
                                           {Cycle::pilgrim_step, "pilgrim_step"},
                                           {Cycle::pilgrim_step, "step"}};
static_assert(cal::names_every_value(kCycleNames));

}  // namespace

std::string_view to_string(Direction d) { return d == Direction::up ? "up" : "down"; }

std::string_view to_string(Cycle c) { return name_of(kCycleNames, c); }

Cycle cycle_from_string(std::string_view name) {
  return parse_name(kCycleNames, name, "test cycle");
}

bool is_long_axis(double first_mm, double last_mm) { return last_mm - first_mm > kLongAxisMm; }

int long_axis_target_count(double first_mm, double last_mm) {
  // A hair of slack so that 3000 mm gives 12 intervals of 250, not 13.
  const double intervals = std::ceil((last_mm - first_mm) / kLongAxisIntervalMm - 1e-9);
  if (!(intervals < max_plan_targets))  // before the cast, which would overflow
    throw InputError(fmt::format("targets: {} .. {} mm at {} mm intervals is more than {} targets",
                                 first_mm, last_mm, kLongAxisIntervalMm, max_plan_targets));
  return static_cast<int>(intervals) + 1;
}

std::vector<double> generate_targets(const TargetSpec& s) {
  if (!std::isfinite(s.first_mm) || !std::isfinite(s.last_mm) || !(s.last_mm > s.first_mm)) {
    throw InputError(fmt::format("targets: last ({} mm) must be greater than first ({} mm)",
                                 s.last_mm, s.first_mm));
  }
  if (s.interval_mm && s.count) {
    throw InputError("targets: give either an interval or a count, not both");
  }
  const bool long_default = !s.interval_mm && !s.count;
  if (long_default && !is_long_axis(s.first_mm, s.last_mm)) {
    throw InputError(fmt::format(
        "targets: give an interval or a count (only an axis over {} mm gets the ISO 230-2 "
        "default of an average interval of {} mm; this one is {} mm)",
        kLongAxisMm, kLongAxisIntervalMm, s.last_mm - s.first_mm));
  }
  const double length = s.last_mm - s.first_mm;
  int count = 0;
  if (long_default) {
    count = long_axis_target_count(s.first_mm, s.last_mm);
  } else if (s.count) {
    count = *s.count;
    if (count < 2 || count > max_plan_targets)
      throw InputError(
          fmt::format("targets: count = {} must be in 2 .. {}", count, max_plan_targets));
  } else {
    const double iv = *s.interval_mm;
    if (!(iv > 0) || !std::isfinite(iv))
      throw InputError(fmt::format("targets: interval = {} mm must be finite and > 0", iv));
    const double steps = length / iv;
    if (!(steps < max_plan_targets))  // before the cast below, which would overflow
      throw InputError(
          fmt::format("targets: interval {} mm gives {:.0f} targets over {} .. {} mm, more than {}",
                      iv, steps + 1, s.first_mm, s.last_mm, max_plan_targets));
    if (std::abs(steps - std::round(steps)) > 1e-6 * std::max(1.0, steps)) {
      throw InputError(fmt::format(
          "targets: interval {} mm does not divide the travel {} .. {} mm into whole steps", iv,
          s.first_mm, s.last_mm));
    }
    count = static_cast<int>(std::round(steps)) + 1;
  }
  if (!(s.round_to_mm >= 0) || !std::isfinite(s.round_to_mm)) {
    throw InputError(
        fmt::format("targets: rounding step {} mm must be finite and >= 0", s.round_to_mm));
  }
  if (!(s.random_fraction >= 0 && s.random_fraction < 0.5)) {
    throw InputError(
        fmt::format("targets: random fraction = {} must be in [0, 0.5)", s.random_fraction));
  }
  const double interval = length / (count - 1);
  SignedUniform uniform(s.seed);
  std::vector<double> t(static_cast<std::size_t>(count));
  for (int i = 0; i < count; ++i) {
    const bool inner = i > 0 && i < count - 1;  // the end targets stay on the travel limits
    const double offset = inner ? s.random_fraction * interval * uniform() : 0.0;
    t[i] = round_to(s.first_mm + i * interval + offset, s.round_to_mm);
  }
  for (int i = 1; i < count; ++i) {
    if (!(t[i] > t[i - 1])) {
      throw InputError(
          fmt::format("targets: rounding to {} mm merges targets {} and {}; use a finer rounding",
                      s.round_to_mm, i, i + 1));
    }
  }
  return t;
}

Plan make_plan(const TargetSpec& ts, const CycleSpec& cs) {
  if (cs.runs < 1 || cs.runs > max_plan_runs)
    throw InputError(fmt::format("cycle: runs = {} must be in 1 .. {}", cs.runs, max_plan_runs));
  if (!(cs.overrun_mm >= 0) || !std::isfinite(cs.overrun_mm)) {
    throw InputError(fmt::format("cycle: over-run = {} mm must be >= 0", cs.overrun_mm));
  }
  if (cs.cycle == Cycle::pilgrim_step && !cs.bidirectional) {
    throw InputError(
        "cycle: the pilgrim-step cycle approaches every target in both directions; "
        "use the linear cycle for a unidirectional test");
  }
  Plan p;
  p.targets_mm = generate_targets(ts);
  const double length_m = (ts.last_mm - ts.first_mm) / 1000.0;
  const auto n_targets = p.targets_mm.size();
  if (is_long_axis(ts.first_mm, ts.last_mm)) {
    p.notes.push_back(fmt::format(
        "axis over {} mm: ISO 230-2 tests the whole travel with one approach in each direction "
        "or more, targets an average of {} mm apart; with one run the repeatability and the "
        "accuracy A are not evaluated (ISO 230-2:2014, 6.2), and a {} mm section may be tested "
        "with the usual 5 runs if agreed",
        kLongAxisMm, kLongAxisIntervalMm, kLongAxisMm));
    const double average_mm = (ts.last_mm - ts.first_mm) / static_cast<double>(n_targets - 1);
    if (average_mm > kLongAxisIntervalMm + 1e-9) {
      p.warnings.push_back(fmt::format(
          "{} targets over {} m, an average interval of {:.1f} mm: ISO 230-2 asks for {} mm or "
          "less on an axis over {} mm ({} targets)",
          n_targets, length_m, average_mm, kLongAxisIntervalMm, kLongAxisMm,
          long_axis_target_count(ts.first_mm, ts.last_mm)));
    }
  } else {
    if (cs.runs < 5) {
      p.warnings.push_back(
          fmt::format("{} runs per direction: ISO 230-2 asks for at least 5", cs.runs));
    }
    if (n_targets < 5 || static_cast<double>(n_targets) < 5.0 * length_m) {
      p.warnings.push_back(fmt::format(
          "{} targets over {} m: ISO 230-2 asks for at least 5 per metre and at least 5 in all",
          n_targets, length_m));
    }
  }
  if (cs.overrun_mm == 0 && cs.bidirectional) {
    p.warnings.push_back("no over-run: reversals happen at the end targets themselves");
  }
  switch (cs.cycle) {
    case Cycle::linear:
      linear_moves(p.targets_mm, cs, p.moves);
      break;
    case Cycle::pendulum:
      pendulum_moves(p.targets_mm, cs, p.moves);
      break;
    case Cycle::pilgrim_step:
      pilgrim_moves(p.targets_mm, cs, p.moves);
      break;
  }
  return p;
}

}  // namespace cal::iso230_2
