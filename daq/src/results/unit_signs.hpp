#pragma once
// The units' signs: a unit as a terminal prints it ("um", "urad", "um/m", "degC") and as a page
// or a report does ("µm", "µrad", "µm/m", "°C"). The one table unit_html and units_html
// (result_rows.hpp) write from, and the operator's and fleet pages too: the server gives it to
// them as JSON (daq/web/present.js).
#include <span>
#include <string>
#include <string_view>
#include <utility>

namespace daq {

// Longest first ("um/m" before "um").
std::span<const std::pair<std::string_view, std::string_view>> unit_signs();
// The same as JSON: [["um/m", "µm/m"], ["um", "µm"], ...].
std::string unit_signs_json();

}  // namespace daq
