// Placeholder: arrives with the service issue.
#include "cal/daq/sequencer.hpp"
namespace cal::daq {
int sequencer_placeholder() { return 0; }
}  // namespace cal::daq
