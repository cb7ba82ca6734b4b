// A machine's specification alone: [tolerances] tables without the rest of a configuration.
#pragma once

#include <filesystem>
#include <string_view>

#include "cal/daq/config.hpp"

namespace cal::daq {

// A text of [tolerances.AXIS] and [tolerances.PLANE] tables only (daq sim --tolerances), read
// as in a configuration; any other key is refused with its position.
Config parse_tolerances(std::string_view toml_text, const std::filesystem::path& source_name);

}  // namespace cal::daq
