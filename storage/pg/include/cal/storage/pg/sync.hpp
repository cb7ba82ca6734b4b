#pragma once
// The central store on PostgreSQL (issue 35; docs/storage.md, "Central store"): its schema and
// `daq sync --to`, which copies the runs of a local SQLite store into it, idempotently (a run is
// stored once, keyed by its UUID) and resumably (a sync cut half way continues from the chunks
// the server has, checking that they are the local ones by their checksums).
//
// libpqxx and libpq stay in storage/pg/src: this header names neither.
#include <cstdint>
#include <filesystem>
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
// 3: results known by a fingerprint of their content (daq sync --from and back stores one).
// 4: a run's stops kept as versions (run_versions: who sent them, from where, when) when the
// same run was changed in two places.
// 5: machines known by a stable id (their UUID), not by name.
// 6 (with local schema 9): roles (caldaq_engineer sends, caldaq_reviewer approves; nothing for
// other logins) and sign-off (approvals, made by caldaq.approve).
// 7 (with local schema 10): sites. A login reads and writes only the machines, runs (with every
// row of a run) and compensation tables of the sites caldaq.site_grants grants it ('*': all);
// row-level security, and caldaq.approve checks the reviewer's sites.
// 8: the fleet view's tables (per run, result, value and instrument), kept by triggers on the
// server (daq serve --db postgresql://...: docs/web.md "The fleet view").
// 9: the fleet's straightness, angular and roll runs; each trend line's window (the last
// compensation table or switch of the control's compensation that resets it).
// 10 (with local schema 11): machine models (caldaq.models), known by their UUID, of a machine
// (visible and writable where their machine is).
// 11: each result tied to the version of the run's stops it was computed from (result_versions);
// the readers read the chosen (else current) version's results only.
// 12: the fleet's current results those of the run's current version; daq's verdict stored with
// each result (results.verdict, verdict_failed: the fleet reads it, the server judges nothing); an
// approval records the approved result's own version.
// 13: the failing tests' index (fleet_tests_failing): the fleet's first view reads rows that
// grow with the machines, not with the results synced.
inline constexpr int central_schema_version = 13;

// Whether `text` names a PostgreSQL server (a postgresql:// or postgres:// URI) rather than a
// SQLite file.
bool is_postgresql_url(std::string_view text);
// The URI with any password replaced by "***": what messages print.
std::string redacted(std::string_view url);

// daq's verdict of a result (daq/src/results/verdict.cpp), as the server keeps it with the result
// (central schema 12) for the fleet view.
struct StoredVerdict {
  std::string verdict;  // "pass", "fail", or "none" (no limit applies)
  std::string failed;   // the symbols of the values that failed, ", " between them, byte order
  bool operator==(const StoredVerdict&) const = default;
};

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
  // Who sends and from where (a user and a host name): recorded with each version of a run's
  // stops (with the local store's path and the time).
  std::string sent_by, sent_from;
  // The site of the machines new to the server (and of runs without a machine), central schema 7.
  // Empty: the one site the login may write, else (a login of several sites, or all) the
  // [customer] site of the configuration their runs were measured with. A machine on the server
  // keeps its site (another one here is an error): which site a machine is of is the
  // administrator's.
  std::string site;
  // The verdict of a result by its run's settings (both JSON text, as stored): storage/ does not
  // judge, daq does (daq sync passes verdict.cpp's). Sent with every result, and sent again when
  // it changed (the run's tolerances edited); a sync also judges the results on the server that
  // have none (those of a server migrated from schema 11: the sync that migrates judges them
  // all). Empty: results go without one (the fleet shows "none").
  std::function<StoredVerdict(std::string_view settings_json, std::string_view result_json)>
      verdict;
};

