#pragma once
// How much of each sample the circle analysis holds (issue 32). Apart from circle.hpp so that
// the many users of the analysis do not depend on it.
#include <cstddef>
#include <span>

#include "cal/analysis/circle.hpp"

namespace cal::circle {

// The fit keeps a 40-byte record of each sample (its cos, sin, deviation and reversal-spike
// columns) for a run of at most this many samples (both traces: 10 MB, a 1 kHz circle of about
// two minutes a direction); a longer run's records are rebuilt from the traces on every pass
// over them, by the same operations and so to the same values, so that the fit holds nothing
// per sample beyond the traces. The results are the same either way.
inline constexpr std::size_t fit_records_held_max_samples = 262144;

// analyse(setup, traces) with another limit than fit_records_held_max_samples (tests and
// benchmarks: 0 rebuilds every record, SIZE_MAX holds every one).
Result analyse(const Setup& setup, std::span<const Trace> traces,
               std::size_t records_held_max_samples);

}  // namespace cal::circle
