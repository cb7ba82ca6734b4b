#pragma once
// Compensation tables for the machine's controller from measured ISO 230-2 runs: per-axis
// positioning compensation on a regular grid (start, interval, points), one table plus
// backlash or separate forward/reverse tables, absolute or incremental values, error or
// correction sign, machine units and resolution; and writers for a documented CSV and
// controller formats (docs/compensation-tables.md says which parts of each format are from
// public documentation). Analysis does no I/O: writers return the text.
#include <span>
#include <string>
#include <vector>

#include "cal/analysis/iso230_2.hpp"

namespace cal::comptable {

// What a table's values are: the correction (-error, what the control adds to the position) or
// the measured error (measured - target). Each controller format has its vendor's own
// (comp_meaning.hpp); only caldaq's CSV lets the user choose.
enum class Sign { correction, error };

// Bounds of a table (see positioning()): a grid within +-100 m of at most 100 000 points.
inline constexpr double max_position_mm = 100'000;
inline constexpr int max_points = 100'000;
enum class Units { mm, um, inch };
enum class Outside { refuse, hold };  // grid points beyond the measured targets

struct Spec {
  std::string axis = "X";
  double start_mm = 0.0;
  double interval_mm = 10.0;
  int points = 2;
  bool bidirectional = false;  // separate forward/reverse tables; else one table + backlash
  bool incremental = false;    // each value relative to the previous point (the first absolute)
  Sign sign = Sign::correction;
  Units units = Units::mm;
  double resolution = 0.0001;  // in `units`; values are rounded to it (0: no rounding)
  Outside outside = Outside::refuse;
};

struct Table {
  Spec spec;
  std::vector<double> position_mm;
  std::vector<double> forward;  // in spec.units; also the single table when !bidirectional
  std::vector<double> reverse;  // bidirectional only
  double backlash = 0.0;  // !bidirectional: the mean reversal, in spec.units (>= 0 lost motion)
};

// From the per-target statistics of an evaluation (mean deviations up and down, um): the
// forward table from x-bar-up, the reverse from x-bar-down, or one table from the
// bidirectional mean x-bar with backlash = mean(x-bar-down - x-bar-up) (lost motion makes the
// down approach stop higher). Linear interpolation between targets. Throws cal::InputError
// for interval <= 0, points < 2, resolution < 0, fewer than 2 targets, or a grid point
// outside the measured range under Outside::refuse; also for an axis name that is not letters
// and digits (a letter first, at most 8), a grid beyond the bounds above, a resolution other
// than 0 or 1e-9 .. 1. Every writer validates again and refuses a table holding a number that
// is not finite.
Table positioning(const Spec& spec, std::span<const iso230_2::TargetStats> targets);

// A straightness cross-compensation: the correction of axis `slave` as a function of the
// position of axis `spec.axis`, from a straightness run (deviations in um); the slope (i.e.
// squareness) is kept unless remove_slope.
Table cross(const Spec& spec, std::span<const double> position_mm,
            std::span<const double> deviation_um, bool remove_slope);

std::string units_name(Units u);
// Micrometres in one of the table's units (1000 per mm, 25400 per inch exactly, 1 per um).
double um_per_unit(Units u);
Units units_from_string(const std::string& s);

// A number of a controller table: cal::control_text (fixed_text.hpp), rounded half away from
// zero, never "-0.000"; a value that is not finite is refused.
std::string fixed(double v, int decimals);

// Writers. Each refuses a table whose sign is not its format's (comp_meaning.hpp: LinuxCNC
// corrections; SINUMERIK LEC and the ISG list errors); every value in fixed notation, no -0.
std::string write_csv(const Table& t);       // caldaq comp-table CSV (documented columns)
std::string write_linuxcnc(const Table& t);  // LinuxCNC COMP_FILE, COMP_FILE_TYPE = 1
std::string write_siemens(const Table& t, int axis_number = 1);  // 840D LEC, $AA_ENC_COMP
std::string write_isg(const Table& t);  // Beckhoff TwinCAT CNC / ISG SSFK list

// What a written table does on the machine: the correction the control adds (um) at each grid
// point moving in the positive (forward) and negative (reverse) direction, computed from the
// values as written (rounded, in the format's sign and units, increments summed), so that a
// residual computed with it is what the file leaves, not what was meant. backlash_in_table:
// the format carries both directions (LinuxCNC, the ISG list, HEIDENHAIN's BACKLASH column);
// else both directions get the one table and the reversal is left to the control's backlash
// parameter (it then shows in the residual).
struct Applied {
  std::vector<double> position_mm, forward_um, reverse_um;
};
Applied applied(const Table& t, bool backlash_in_table);
// The correction at x (um): linear between grid points, the end values held beyond them (as
// the controls named here do outside a table).
double correction_at_um(const std::vector<double>& position_mm, const std::vector<double>& um,
                        double x_mm);

// Per target: what the measured mean deviations become with the applied table (um), and the
// largest before and after.
struct PredictedResidual {
  std::vector<double> target_mm, before_up_um, before_down_um, up_um, down_um;
  double before_max_um = 0.0, after_max_um = 0.0;
};
PredictedResidual predict(const Applied& a, std::span<const iso230_2::TargetStats> targets);

}  // namespace cal::comptable