struct SyncReport {
  std::int64_t runs = 0;            // runs synced
  std::int64_t runs_new = 0;        // of which the server did not have before
  std::int64_t chunks_sent = 0;     // chunks copied now
  std::int64_t chunks_already = 0;  // chunks the server had (from an earlier or cut sync), checked
  std::int64_t chunks_verified_bytes = 0;  // chunks whose server bytes were re-read (verify_bytes)
  std::int64_t bytes_sent = 0;             // chunk BLOB bytes copied now
  std::int64_t versions_new = 0;     // runs whose stops differ from every version the server had
  std::int64_t models = 0;           // models of the local store (schema 11) synced
  std::int64_t models_new = 0;       // of which the server did not have before
  int server_schema = 0;             // the central schema version after migration
  std::int64_t verdicts_judged = 0;  // results on the server judged without their laptop's copy
};

// Copies the runs of `local` to the central store at `url` (migrating its schema first).
// Throws StoreError naming the server (password redacted) and what failed; a chunk the server
// holds that differs from the local one (checksum, row or length) is an error naming the run
// and the chunk, and nothing of that run is overwritten.
SyncReport sync_to(const Store& local, std::string_view url, const SyncOptions& options = {});

struct PullOptions {
  // The machine whose history is brought: its name on the server, or its UUID (when two
  // sites' machines have the name).
  std::string machine;
  // Chunks received per local transaction: what a cut pull receives again.
  std::size_t chunks_per_transaction = 64;
  // Called after each chunk is received, before its transaction commits (the tests' cut).
  std::function<void(std::int64_t chunks_received)> after_chunk;
  // Called when a run is done, with its local record.
  std::function<void(const RunRecord&, std::int64_t received, std::int64_t already)> run_done;
  // Runs brought with another version of their stops than the current one (--version RUN:N):
  // the run's id on the server or its UUID, and the version. Each must be a run of the machine
  // that this store does not have yet (a store keeps one version of a run).
  struct VersionChoice {
    std::string run;
    int version = 0;
  };
  std::vector<VersionChoice> versions;
};

struct PullReport {
  std::int64_t runs = 0;               // the machine's runs on the server
  std::int64_t runs_new = 0;           // of which this store did not have before
  std::int64_t results_new = 0;        // results brought (of runs new or not)
  std::int64_t chunks_received = 0;    // chunks copied now, each checked against its checksum
  std::int64_t chunks_already = 0;     // chunks this store had, checked against the server's
  std::int64_t bytes_received = 0;     // chunk BLOB bytes copied now
  std::int64_t compensations_new = 0;  // compensation tables of the machine brought
  std::int64_t calibrations_new = 0;   // ballbar calibrations brought
  std::int64_t models_new = 0;         // models of the machine brought (central schema 10)
  std::int64_t approvals_new = 0;      // the server's approvals of results here brought (schema 7)
  std::int64_t operator_actions_refreshed = 0;  // runs brought before whose actions changed there
  int server_schema = 0;
};

// daq sync --from: brings one machine's history from the central store at `url` into `local`
// (the machine added by name if this store lacks it): its runs with their UUIDs, instruments,
// stops, results with their provenance and the server's approvals of them (read-only here), the
// quality, the operator's actions (refreshed for runs brought before) and every reading chunk;
// its compensation tables; the ballbar calibrations. Idempotent (what is here is not
// brought again: runs by UUID, results by content, chunks by number and checksum) and resumable
// (a cut pull continues from the chunks here). Every chunk received is checked against the
// checksum the server holds for it; a chunk here that differs from the server's is an error
// naming the run and the chunk, and nothing of that run is overwritten. The local store at
// `local_path` is opened (created when missing, migrated when older) only once the server and
// the machine are found: a refused pull leaves no file behind. Throws StoreError.
PullReport sync_from(const std::filesystem::path& local_path, std::string_view url,
                     const PullOptions& options);

// Creates or migrates the central schema; returns its version. Refuses a newer one.
int migrate(std::string_view url);

}  // namespace cal::storage::pg
