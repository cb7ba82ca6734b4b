#pragma once
// How the cyclic-period search refines its grid's best period (issue 32). Apart from
// circle_source.hpp so that the many users of the analysis do not depend on it: only the tests
// and benchmarks that check one refinement against the other include it.
#include <cstddef>
#include <span>

#include "cal/analysis/circle.hpp"
#include "cal/analysis/circle_source.hpp"

namespace cal::circle {

// Brent's method takes the same steps either way; each trial's normal equations come from
// series summed in one pass over the samples (the default of every analyse()), or from a pass
// over every sample per trial, as before the one-pass series (for checking the one against the
// other). one_pass_series_from_an_edge (a check only): the narrow bracket is put at the grid's
// low edge, 100 tolerances wide, so the minimum found there lies on its edge and the refinement
// is done again over the grid's bracket, the fallback no ordinary run is sure to reach.
enum class PeriodRefinement { one_pass_series, pass_per_trial, one_pass_series_from_an_edge };

Result analyse(const Setup& setup, std::span<const Trace> traces,
               std::size_t records_held_max_samples, PeriodRefinement refinement);
Result analyse(const Setup& setup, std::span<const TraceSource> traces,
               std::size_t records_held_max_samples, PageOptions pages,
               PeriodRefinement refinement);

}  // namespace cal::circle
