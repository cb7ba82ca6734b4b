// Placeholder: being written.
#include "cal/analysis/squareness.hpp"
