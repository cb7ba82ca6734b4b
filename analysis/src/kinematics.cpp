// Placeholder: being written.
#include "cal/analysis/kinematics.hpp"
