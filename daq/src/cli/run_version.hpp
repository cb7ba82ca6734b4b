#pragma once
// --version N of the read commands (daq show, export, analyse RUN): which version of a run's
// stops they read. A central store keeps one per place the run was changed in (docs/storage.md,
// "Conflicts are versions"); a local store keeps one.
#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>

#include "cal/storage/store.hpp"

namespace daq {

// Adds --version N (a positive whole number; 0, the default: the current version).
void add_version_option(CLI::App& cmd, int& target);

// Makes `store` (opened from `db`) read version `version` of run `run`'s stops: nothing for 0; a
// local store refuses any (cal::InputError), a central store one the run lacks (StoreError).
void choose_version(cal::storage::RunReader& store, const std::string& db, std::int64_t run,
                    int version);

}  // namespace daq
