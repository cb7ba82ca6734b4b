// Placeholder: being written.
#include "cal/analysis/circle.hpp"
