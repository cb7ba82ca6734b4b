// Placeholder: being written.
#include "cal/analysis/straightness.hpp"
