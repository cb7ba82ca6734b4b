#pragma once
// Device options: every device declares its settings once, in a table (name, type, unit, range,
// default, help), as libsigrok drivers declare their config keys. The TOML loader, `daq decode
// --set KEY=VALUE`, `daq devices --options` and docs/drivers.md all read these tables, so a
// device's settings are written in one place. Pure: no I/O.
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

namespace cal::drivers {

enum class OptionType { boolean, integer, number, string, choice, integer_list };
std::string_view to_string(OptionType type);

// std::monostate: no value (an option whose default is derived from others, e.g. a gauge's
// plausible range from its unit).
using OptionValue = std::variant<std::monostate, bool, std::int64_t, double, std::string,
                                 std::vector<std::int64_t>>;

struct OptionSpec {
  std::string name;
  OptionType type = OptionType::string;
  std::string unit;                  // of a number or integer ("s", "mm"); empty when none
  std::optional<double> min, max;    // numbers, integers and the elements of integer lists
  std::vector<std::string> choices;  // the values a choice takes
  OptionValue default_value;         // std::monostate: derived (the help says from what)
  std::string help;
  // Strings only: "\r", "\n" and "\t" written as two characters become the control character
  // (TOML literal strings and command lines have no escapes).
  bool unescape = false;
};

const OptionSpec* find_option(std::span<const OptionSpec> table, std::string_view name);

// A value checked against its spec: `value` normalised (an integer given for a number becomes
// a double, escapes of an `unescape` string are replaced), or `error` saying why not, e.g.
// "expected an integer", "'silver' is not one of: ds75, gold, temperx", "must be >= 0".
struct CheckedOption {
  OptionValue value;
  std::string error;
};
CheckedOption check_option(const OptionSpec& spec, OptionValue value);

// Parses the text of `--set KEY=VALUE` by the spec's type ("true"/"false", an integer, a
// number, a string, a list "0,1" or "[0, 1]") and checks it; throws cal::InputError "option
// 'KEY': ..." on failure.
OptionValue parse_option_text(const OptionSpec& spec, std::string_view text);

// As written in a TOML file: true, 3, 0.5, "mm", [0, 1]; "" for no value.
std::string format_option_value(const OptionValue& value);

// The option values of one device: every option of its table has a value (its default unless
// set). Reads of a name that is not in the table, or of the wrong type, throw std::logic_error
// (a programming error, not bad input).
class Options {
 public:
  Options() = default;
  explicit Options(std::span<const OptionSpec> table);

  // Sets a checked value (see check_option); throws std::logic_error for an unknown name.
  void set(std::string_view name, OptionValue value);
  bool is_set(std::string_view name) const;     // given explicitly, not the default
  bool has_value(std::string_view name) const;  // not std::monostate

  bool boolean(std::string_view name) const;
  std::int64_t integer(std::string_view name) const;
  double number(std::string_view name) const;
  const std::string& text(std::string_view name) const;  // string or choice
  const std::vector<std::int64_t>& integers(std::string_view name) const;
  const OptionValue& value(std::string_view name) const;
  const std::map<std::string, OptionValue, std::less<>>& values() const { return values_; }

  bool operator==(const Options&) const = default;

 private:
  std::map<std::string, OptionValue, std::less<>> values_;
  std::set<std::string, std::less<>> set_;
};

}  // namespace cal::drivers
