#pragma once
// The live page with its chart library inlined (one self-contained document, works offline).
#include <string>

namespace cal::daq::web {
std::string live_page();
}
