#pragma once
// Command-line values checked at the door (docs/cli.md, "Numbers"): every floating-point
// option takes only a finite plain decimal (no nan, inf, hex), every integer option only a
// plain decimal integer in its type's range ("010" is ten, not eight; "-1" is refused for a
// count); options whose meaning bounds them check their range by name.
#include <CLI/CLI.hpp>

#include "csv_table.hpp"

namespace daq {

// Walks `app` and all its subcommands and adds the checks above to every numeric option, by
// the type CLI11 knows for it (call once, after every command is added).
void check_numbers(CLI::App& app);

// A finite number within [lo, hi] (CLI::Range lets NaN through).
CLI::Validator finite_in(double lo, double hi);

// --decimal-comma: the CSV input has decimal commas and ';' between cells (csv_table.hpp).
void add_decimal_comma_flag(CLI::App& cmd, CsvOptions& csv);

}  // namespace daq
