#include "commands.hpp"

namespace daq {

void add_circle_commands(CLI::App& /*app*/, CLI::App& /*analyse*/) {}

}  // namespace daq
