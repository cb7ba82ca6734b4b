// Command-line values checked at the door (see cli_checks.hpp).
#include "cli_checks.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <limits>

namespace daq {
namespace {

CLI::Validator finite_decimal() {
  return CLI::Validator(
      [](std::string& input) -> std::string {
        if (parse_decimal(input)) return {};
        return fmt::format("'{}' is not a finite decimal number", input);
      },
      "", "finite");
}

template <class T>
CLI::Validator plain_integer() {
  return CLI::Validator(
      [](std::string& input) -> std::string {
        std::string_view s = input;
        const bool negative = s.starts_with('-');
        if (s.starts_with('+') || negative) s.remove_prefix(1);
        if (s.empty() || s.find_first_not_of("0123456789") != std::string_view::npos)
          return fmt::format("'{}' is not a whole decimal number", input);
        // CLI11 converts with base 0: without this, "010" would be read as octal 8.
        while (s.size() > 1 && s.front() == '0') s.remove_prefix(1);
        T v{};
        const std::string digits = (negative ? "-" : "") + std::string(s);
        const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), v);
        if (ec != std::errc{} || end != digits.data() + digits.size())
          return fmt::format("'{}' is out of range ({} .. {})", input,
                             std::numeric_limits<T>::min(), std::numeric_limits<T>::max());
        input = digits;
        return {};
      },
      "", "integer");
}

void walk(CLI::App& app) {
  for (CLI::Option* opt : app.get_options()) {
    const std::string type = opt->get_type_name();
    if (type == "FLOAT")
      opt->check(finite_decimal());
    else if (type == "INT")  // transform: it may rewrite the text ("010" -> "10")
      opt->transform(plain_integer<std::int64_t>());
    else if (type == "UINT")
      opt->transform(plain_integer<std::uint64_t>());
  }
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) walk(*sub);
}

}  // namespace

void check_numbers(CLI::App& app) { walk(app); }

CLI::Validator finite_in(double lo, double hi) {
  return CLI::Validator(
      [lo, hi](std::string& input) -> std::string {
        const auto v = parse_decimal(input);
        if (v && *v >= lo && *v <= hi) return {};
        return fmt::format("'{}' is not a number in [{}, {}]", input, lo, hi);
      },
      fmt::format("in [{}, {}]", lo, hi), "finite_in");
}

void add_decimal_comma_flag(CLI::App& cmd, CsvOptions& csv) {
  cmd.add_flag("--decimal-comma", csv.decimal_comma,
               "The CSV has decimal commas (1,5) and ';' between its cells");
}

}  // namespace daq
