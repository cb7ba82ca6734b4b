// daq sync --to postgresql://...: the local runs copied to the central store (issue 35;
// docs/storage.md, "Central store").
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <system_error>
#include <vector>

#include "cal/analysis/error.hpp"
#include "cal/storage/pg/sync.hpp"
#include "cli_checks.hpp"
#include "commands.hpp"
#include "database.hpp"
#include "progress.hpp"
#include "terminal.hpp"

namespace daq {
namespace {

namespace st = cal::storage;

struct SyncCliOptions {
  std::string db;
  std::string to;
  bool verify = false;
  std::size_t chunks_per_transaction = 64;
  std::vector<std::int64_t> runs;
  bool quiet = false;
  bool json = false;
};

// CALDAQ_SYNC_CUT_AFTER_CHUNKS=N (tests only): the process ends abruptly after sending its N-th
// chunk, before that transaction commits, as when the network drops or the laptop is shut.
std::int64_t cut_after_chunks() {
  const char* env = std::getenv("CALDAQ_SYNC_CUT_AFTER_CHUNKS");
  if (!env || !*env) return -1;
  char* end = nullptr;
  const long long n = std::strtoll(env, &end, 10);
  if (*end != '\0' || n < 1)
    throw cal::InputError(
        fmt::format("CALDAQ_SYNC_CUT_AFTER_CHUNKS: '{}' is not a positive whole number", env));
  return n;
}

// The sync's progress (issue 34), hooked into `options` beside the test's cut: the chunks done
// (sent, or found already there and checked) of all the runs', with the time so far and left,
// on a terminal (stderr; nothing when it is piped) and a line per run on stdout; with --json a
// caldaq.sync-progress.v1 line per run on stderr instead (a program reads them, on a terminal
// too). --quiet: none of it. Returns what the hooks share; it must outlive the sync.
std::shared_ptr<TerminalProgress> attach_progress(st::pg::SyncOptions& options,
                                                  const st::Store& local, const SyncCliOptions& o) {
  std::int64_t chunks = 0, runs = 0;  // the totals: counted first, from the chunks' rows
  for (const auto& r : local.runs())
    if (o.runs.empty() || std::find(o.runs.begin(), o.runs.end(), r.id) != o.runs.end())
      chunks += local.chunk_count(r.id), ++runs;
  auto bar = std::make_shared<TerminalProgress>(
      cal::text::terminal_safe(fmt::format("sync to {}", st::pg::redacted(o.to))), "chunks",
      static_cast<std::uint64_t>(chunks), !o.quiet && !o.json);
  auto sent_before = std::make_shared<std::int64_t>(0);  // chunks sent at the last call
  options.after_chunk = [bar, sent_before, cut = options.after_chunk](std::int64_t sent) {
    bar->add(static_cast<std::uint64_t>(sent - *sent_before));
    bar->tick();
    *sent_before = sent;
    if (cut) cut(sent);
  };
  if (o.quiet) return bar;
  auto runs_done = std::make_shared<std::int64_t>(0);
  auto chunks_done = std::make_shared<std::int64_t>(0);
  options.run_done = [=, json = o.json](const st::RunRecord& r, std::int64_t sent,
                                        std::int64_t already) {
    bar->add(static_cast<std::uint64_t>(already));  // sent ones were counted as they went
    *chunks_done += sent + already;
    ++*runs_done;
    if (json) {
      fmt::print(stderr, "{}\n",
                 nlohmann::json{{"schema", "caldaq.sync-progress.v1"},
                                {"run_id", r.id},
                                {"uuid", r.uuid},
                                {"chunks_sent", sent},
                                {"chunks_already", already},
                                {"runs_done", *runs_done},
                                {"runs", runs},
                                {"chunks_done", *chunks_done},
                                {"chunks", chunks}}
                     .dump());
      std::fflush(stderr);
      return;
    }
    bar->clear();  // the run's line goes where the progress line was
    print_line("run {:>4}  {}  {:>6} chunks sent, {:>6} already there (checked)", r.id, r.uuid,
               sent, already);
    std::fflush(stdout);
    bar->tick();
  };
  return bar;
}

void run_sync(const SyncCliOptions& o) {
  if (!st::pg::is_postgresql_url(o.to))
    throw cal::InputError(fmt::format(
        "--to: '{}' is not a PostgreSQL URI (postgresql://[user@]host[:port]/database or "
        "postgresql:///database?host=/socket/dir)",
        st::pg::redacted(o.to)));
  // Opened for writing: an older database is migrated (schema 7 gives each run its UUID). The
  // sync itself only reads it; WAL lets a running acquisition write meanwhile.
  const auto path = database_path(o.db);
  if (std::error_code ec; !std::filesystem::exists(path, ec))
    throw cal::InputError(
        fmt::format("{}: no such database: nothing to sync (see --db)", path.string()));
  const st::Store local(path);
  st::pg::SyncOptions options;
  options.verify_bytes = o.verify;
  options.chunks_per_transaction = o.chunks_per_transaction;
  options.run_ids = o.runs;
  if (const auto cut = cut_after_chunks(); cut > 0)
    options.after_chunk = [cut](std::int64_t sent) {
      if (sent >= cut) std::_Exit(75);
    };
  const auto progress = attach_progress(options, local, o);
  const auto report = st::pg::sync_to(local, o.to, options);
  progress->clear();  // before the summary, which takes its place
  if (o.json)
    return fmt::print("{}\n", nlohmann::json{{"schema", "caldaq.sync.v1"},
                                             {"db", local.path().string()},
                                             {"to", st::pg::redacted(o.to)},
                                             {"server_schema", report.server_schema},
                                             {"runs", report.runs},
                                             {"runs_new", report.runs_new},
                                             {"chunks_sent", report.chunks_sent},
                                             {"bytes_sent", report.bytes_sent},
                                             {"chunks_already", report.chunks_already},
                                             {"chunks_verified", report.chunks_verified_bytes}}
                                  .dump(2));
  print_line(
      "{}: {} runs synced to {} (central schema {}): {} new; {} chunks sent ({} bytes), {} "
      "already there{}",
      local.path().string(), report.runs, st::pg::redacted(o.to), report.server_schema,
      report.runs_new, report.chunks_sent, report.bytes_sent, report.chunks_already,
      o.verify ? fmt::format("; {} chunks read back and their checksums verified",
                             report.chunks_verified_bytes)
               : std::string());
}

}  // namespace

void add_sync_command(CLI::App& app) {
  auto o = std::make_shared<SyncCliOptions>();
  auto* cmd = app.add_subcommand(
      "sync",
      "Copy the local runs to the central store on PostgreSQL: each run once (by its UUID), "
      "resuming a cut sync from the chunks already there (docs/storage.md, \"Central store\")");
  add_db_option(*cmd, o->db);
  cmd->add_option("--to", o->to,
                  "The central store: postgresql://[user[:password]@]host[:port]/database "
                  "(libpq URI; also ?host=/socket/dir)")
      ->required();
  cmd->add_option("--run", o->runs, "Only these runs (local ids; default: every run)");
  cmd->add_flag("--verify", o->verify,
                "Read every chunk of the synced runs back from the server and verify its "
                "checksum over the server's bytes");
  cmd->add_option("--chunks-per-transaction", o->chunks_per_transaction,
                  "Reading chunks sent per transaction (what a cut sync sends again)")
      ->check(whole_in(1, 100000));
  cmd->add_flag("--quiet", o->quiet, "Only the summary line (no progress either)");
  cmd->add_flag("--json", o->json,
                "Print the summary as JSON (caldaq.sync.v1); the progress goes to stderr as a "
                "JSON line per run (caldaq.sync-progress.v1)");
  cmd->callback([o] { run_sync(*o); });
}

}  // namespace daq
