#pragma once
// The keys of the configuration's plain sections, declared once (issue 19): [environment],
// [trigger], [test.linear] (with its measure keys) and [test.circle]. Each key names its member,
// its unit and range or its allowed words. Every reader and writer of these sections goes
// through the tables, so they cannot disagree:
// - the TOML loader (service/config.cpp) reads and checks each key, with file:line:column;
// - the capture header (runtime/session_spec.cpp) writes every key and reads it back with the
//   same checks (a damaged header is refused naming the key, not replayed with a wrong value);
// - the operator's set-up form (serve/setup_form.cpp) writes the keys a file sets.
// What a table cannot say (a key that excludes another, the plan's combination, the air the
// fallback values make) stays code beside its reader in config.cpp.
#include <array>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "cal/daq/config.hpp"

namespace cal::daq::fields {

// A closed range [lo, hi]; `open_low` makes it (lo, hi], `open_high` [lo, hi).
struct Range {
  double lo = 0, hi = 0;
  std::string_view unit;
  bool open_low = false, open_high = false;
};

enum class Shown { when_set, always };  // in the set-up form: keys a file need not write

template <class S>
using Member = std::variant<double S::*, int S::*, bool S::*, std::string S::*, StalePolicy S::*,
                            std::optional<double> S::*, std::optional<int> S::*,
                            std::vector<double> S::*, std::vector<std::string> S::*,
                            std::array<double, 3> S::*, std::array<int, 2> S::*>;

template <class S>
struct Field {
  std::string_view key;
  Member<S> member;
  std::optional<Range> range;               // numbers: the value, or each element of a list
  std::span<const std::string_view> words;  // strings: one of these (empty: any)
  Shown shown = Shown::when_set;
  bool name = false;                 // a free text: no control characters, at most 200 bytes
  std::string_view header_key = {};  // the key in the capture header where it differs
};

std::span<const Field<EnvironmentConfig>> environment();
std::span<const Field<TriggerConfig>> trigger();
std::span<const Field<LinearTestConfig>> linear();  // without the measure keys
std::span<const Field<MeasureConfig>> measure();    // flat in [test.linear]
std::span<const Field<CircleTestConfig>> circle();

// Why a number is refused by a range ("0.5 must be >= 0 and < 0.5"), or nothing. Non-finite
// numbers are refused by every range.
std::optional<std::string> range_error(const Range& r, double value);
// Why a word is refused ("'foo' is not one of: a, b"), or nothing.
std::optional<std::string> word_error(std::span<const std::string_view> words,
                                      std::string_view value);
// Why a free text is refused (control characters, over 200 bytes), or nothing.
std::optional<std::string> name_error(std::string_view value);

// Why a field refuses a number (its range) or a text (its words, a free text's rules), or
// nothing: the one check every reader of the tables applies.
template <class S>
std::optional<std::string> number_error(const Field<S>& f, double value) {
  return f.range ? range_error(*f.range, value) : std::nullopt;
}
template <class S>
std::optional<std::string> text_error(const Field<S>& f, std::string_view value) {
  if (auto e = word_error(f.words, value)) return e;
  return f.name ? name_error(value) : std::nullopt;
}

// The words of a StalePolicy, and back (nullopt: not a policy).
std::string_view to_string(StalePolicy p);
std::optional<StalePolicy> stale_policy(std::string_view word);

}  // namespace cal::daq::fields
