// daq sync --to postgresql://...: the local runs copied to the central store (issue 35;
// docs/storage.md, "Central store").
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <system_error>
#include <vector>

#include "cal/analysis/error.hpp"
#include "cal/storage/pg/sync.hpp"
#include "cli_checks.hpp"
#include "commands.hpp"
#include "database.hpp"
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
  if (!o.quiet)
    options.run_done = [](const st::RunRecord& r, std::int64_t sent, std::int64_t already) {
      print_line("run {:>4}  {}  {:>6} chunks sent, {:>6} already there (checked)", r.id, r.uuid,
                 sent, already);
    };
  const auto report = st::pg::sync_to(local, o.to, options);
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
  cmd->add_flag("--quiet", o->quiet, "Only the summary line");
  cmd->callback([o] { run_sync(*o); });
}

}  // namespace daq
