// Placeholder: arrives with the service issue.
#include "cal/daq/trigger.hpp"
namespace cal::daq {
int trigger_placeholder() { return 0; }
}  // namespace cal::daq
