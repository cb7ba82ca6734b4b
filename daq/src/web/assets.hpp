#pragma once
// The operator's page with its strings (daq/web/strings.en.json) and chart library inlined:
// one self-contained document that works offline.
#include <string>

namespace cal::daq::web {
std::string operator_page();
}
