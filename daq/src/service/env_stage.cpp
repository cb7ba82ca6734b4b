// Placeholder: arrives with the service issue.
#include "cal/daq/env_stage.hpp"
namespace cal::daq {
int env_stage_placeholder() { return 0; }
}  // namespace cal::daq
