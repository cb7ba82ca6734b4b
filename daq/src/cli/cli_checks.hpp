#pragma once
// Command-line values checked at the door (docs/cli.md, "Numbers"): every floating-point
// option takes only a finite plain decimal (no nan, inf, hex), every integer option only a
// plain decimal integer in its type's range ("010" is ten, not eight; "-1" is refused for a
// count); options whose meaning bounds them check their range with the validators below, never
// with CLI11's own (CLI::Range and CLI::PositiveNumber let nan and hex through, and an integer
// range would be checked on CLI11's octal reading of "010").
#include <CLI/CLI.hpp>
#include <cstdint>

#include "csv_table.hpp"

namespace daq {

// Walks `app` and all its subcommands and adds the checks above to every numeric option, by
// the type CLI11 knows for it (call once, after every command is added). Throws
// std::logic_error if a numeric option carries one of CLI11's own validators (a programming
// error that every test of the command line would then show).
void check_numbers(CLI::App& app);

// No machine position or length is beyond 100 m: the bound of every length option.
inline constexpr double kMaxPositionMm = 100e3;

// A finite decimal within [lo, hi].
CLI::Validator finite_in(double lo, double hi);
// A finite decimal > 0, and >= 0.
CLI::Validator finite_positive();
CLI::Validator finite_non_negative();
// A plain decimal integer within [lo, hi].
CLI::Validator whole_in(std::int64_t lo, std::int64_t hi);

// --decimal-comma: the CSV input has decimal commas and ';' between cells (csv_table.hpp).
void add_decimal_comma_flag(CLI::App& cmd, CsvOptions& csv);

}  // namespace daq
