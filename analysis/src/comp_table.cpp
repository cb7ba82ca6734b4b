// Placeholder: being written.
#include "cal/analysis/comp_table.hpp"
