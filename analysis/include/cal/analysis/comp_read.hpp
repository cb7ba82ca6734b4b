#pragma once
// Reading a positioning table back from a controller file, as the control reads it: what the
// simulated shop's control loads (daq demo --control-table) so that the compensation loop is
// tested against a known truth, and an independent check that what a writer printed is what
// its Applied says. Parsed from the text alone (not from the writer's data).
#include <string_view>

#include "cal/analysis/comp_table.hpp"

namespace cal::comptable {

// The correction (um, what the control adds to the position) at each point of a table file of
// `format` (siemens, linuxcnc, isg, heidenhain, fanuc, csv), with the vendor's meaning of the
// values (comp_meaning.hpp) unless `inverted` (a control that reads them with the other sign).
// Throws cal::InputError naming the line for text that is not such a table.
Applied read_applied(std::string_view format, std::string_view text, bool inverted = false);

}  // namespace cal::comptable
