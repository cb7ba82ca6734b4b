#pragma once
// The ceiling a sync is measured against (issue 35, `daq bench sync`, docs/benchmarks.md): what
// any sync of a run's readings must do at the least, read the run's chunks from the local store
// and hand their rows to the server with PostgreSQL's own bulk path, COPY in its binary format,
// into a table shaped like caldaq.reading_chunks (its primary key, no foreign key). libpq stays
// in storage/pg/src.
#include <cstdint>
#include <span>
#include <string_view>

#include "cal/storage/store.hpp"

namespace cal::storage::pg {

struct CopyCeiling {
  double read_s = 0.0;  // reading the chunks from the local store (checksums verified)
  double copy_s = 0.0;  // COPY FROM STDIN (FORMAT binary) of them, committed
  std::int64_t chunks = 0, readings = 0, bytes = 0;
};

// Copies the chunks of `run_ids` in `local` into a scratch table on the server at `url`
// (public.caldaq_bench_reading_chunks, dropped again: nothing is left on the server). Throws StoreError naming the server
// (password redacted) and what failed.
CopyCeiling copy_ceiling(const Store& local, std::string_view url,
                         std::span<const std::int64_t> run_ids);

// Deletes the runs of these UUIDs from the central store at `url` (with their chunks, stops and
// results, by the schema's cascades): the bench's own runs, when it is done.
void delete_central_runs(std::string_view url, std::span<const std::string> uuids);

}  // namespace cal::storage::pg
