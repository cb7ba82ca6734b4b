// Placeholder: arrives with the service issue.
#include "cal/daq/gcode.hpp"
namespace cal::daq {
int gcode_placeholder() { return 0; }
}  // namespace cal::daq
