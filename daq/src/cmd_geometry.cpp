#include "commands.hpp"

namespace daq {

void add_geometry_commands(CLI::App& /*app*/, CLI::App& /*analyse*/) {}

}  // namespace daq
