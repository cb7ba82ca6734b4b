#pragma once
// Reading the central store (issue 35): the RunReader of a PostgreSQL server that daq sync
// filled. libpqxx stays in storage/pg/src.
#include <memory>
#include <string_view>

#include "cal/storage/store.hpp"

namespace cal::storage::pg {

// Connects and checks that the server holds a caldaq central store of a version this daq reads
// (nothing is created or migrated: a reader never writes). Throws StoreError naming the server
// (password hidden) and what is wrong. Runs are numbered by the server (the order it first saw
// them), not by the laptops they came from.
std::unique_ptr<RunReader> open_central(std::string_view url);

// From now on `central` (a reader open_central made) reads version `version` of run `run_id`'s
// stops instead of its current one (targets(); daq show|export|analyse RUN --version N, daq sync
// --from ... --version RUN:N). Throws StoreError naming the run and the versions it has when
// there is no such version.
void read_version(RunReader& central, std::int64_t run_id, int version);

// daq approve RUN --db postgresql://... (central schema 6): the login of this connection approves
// result `result_id` of run `run_id` (the server's ids, as daq show lists them) through the
// server's caldaq.approve, which records that login and the time, the result's fingerprint and
// the run's current version, and refuses a login without the role caldaq_reviewer, a result
// superseded since and one approved already (StoreError with the server's reason).
Approval approve_central(std::string_view url, std::int64_t run_id, std::int64_t result_id);

}  // namespace cal::storage::pg
