#pragma once
// The profile of a stored straightness, angular or roll run evaluated again from its stored
// stops (daq analyse RUN, and a report of a run whose result was not stored): the same
// evaluation the run made when it ended (kinds/kind.hpp, caldaq.profile.v1).
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cal/storage/store.hpp"

namespace daq {

// Whether a run's kind is one evaluated as a profile (straightness, angular, roll).
bool is_profile_kind(std::string_view run_kind);

// A run's stored stops as the current code writes them. A rotary run stored before commit
// a452795 (2026-11-28) holds each stop's reference angle (continuous, arcsec) where it now
// holds the deviation (the angle minus the target, modulo a turn): such a run is recognised
// from its values against its targets and converted, and `note` (when given) says so, naming
// the run. Throws cal::InputError naming the run when its stops are neither all angles nor all
// deviations. Other runs' stops are returned as stored.
std::vector<cal::storage::CapturedTarget> stored_targets(const cal::storage::RunReader& store,
                                                         const cal::storage::RunRecord& run,
                                                         std::string* note = nullptr);

// Throws cal::InputError naming the run when it has no stops or is not of such a kind.
nlohmann::json stored_profile(const cal::storage::RunReader& store,
                              const cal::storage::RunRecord& run);

// A stored rotary run (kinds/rotary.cpp) evaluated again from its stored stops (each one's
// deviation in arcsec) by `standard` (a key of daq analyse --standard; empty: the run's own):
// caldaq.rotary.v1, the numbers the run stored when evaluated by the same standard. Throws
// cal::InputError naming the run when it has no stops or is not a rotary run.
nlohmann::json stored_rotary(const cal::storage::RunReader& store,
                             const cal::storage::RunRecord& run, std::string_view standard = {});

}  // namespace daq
