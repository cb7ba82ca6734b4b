#pragma once
// The operator's page with its strings (daq/web/strings.en.json) and chart library inlined:
// one self-contained document that works offline.
#include <string>
#include <string_view>

namespace cal::daq::web {
// Every script element of the page carries `nonce` (its Content-Security-Policy allows only
// those, so markup that came from elsewhere cannot run script); empty: no nonce attribute.
std::string operator_page(std::string_view nonce = {});
// The fleet view's page (daq/web/fleet.html: daq serve --db postgresql://...), self-contained too.
std::string fleet_page(std::string_view nonce = {});
}  // namespace cal::daq::web
