#pragma once
// What a value in each controller format means, by its vendor's own public text: whether the
// file holds the measured error (measured - target; the control takes it off) or the correction
// (-error; the control adds it), what the control applies it to, relative to what, and how sure
// that reading is. The writers take the sign from here, never from the user (only caldaq's own
// CSV lets the user choose). The quotes and their sources are in docs/compensation-tables.md.
#include <span>
#include <string>
#include <string_view>

#include "cal/analysis/comp_table.hpp"

namespace cal::comptable {

// How the reading of the sign is supported.
enum class Evidence {
  stated,        // the vendor states the direction in so many words (quoted)
  best_reading,  // implied by the vendor's text (names, a formula, a worked example), not stated
  not_found,     // the public text read does not say: verify with one point on the machine
};
std::string_view to_string(Evidence e);

struct FormatMeaning {
  std::string_view format;     // the -f name, e.g. "siemens"
  std::string_view name;       // the control's function
  Sign written;                // what the file's values are
  std::string_view applied;    // what the control does with a value
  std::string_view reference;  // relative to what the values are
  Evidence evidence;
  std::string_view source;  // document and page
  std::string_view quote;   // the sentence the reading rests on ("" where none was found)
};

// Every format's meaning; format_meaning throws cal::InputError naming the known formats.
std::span<const FormatMeaning> format_meanings();
const FormatMeaning& format_meaning(std::string_view format);

// The meaning as comment lines for a file's header, each starting with `comment` (e.g. "; ",
// "# "): the function, the sign with its evidence and source, and, unless stated by the vendor,
// that the sign must be verified on the machine before the table is trusted.
std::string meaning_header(const FormatMeaning& m, std::string_view comment);
// The same in a few sentences for the command's output.
std::string meaning_text(const FormatMeaning& m);

}  // namespace cal::comptable
