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

}  // namespace cal::storage::pg
