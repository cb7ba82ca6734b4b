#pragma once
// The names of an enum's values, written once as a table and read both ways: the name of a
// value (to_string) and the value of a name (the parse of a command-line or stored word). Like
// text.hpp, not metrology, but analysis/ is the library everything depends on.
//
// A table lists each value's shown name first; later rows of the same value are accepted
// spellings (aliases) that name_of never returns. A value missing from the table reads as
// `unknown`, so the tests that print every value are what catch a new value without a name
// (a switch would have had the compiler's -Wswitch do it).
#include <fmt/format.h>

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>

#include "cal/analysis/error.hpp"

namespace cal {

template <class Enum>
struct EnumName {
  Enum value;
  std::string_view name;
};

// The first name of `value` in `names`, or `unknown`.
template <class Enum, std::size_t N>
constexpr std::string_view name_of(const EnumName<Enum> (&names)[N], Enum value,
                                   std::string_view unknown = "?") {
  for (const auto& n : names)
    if (n.value == value) return n.name;
  return unknown;
}

// The value named `name` (any of its spellings), or nullopt.
template <class Enum, std::size_t N>
constexpr std::optional<Enum> value_named(const EnumName<Enum> (&names)[N], std::string_view name) {
  for (const auto& n : names)
    if (n.name == name) return n.value;
  return std::nullopt;
}

// The value named `name`, or InputError "unknown WHAT 'NAME': expected A, B or C" (the shown
// names of the values, in the table's order).
template <class Enum, std::size_t N>
Enum parse_name(const EnumName<Enum> (&names)[N], std::string_view name, std::string_view what) {
  if (const auto v = value_named(names, name)) return *v;
  std::string expected;
  for (std::size_t i = 0; i < N; ++i) {
    if (name_of(names, names[i].value) != names[i].name) continue;  // an alias
    if (!expected.empty()) expected += " or ";
    expected += names[i].name;
  }
  // "a or b or c" -> "a, b or c"
  for (auto at = expected.find(" or "); at != expected.rfind(" or "); at = expected.find(" or "))
    expected.replace(at, 4, ", ");
  throw InputError(fmt::format("unknown {} '{}': expected {}", what, name, expected));
}

}  // namespace cal
