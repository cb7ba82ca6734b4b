// Command-line values checked at the door (see cli_checks.hpp).
#include "cli_checks.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>

namespace daq {
namespace {

// The names of this file's validators: check_numbers refuses any other on a numeric option.
constexpr std::string_view kFinite = "finite", kInteger = "integer", kFiniteIn = "finite_in",
                           kWholeIn = "whole_in";

CLI::Validator finite_decimal() {
  return CLI::Validator(
      [](std::string& input) -> std::string {
        if (parse_decimal(input)) return {};
        return fmt::format("'{}' is not a finite decimal number", input);
      },
      "", std::string(kFinite));
}

// `text` as a plain decimal integer of type T ("010" is ten; leading zeros dropped in
// `normalised`), or the reason it is not one.
template <class T>
std::optional<std::string> integer_error(const std::string& text, T& value,
                                         std::string& normalised) {
  std::string_view s = text;
  const bool negative = s.starts_with('-');
  if (s.starts_with('+') || negative) s.remove_prefix(1);
  if (s.empty() || s.find_first_not_of("0123456789") != std::string_view::npos)
    return fmt::format("'{}' is not a whole decimal number", text);
  // CLI11 converts with base 0: without this, "010" would be read as octal 8.
  while (s.size() > 1 && s.front() == '0') s.remove_prefix(1);
  normalised = (negative ? "-" : "") + std::string(s);
  const auto [end, ec] =
      std::from_chars(normalised.data(), normalised.data() + normalised.size(), value);
  if (ec != std::errc{} || end != normalised.data() + normalised.size())
    return fmt::format("'{}' is out of range ({} .. {})", text, std::numeric_limits<T>::min(),
                       std::numeric_limits<T>::max());
  return std::nullopt;
}

template <class T>
CLI::Validator plain_integer() {
  return CLI::Validator(
      [](std::string& input) -> std::string {
        T v{};
        std::string digits;
        if (auto e = integer_error(input, v, digits)) return *e;
        input = digits;
        return {};
      },
      "", std::string(kInteger));
}

// Which of the checks above an option of this type takes: CLI11 appends its validators'
// descriptions to the type name ("FLOAT:POSITIVE"), so only the part before ':' is the type.
std::string base_type(const CLI::Option& opt) {
  const std::string type = opt.get_type_name();
  return type.substr(0, type.find(':'));
}

void walk(CLI::App& app) {
  for (CLI::Option* opt : app.get_options()) {
    const std::string type = base_type(*opt);
    if (type != "FLOAT" && type != "INT" && type != "UINT") continue;
    for (int i = 0;; ++i) {
      CLI::Validator* v = nullptr;
      try {
        v = opt->get_validator(i);
      } catch (const CLI::OptionNotFound&) {
        break;
      }
      const std::string name = v->get_name();
      if (name != kFinite && name != kInteger && name != kFiniteIn && name != kWholeIn)
        throw std::logic_error(fmt::format(
            "{} {}: a numeric option checked by a validator other than cli_checks.hpp's ({})",
            app.get_name(), opt->get_name(), v->get_description()));
    }
    if (type == "FLOAT")
      opt->check(finite_decimal());
    else if (type == "INT")  // transform: it may rewrite the text ("010" -> "10")
      opt->transform(plain_integer<std::int64_t>());
    else
      opt->transform(plain_integer<std::uint64_t>());
  }
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) walk(*sub);
}

// A finite decimal for which `ok(v)` holds, else "'TEXT' is not a number WHAT".
template <class Ok>
CLI::Validator finite_where(Ok ok, std::string what) {
  return CLI::Validator(
      [ok, what](std::string& input) -> std::string {
        const auto v = parse_decimal(input);
        if (v && ok(*v)) return {};
        return fmt::format("'{}' is not a number {}", input, what);
      },
      what, std::string(kFiniteIn));
}

}  // namespace

void check_numbers(CLI::App& app) { walk(app); }

CLI::Validator finite_in(double lo, double hi) {
  return finite_where([lo, hi](double v) { return v >= lo && v <= hi; },
                      fmt::format("in [{}, {}]", lo, hi));
}

CLI::Validator finite_positive() {
  return finite_where([](double v) { return v > 0; }, "> 0");
}

CLI::Validator finite_non_negative() {
  return finite_where([](double v) { return v >= 0; }, ">= 0");
}

CLI::Validator whole_in(std::int64_t lo, std::int64_t hi) {
  return CLI::Validator(
      [lo, hi](std::string& input) -> std::string {
        std::int64_t v = 0;
        std::string digits;
        if (auto e = integer_error(input, v, digits)) return *e;
        if (v < lo || v > hi)
          return fmt::format("'{}' is not a whole number in [{}, {}]", input, lo, hi);
        return {};
      },
      fmt::format("in [{}, {}]", lo, hi), std::string(kWholeIn));
}

void add_decimal_comma_flag(CLI::App& cmd, CsvOptions& csv) {
  cmd.add_flag("--decimal-comma", csv.decimal_comma,
               "The CSV has decimal commas (1,5) and ';' between its cells");
}

}  // namespace daq
