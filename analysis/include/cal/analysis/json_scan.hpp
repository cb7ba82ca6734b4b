#pragma once
// The structure of JSON text without parsing it: its characters outside strings (a string's
// brackets and escaped quotes are skipped). For bounds that must be known before the text is
// parsed: how deep it nests, where an object ends in a stream of them. Like text.hpp, not
// metrology, but analysis/ is the library everything depends on. No I/O.
#include <cstddef>
#include <string_view>

namespace cal::text {

// Calls stop(c) for each character c = text[i] outside strings from `from` on (the quotes
// that open strings included); returns the first i for which it returns true, or npos.
template <class Stop>
std::size_t find_outside_json_strings(std::string_view text, std::size_t from, Stop stop) {
  bool in_string = false, escaped = false;
  for (std::size_t i = from; i < text.size(); ++i) {
    const char c = text[i];
    if (!in_string) {
      in_string = c == '"';
      if (stop(c)) return i;
    } else if (escaped) {
      escaped = false;
    } else if (c == '\\') {
      escaped = true;
    } else if (c == '"') {
      in_string = false;
    }
  }
  return std::string_view::npos;
}

}  // namespace cal::text
