#pragma once
// `daq model build` from the run store: the latest complete run of each component of a
// machine (the test kinds store their component and set-up in the run's settings, see
// kinds/kind.hpp), turned into profiles for cal::daq::model::build (model/model_build.hpp).
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "cal/storage/store.hpp"
#include "model/model_build.hpp"

namespace daq {

struct StoredProfiles {
  std::vector<cal::daq::model::MeasuredProfile> profiles;  // the latest of each component
  std::vector<std::string> skipped;  // runs not used, and why (older, incomplete, aborted)
  // The chain and offsets the runs recorded ([machine] of their configuration); the newest
  // run that states a topology wins.
  std::optional<cal::kinematics::Topology> topology;
  cal::kinematics::Vec3 tool_offset_mm{}, table_offset_mm{};
};

// Throws cal::InputError when the machine is unknown or has no run of any test kind. With
// `only` given, only those runs are read (a campaign's, for its report).
StoredProfiles stored_profiles(const cal::storage::RunReader& store, const std::string& machine,
                               std::span<const std::int64_t> only = {});

}  // namespace daq
