#pragma once
// The central store on PostgreSQL (issue 35; docs/storage.md, "Central store"): its schema and
// `daq sync --to`, which copies the runs of a local SQLite store into it, idempotently (a run is
// stored once, keyed by its UUID) and resumably (a sync cut half way continues from the chunks
// the server has, checking that they are the local ones by their checksums).
//
// libpqxx and libpq stay in storage/pg/src: this header names neither.
#include <cstdint>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "cal/storage/store.hpp"

namespace cal::storage::pg {

// The central schema's version (table caldaq.schema_version), migrated by open/sync.
// 1 (issue 35): machines, runs keyed by UUID, instruments, reading chunks with their checksums,
// captured stops, missed stops, results with provenance, the operator's actions.
// 2: the stop quality as rows (suspect stops), compensation tables, ballbar calibrations: what
// the read commands read from either store.
inline constexpr int central_schema_version = 2;

// Whether `text` names a PostgreSQL server (a postgresql:// or postgres:// URI) rather than a
// SQLite file.
bool is_postgresql_url(std::string_view text);
// The URI with any password replaced by "***": what messages print.
std::string redacted(std::string_view url);

struct SyncOptions {
  // Chunks sent per transaction: what a cut can lose and then sends again.
  std::size_t chunks_per_transaction = 64;
  // Download every chunk of the synced runs from the server and recompute its checksum over the
  // server's bytes (default: the server's row, checksum and length are compared with the local
  // chunk's, the bytes not re-read).
  bool verify_bytes = false;
  // Only these local run ids (empty: all).
  std::vector<std::int64_t> run_ids;
  // Called after each chunk is sent, with the chunks sent so far in this sync, before its
  // transaction commits (the tests end the process here to cut a sync mid-transaction).
  std::function<void(std::int64_t chunks_sent)> after_chunk;
  // Called when a run is done (for progress lines).
  std::function<void(const RunRecord&, std::int64_t sent, std::int64_t already)> run_done;
};

struct SyncReport {
  std::int64_t runs = 0;            // runs synced
  std::int64_t runs_new = 0;        // of which the server did not have before
  std::int64_t chunks_sent = 0;     // chunks copied now
  std::int64_t chunks_already = 0;  // chunks the server had (from an earlier or cut sync), checked
  std::int64_t chunks_verified_bytes = 0;  // chunks whose server bytes were re-read (verify_bytes)
  std::int64_t bytes_sent = 0;             // chunk BLOB bytes copied now
  int server_schema = 0;                   // the central schema version after migration
};

// Copies the runs of `local` to the central store at `url` (migrating its schema first).
// Throws StoreError naming the server (password redacted) and what failed; a chunk the server
// holds that differs from the local one (checksum, row or length) is an error naming the run
// and the chunk, and nothing of that run is overwritten.
SyncReport sync_to(const Store& local, std::string_view url, const SyncOptions& options = {});

// Creates or migrates the central schema; returns its version. Refuses a newer one.
int migrate(std::string_view url);

}  // namespace cal::storage::pg
