#include "commands.hpp"

namespace daq {

void add_compensate_commands(CLI::App& /*app*/, CLI::App& /*analyse*/) {}

}  // namespace daq
