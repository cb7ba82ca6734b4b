// daq sync --to postgresql://...: the local runs copied to the central store (issue 35;
// docs/storage.md, "Central store"); daq approve: a reviewer's sign-off of a result, in either
// store ("Sign-off").
#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <system_error>
#include <vector>

#include "cal/analysis/error.hpp"
#include "cal/analysis/text.hpp"
#include "cal/storage/pg/central.hpp"
#include "cal/storage/pg/sync.hpp"
#include "cli_checks.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "database.hpp"
#include "json_input.hpp"
#include "progress.hpp"
#include "run_document.hpp"
#include "terminal.hpp"
#include "verdict.hpp"

namespace daq {
namespace {

namespace st = cal::storage;

struct SyncCliOptions {
  std::string db;
  std::string to;
  std::string from;
  std::string machine;
  std::string site;
  bool verify = false;
  std::size_t chunks_per_transaction = 64;
  std::vector<std::int64_t> runs;
  std::vector<std::string> versions;  // --from: RUN:N, a run brought at version N of its stops
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

// daq's verdict of a stored result by its run's settings, as the central store keeps it with the
// result (central schema 12) for the fleet view: verdict.cpp's, the one rule (the value as
// cal::fixed_text prints it against the limit). A document that is not JSON is judged "none".
st::pg::StoredVerdict stored_verdict(std::string_view settings_json, std::string_view result_json) {
  const auto result = cal::daq::parse_stored_json(result_json);
  if (!result.is_object()) return {.verdict = "none", .failed = ""};
  auto settings = cal::daq::parse_stored_json(settings_json);
  if (!settings.is_object()) settings = nlohmann::json::object();
  Verdict v;
  try {
    v = verdict_of(settings, result);
  } catch (const std::exception&) {  // a limit or value of the wrong type: daq show fails too
    return {.verdict = "none", .failed = ""};
  }
  std::vector<std::string> failed;
  for (const auto& c : v.checks)
    if (!c.pass) failed.push_back(c.symbol);
  std::sort(failed.begin(), failed.end());
  return {.verdict = !v.configured ? "none"
                     : v.pass      ? "pass"
                                   : "fail",
          .failed = fmt::format("{}", fmt::join(failed, ", "))};
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

void need_postgresql_url(std::string_view option, std::string_view url) {
  if (!st::pg::is_postgresql_url(url))
    throw cal::InputError(
        fmt::format("{}: '{}' is not a PostgreSQL URI (postgresql://[user@]host[:port]/database or "
                    "postgresql:///database?host=/socket/dir)",
                    option, st::pg::redacted(url)));
}

// --version RUN:N: the server's run id or UUID, and a version number (1, 2, ...).
st::pg::PullOptions::VersionChoice version_choice(const std::string& text) {
  const auto colon = text.rfind(':');
  const auto bad = [&] {
    return cal::InputError(fmt::format(
        "--version '{}': give RUN:N, the run (its id on the server or its UUID) and the version "
        "of its stops (daq show RUN --db postgresql://... lists them), e.g. 3:2",
        cal::text::terminal_safe(text)));
  };
  if (colon == std::string::npos || colon == 0) throw bad();
  const std::string number = text.substr(colon + 1);
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(number.c_str(), &end, 10);
  if (number.empty() || *end != '\0' || errno != 0 || v < 1 || v > 1000000) throw bad();
  return {.run = text.substr(0, colon), .version = static_cast<int>(v)};
}

// daq sync --from URL --machine NAME: the machine's history brought into the local store
// (created when missing: a laptop before a visit), a line per run and a summary.
void run_pull(const SyncCliOptions& o) {
  need_postgresql_url("--from", o.from);
  if (o.machine.empty())
    throw cal::InputError("--from needs --machine NAME: which machine's history to bring");
  if (!o.runs.empty() || o.verify || !o.site.empty())
    throw cal::InputError(
        "--run, --verify and --site are for --to (--from checks every chunk it brings)");
  const auto path = database_path(o.db);
  st::pg::PullOptions options;
  options.machine = o.machine;
  for (const auto& v : o.versions) options.versions.push_back(version_choice(v));
  options.chunks_per_transaction = o.chunks_per_transaction;
  if (const auto cut = cut_after_chunks(); cut > 0)
    options.after_chunk = [cut](std::int64_t received) {
      if (received >= cut) std::_Exit(75);
    };
  if (!o.quiet && !o.json)
    options.run_done = [](const st::RunRecord& r, std::int64_t received, std::int64_t already) {
      print_line("run {:>4}  {}  {:>6} chunks received, {:>6} already here (checked)", r.id, r.uuid,
                 received, already);
      std::fflush(stdout);
    };
  const auto report = st::pg::sync_from(path, o.from, options);
  if (o.json)
    return fmt::print(
        "{}\n", nlohmann::json{{"schema", "caldaq.sync-from.v1"},
                               {"db", path.string()},
                               {"from", st::pg::redacted(o.from)},
                               {"machine", o.machine},
                               {"server_schema", report.server_schema},
                               {"runs", report.runs},
                               {"runs_new", report.runs_new},
                               {"results_new", report.results_new},
                               {"chunks_received", report.chunks_received},
                               {"bytes_received", report.bytes_received},
                               {"chunks_already", report.chunks_already},
                               {"compensations_new", report.compensations_new},
                               {"calibrations_new", report.calibrations_new},
                               {"approvals_new", report.approvals_new},
                               {"operator_actions_refreshed", report.operator_actions_refreshed},
                               {"models_new", report.models_new}}
                    .dump(2));
  print_line(
      "{}: {} runs of machine '{}' brought from {} (central schema {}): {} new, {} new results; "
      "{} chunks received ({} bytes), {} already here; {} compensation tables, {} ballbar "
      "calibrations, {} approvals new; {} runs' operator actions refreshed; {} models new",
      path.string(), report.runs, cal::text::terminal_safe(o.machine), st::pg::redacted(o.from),
      report.server_schema, report.runs_new, report.results_new, report.chunks_received,
      report.bytes_received, report.chunks_already, report.compensations_new,
      report.calibrations_new, report.approvals_new, report.operator_actions_refreshed,
      report.models_new);
}

void run_sync(const SyncCliOptions& o) {
  if (o.to.empty() == o.from.empty())
    throw cal::InputError("give one of --to (send the local runs) and --from (bring a machine's)");
  if (!o.from.empty()) return run_pull(o);
  if (!o.machine.empty()) throw cal::InputError("--machine is for --from");
  if (!o.versions.empty())
    throw cal::InputError("--version is for --from (a run is sent with the stops it has here)");
  need_postgresql_url("--to", o.to);
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
  options.sent_by = user_name();
  options.sent_from = host_name();
  options.site = o.site;
  options.verdict = stored_verdict;
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
                                             {"chunks_verified", report.chunks_verified_bytes},
                                             {"versions_new", report.versions_new},
                                             {"models", report.models},
                                             {"models_new", report.models_new},
                                             {"verdicts_judged", report.verdicts_judged}}
                                  .dump(2));
  print_line(
      "{}: {} runs synced to {} (central schema {}): {} new; {} chunks sent ({} bytes), {} "
      "already there{}{}{}",
      local.path().string(), report.runs, st::pg::redacted(o.to), report.server_schema,
      report.runs_new, report.chunks_sent, report.bytes_sent, report.chunks_already,
      o.verify ? fmt::format("; {} chunks read back and their checksums verified",
                             report.chunks_verified_bytes)
               : std::string(),
      report.versions_new ? fmt::format("; {} runs' stops differ from the server's: kept as a new "
                                        "version (daq show names the versions)",
                                        report.versions_new)
                          : std::string(),
      // Only for a store that keeps models (the line is as before otherwise).
      report.models ? fmt::format("; {} models synced, {} new", report.models, report.models_new)
                    : std::string());
}

struct ApproveOptions {
  std::string db;
  std::int64_t run = 0;
  std::int64_t result = 0;  // 0: the run's one current result
  bool json = false;
};

// The result to approve: the one named (it must be the run's), else the run's one current result.
std::int64_t result_to_approve(const st::RunReader& store, const ApproveOptions& o) {
  if (!store.run(o.run)) throw cal::InputError(fmt::format("{}: no run {}", store.name(), o.run));
  if (o.result) return o.result;  // the store refuses one not of the run, or superseded
  std::vector<std::int64_t> current;
  for (const auto& r : store.results(o.run))
    if (r.current()) current.push_back(r.id);
  if (current.empty())
    throw cal::InputError(
        fmt::format("{}: run {} has no result to approve (daq analyse {} --store "
                    "stores one)",
                    store.name(), o.run, o.run));
  if (current.size() > 1)
    throw cal::InputError(fmt::format(
        "{}: run {} has {} current results (results {}; daq show {} names them): approve one "
        "with --result",
        store.name(), o.run, current.size(), fmt::join(current, ", "), o.run));
  return current.front();
}

// daq approve RUN: on the central store the server checks the reviewer's role and records the
// login; in a local store (no accounts of its own) the approver is this account.
void run_approve(const ApproveOptions& o) {
  st::Approval a;
  std::string where;
  if (st::pg::is_postgresql_url(o.db)) {
    const auto reader = st::pg::open_central(o.db);
    a = st::pg::approve_central(o.db, o.run, result_to_approve(*reader, o));
    where = reader->name();
  } else {
    const auto path = database_path(o.db);
    if (std::error_code ec; !std::filesystem::exists(path, ec))
      throw cal::InputError(fmt::format("{}: no such database (see --db)", path.string()));
    st::Store store(path);
    a = store.approve(o.run, result_to_approve(store, o), user_name());
    where = store.name();
  }
  auto j = approval_json(a);
  j["schema"] = "caldaq.approval.v1";
  j["run"] = o.run;
  j["db"] = where;
  if (o.json) return fmt::print("{}\n", j.dump(2));
  print_line("{}: run {}: result {} approved by {} at {}{}", where, o.run, a.result_id,
             a.approved_by, j["approved"].get<std::string>(),
             a.result_fingerprint.empty()
                 ? std::string()
                 : fmt::format(" (fingerprint {}, version {} of its stops)", a.result_fingerprint,
                               a.run_version));
}

}  // namespace

void add_approve_command(CLI::App& app) {
  const auto [cmd, o] = add_command<ApproveOptions>(
      app, "approve", run_approve,
      "Sign off a stored run's result as a reviewer: its report is then issued as a certificate "
      "naming who approved it and when (docs/storage.md, \"Sign-off\")");
  cmd->add_option("RUN", o->run, "The stored run (see daq runs)")->required();
  cmd->add_option("--result", o->result,
                  "The result to approve (see daq show RUN; default: the run's current result, "
                  "when it has one). A result superseded since is refused");
  add_read_db_option(*cmd, o->db);
  cmd->add_flag("--json", o->json, "Print the approval as JSON (caldaq.approval.v1)");
}

void add_sync_command(CLI::App& app) {
  auto o = std::make_shared<SyncCliOptions>();
  auto* cmd = app.add_subcommand(
      "sync",
      "Copy the local runs to the central store on PostgreSQL (--to), or bring one machine's "
      "history from it (--from URI --machine NAME): each run once (by its UUID), resuming a cut "
      "sync from the chunks already there (docs/storage.md, \"Central store\")");
  add_db_option(*cmd, o->db);
  cmd->add_option("--to", o->to,
                  "The central store: postgresql://[user[:password]@]host[:port]/database "
                  "(libpq URI; also ?host=/socket/dir)");
  cmd->add_option(
      "--from", o->from,
      "Bring a machine's history (runs, results, readings, compensation tables, "
      "models, ballbar calibrations) from this central store into the local one (--machine)");
  cmd->add_option("--machine", o->machine,
                  "With --from: the machine, by its name on the server or by its UUID (when "
                  "two sites' machines share the name)");
  cmd->add_option("--site", o->site,
                  "With --to: the site of the machines new to the server (default: the [customer] "
                  "site of their runs' configuration, else the one site the login may write); a "
                  "machine on the server keeps its site (docs/storage.md, \"Sites\")")
      ->check(CLI::Validator(
          [](const std::string& v) { return v.empty() ? std::string("a site is not empty") : ""; },
          "SITE"));
  cmd->add_option("--run", o->runs, "Only these runs (local ids; default: every run)");
  cmd->add_option("--version", o->versions,
                  "With --from, RUN:N (repeatable): bring that run (its id on the server, or its "
                  "UUID) with version N of its stops instead of the current one, into a store "
                  "that lacks it (daq show RUN --db postgresql://... lists the versions)");
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
