#pragma once
// The operator's page with its strings (daq/web/strings.en.json) and chart library inlined:
// one self-contained document that works offline.
#include <string>
#include <string_view>

namespace cal::daq::web {
// Every script element of the page carries `nonce` (its Content-Security-Policy allows only
// those, so markup that came from elsewhere cannot run script); empty: no nonce attribute.
// `unit_signs`: the units' signs as JSON ([["um", "µm"], ...], ::daq::unit_signs_json()), which
// the pages' shared presentation (daq/web/present.js) writes units with.
std::string operator_page(std::string_view nonce = {}, std::string_view unit_signs = "[]");
// The fleet view's page (daq/web/fleet.html: daq serve --db postgresql://...), self-contained too.
std::string fleet_page(std::string_view nonce = {}, std::string_view unit_signs = "[]");
}  // namespace cal::daq::web
