#pragma once
// The names of an enum's values, written once as a table and read both ways: the name of a
// value (to_string) and the value of a name (the parse of a command-line or stored word). Like
// text.hpp, not metrology, but analysis/ is the library everything depends on.
//
// A table lists each value's shown name first; later rows of the same value are accepted
// spellings (aliases) that name_of never returns. A value missing from the table would read as
// `unknown`; what a switch's -Wswitch would catch, `static_assert(cal::names_every_value(T))`
// beside each table catches when it is compiled: the compiler lists the enum's values.
#include <fmt/format.h>

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include "cal/analysis/error.hpp"

namespace cal {

template <class Enum>
struct EnumName {
  Enum value;
  std::string_view name;
};

namespace detail {

// Whether V is one of its enum's named values, read from the compiler's name of this function
// (as magic_enum does): GCC writes "[with auto V = cal::Plane::xy]", Clang "[V = cal::Plane::xy]"
// (or "(anonymous namespace)::Colour::red"), and both "(cal::Plane)3" for a number that names
// no value: a ')' followed by the number.
template <auto V>
constexpr bool is_enumerator() {
  constexpr std::string_view f = __PRETTY_FUNCTION__;
  constexpr std::size_t at = f.rfind("V = ");
  static_assert(at != std::string_view::npos, "a compiler that does not write \"V = \"");
  const std::string_view v = f.substr(at + 4, f.find_first_of(";]", at) - (at + 4));
  const std::size_t close = v.rfind(')');
  return close == std::string_view::npos || close + 1 == v.size() ||
         !(v[close + 1] == '-' || (v[close + 1] >= '0' && v[close + 1] <= '9'));
}

// Which of the numbers 0 .. N - 1 name a value of Enum.
template <class Enum, std::size_t... I>
constexpr std::array<bool, sizeof...(I)> enumerators(std::index_sequence<I...>) {
  // An enum class: 0 .. 63 are all its values, named or not (an unscoped enum's range may end
  // before them, and casting a number past it is not a constant).
  static_assert(std::is_enum_v<Enum> && !std::is_convertible_v<Enum, int>, "an enum class");
  return {is_enumerator<static_cast<Enum>(I)>()...};
}

}  // namespace detail

// What the checks below see of an enum: its values 0 .. kEnumValuesSeen - 1.
inline constexpr std::size_t kEnumValuesSeen = 64;

// How many named values `Enum` has in 0 .. kEnumValuesSeen - 1, counted by the compiler.
template <class Enum>
constexpr std::size_t enumerator_count() {
  std::size_t n = 0;
  for (const bool named : detail::enumerators<Enum>(std::make_index_sequence<kEnumValuesSeen>{}))
    n += named ? 1 : 0;
  return n;
}

// Whether `names` names every value of its enum (those in 0 .. kEnumValuesSeen - 1). Beside
// each table, static_assert(cal::names_every_value(kNames)): a new value without a name then
// does not compile, as a switch's -Wswitch would have it.
template <class Enum, std::size_t N>
constexpr bool names_every_value(const EnumName<Enum> (&names)[N]) {
  const auto values = detail::enumerators<Enum>(std::make_index_sequence<kEnumValuesSeen>{});
  for (std::size_t i = 0; i < values.size(); ++i) {
    bool named = !values[i];
    for (const auto& n : names) named = named || n.value == static_cast<Enum>(i);
    if (!named) return false;
  }
  return true;
}

// Whether `table`, read as table[static_cast<std::size_t>(value)], has one entry for each value
// of Enum (whose values are then 0 .. N - 1), none of them an empty name: beside such a table,
// static_assert(cal::one_per_value<Enum>(kNames)).
template <class Enum, class T, std::size_t N>
constexpr bool one_per_value(const std::array<T, N>& table) {
  const auto values = detail::enumerators<Enum>(std::make_index_sequence<kEnumValuesSeen>{});
  if (N != enumerator_count<Enum>()) return false;
  for (std::size_t i = 0; i < N; ++i) {
    if (!values[i]) return false;
    if constexpr (std::is_pointer_v<T>) {
      if (table[i] == nullptr) return false;  // fewer names than the array holds
    } else if constexpr (std::is_same_v<T, std::string_view>) {
      if (table[i].empty()) return false;
    }
  }
  return true;
}

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
