// The SQLite run store (see store.hpp; schema and chunk format in docs/storage.md).
#include "cal/storage/store.hpp"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <thread>

#include "cal/analysis/enum_names.hpp"
#include "store_impl.hpp"

namespace cal::storage {

namespace {
constexpr EnumName<RunStatus> kStatusNames[] = {{RunStatus::running, "running"},
                                                {RunStatus::complete, "complete"},
                                                {RunStatus::incomplete, "incomplete"},
                                                {RunStatus::aborted, "aborted"}};
static_assert(cal::names_every_value(kStatusNames));
}  // namespace

std::string_view to_string(RunStatus s) { return name_of(kStatusNames, s, "unknown"); }

namespace {

using detail::Stmt;

// The CHECK constraint admits only the four names; anything else reads as still running.
RunStatus status_from(std::string_view s) {
  return value_named(kStatusNames, s).value_or(RunStatus::running);
}

// A random (version 4) UUID in canonical lower-case text, made by SQLite for each row a
// migration gives one (as new_uuid() makes them).
#define CALDAQ_RANDOM_UUID                                                                       \
  "lower(hex(randomblob(4)) || '-' || hex(randomblob(2)) || '-4' || substr(hex(randomblob(2)), " \
  "2) || '-' || substr('89AB', 1 + (abs(random()) % 4), 1) || substr(hex(randomblob(2)), 2) || " \
  "'-' || hex(randomblob(6)))"

// The schema, one entry per version: entry k migrates from version k to k + 1. A migration
// runs in one transaction with the user_version update, so a crash mid-migration leaves the
// previous version intact.
constexpr const char* kMigrations[] = {
    R"sql(
CREATE TABLE machines(
  id INTEGER PRIMARY KEY,
  name TEXT NOT NULL UNIQUE,
  description TEXT NOT NULL DEFAULT '',
  config_json TEXT NOT NULL DEFAULT '{}');
CREATE TABLE runs(
  id INTEGER PRIMARY KEY,
  machine_id INTEGER REFERENCES machines(id),
  campaign TEXT NOT NULL DEFAULT '',
  kind TEXT NOT NULL,
  axis TEXT NOT NULL DEFAULT '',
  settings_json TEXT NOT NULL DEFAULT '{}',
  capture_path TEXT NOT NULL DEFAULT '',
  software_version TEXT NOT NULL DEFAULT '',
  started_unix_ms INTEGER NOT NULL,
  ended_unix_ms INTEGER,
  status TEXT NOT NULL CHECK(status IN ('running', 'complete', 'incomplete', 'aborted')),
  note TEXT NOT NULL DEFAULT '',
  owner_pid INTEGER NOT NULL DEFAULT 0);
CREATE TABLE instruments(
  run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  device INTEGER NOT NULL,
  driver TEXT NOT NULL,
  transport TEXT NOT NULL,
  settings_json TEXT NOT NULL DEFAULT '{}',
  PRIMARY KEY(run_id, device));
CREATE TABLE reading_chunks(
  id INTEGER PRIMARY KEY,
  run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  device INTEGER NOT NULL,
  channel INTEGER NOT NULL,
  quantity INTEGER NOT NULL,
  first_ns INTEGER NOT NULL,
  last_ns INTEGER NOT NULL,
  count INTEGER NOT NULL,
  data BLOB NOT NULL);
CREATE INDEX reading_chunks_by_run ON reading_chunks(run_id, first_ns);
CREATE TABLE captured_targets(
  run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  target_index INTEGER NOT NULL,
  run_number INTEGER NOT NULL,
  direction TEXT NOT NULL CHECK(direction IN ('+', '-')),
  nominal_mm REAL NOT NULL,
  time_ns INTEGER NOT NULL,
  raw_m REAL NOT NULL,
  deviation_um REAL NOT NULL,
  refractive_index REAL NOT NULL,
  material_temperature_degc REAL NOT NULL,
  PRIMARY KEY(run_id, run_number, direction, target_index));
CREATE TABLE results(
  id INTEGER PRIMARY KEY,
  run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  standard TEXT NOT NULL,
  json TEXT NOT NULL,
  created_unix_ms INTEGER NOT NULL);
)sql",
    // 1 -> 2: what makes a result traceable (docs/storage.md): its provenance and whether a
    // later result superseded it; the planned stops a run never captured; the run's time
    // origin. Results already stored: a later result of the same standard, or a later
    // re-compensation, supersedes an earlier one.
    R"sql(
ALTER TABLE results ADD COLUMN provenance_json TEXT NOT NULL DEFAULT '{}';
ALTER TABLE results ADD COLUMN superseded_by INTEGER REFERENCES results(id);
UPDATE results SET superseded_by = (
  SELECT MIN(later.id) FROM results AS later
  WHERE later.run_id = results.run_id AND later.id > results.id
    AND (later.standard = results.standard OR later.standard LIKE '%(recompensated)'));
CREATE INDEX results_by_run ON results(run_id, id);
CREATE TABLE missed_stops(
  run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  run_number INTEGER NOT NULL,
  direction TEXT NOT NULL CHECK(direction IN ('+', '-')),
  target_index INTEGER NOT NULL,
  nominal_mm REAL NOT NULL,
  PRIMARY KEY(run_id, run_number, direction, target_index));
ALTER TABLE runs ADD COLUMN origin_session_ns INTEGER;
ALTER TABLE runs ADD COLUMN origin_unix_ns INTEGER;
)sql",
    // 2 -> 3: reading chunks carry their encoding (1: the 17-byte records of schemas 1 and 2, kept
    // as they are; 2: chunk.hpp), their sequence number in the run and a CRC-32C over their
    // row and BLOB (NULL for the chunks written before), checked on every read; the file says
    // it is caldaq's (application id "CALD").
    R"sql(
ALTER TABLE reading_chunks ADD COLUMN encoding INTEGER NOT NULL DEFAULT 1;
ALTER TABLE reading_chunks ADD COLUMN seq INTEGER;
ALTER TABLE reading_chunks ADD COLUMN crc INTEGER;
CREATE UNIQUE INDEX reading_chunks_by_seq ON reading_chunks(run_id, seq);
PRAGMA application_id = 1128352836;
)sql",
    // 3 -> 4 (issue 18): ballbar calibrations against a calibrator, with their date, so that a
    // test's absolute radius names the calibration it used.
    R"sql(
CREATE TABLE ballbar_calibrations(
  id INTEGER PRIMARY KEY,
  bar TEXT NOT NULL CHECK(bar <> ''),
  nominal_mm REAL NOT NULL CHECK(nominal_mm > 0),
  extensions TEXT NOT NULL DEFAULT '',
  calibrator TEXT NOT NULL DEFAULT '',
  calibrator_length_mm REAL NOT NULL CHECK(calibrator_length_mm > 0),
  reading_mm REAL NOT NULL,
  zero_length_mm REAL NOT NULL CHECK(zero_length_mm > 0),
  temperature_degc REAL,
  calibrated_unix_ms INTEGER NOT NULL,
  note TEXT NOT NULL DEFAULT '');
CREATE INDEX ballbar_calibrations_by_bar
  ON ballbar_calibrations(bar, nominal_mm, calibrated_unix_ms);
)sql",
    // 4 -> 5 (issue 26): what is acted on must be traceable and sound. Where each instrument's
    // readings came from (a real device, a simulated twin, a replay of which capture; '' before
    // this schema: not recorded); the compensation tables written from runs or models, with
    // what they were predicted to leave, so that the next measurement of the axis can be
    // compared with the prediction; and the quality gate of a run's stops (docs/iso230-2.md,
    // "Suspect stops"): why a stop is suspect (NULL: it is not), the run's verdict ('ok',
    // 'suspect', 'not checked'; NULL: stored before the gate, assessed when read) and its summary.
    R"sql(
ALTER TABLE instruments ADD COLUMN origin TEXT NOT NULL DEFAULT '';
ALTER TABLE instruments ADD COLUMN origin_detail TEXT NOT NULL DEFAULT '';
CREATE TABLE compensations(
  id INTEGER PRIMARY KEY,
  machine_id INTEGER REFERENCES machines(id),
  source_run_id INTEGER REFERENCES runs(id) ON DELETE SET NULL,
  source TEXT NOT NULL DEFAULT '',
  axis TEXT NOT NULL,
  format TEXT NOT NULL,
  created_unix_ms INTEGER NOT NULL,
  json TEXT NOT NULL);
CREATE INDEX compensations_by_machine ON compensations(machine_id, axis, created_unix_ms);
ALTER TABLE captured_targets ADD COLUMN suspect TEXT;
ALTER TABLE runs ADD COLUMN quality TEXT
  CHECK(quality IS NULL OR quality IN ('ok', 'suspect', 'not checked'));
ALTER TABLE runs ADD COLUMN quality_note TEXT NOT NULL DEFAULT '';
)sql",
    // 5 -> 6 (issue 29): what the operator did during a run (a stop captured by hand, a target
    // skipped or measured again, the run paused and resumed), when, from where and by whom,
    // written as it happens so a killed run keeps it.
    R"sql(
CREATE TABLE operator_actions(
  id INTEGER PRIMARY KEY,
  run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  time_unix_ms INTEGER NOT NULL,
  action TEXT NOT NULL CHECK(action IN ('capture', 'skip', 'retry', 'pause', 'resume')),
  source TEXT NOT NULL DEFAULT '',
  operator TEXT NOT NULL DEFAULT '',
  run_number INTEGER,
  direction TEXT CHECK(direction IS NULL OR direction IN ('+', '-')),
  target_index INTEGER,
  nominal_mm REAL,
  detail TEXT NOT NULL DEFAULT '');
CREATE INDEX operator_actions_by_run ON operator_actions(run_id, id);
)sql",
    // 6 -> 7 (issue 35): a stable identity per run, a random UUID, by which the central store
    // (daq sync) knows it whatever its local id; the runs already stored get theirs now.
    R"sql(
ALTER TABLE runs ADD COLUMN uuid TEXT;
UPDATE runs SET uuid = )sql" CALDAQ_RANDOM_UUID R"sql(;
CREATE UNIQUE INDEX runs_by_uuid ON runs(uuid);
)sql",
    // 7 -> 8 (issue 35): a stable identity per machine, a random UUID, by which the central
    // store tells machines apart (two sites may each have a "Mill 1").
    R"sql(
ALTER TABLE machines ADD COLUMN uuid TEXT;
UPDATE machines SET uuid = )sql" CALDAQ_RANDOM_UUID R"sql(;
CREATE UNIQUE INDEX machines_by_uuid ON machines(uuid);
)sql",
    // 8 -> 9 (issue 35): sign-off. A reviewer's approval of one result (the exact one: a
    // re-analysis makes a new result, not approved), who and when; a report is issued as a
    // certificate only for an approved result. Central schema 6 holds the server's approvals.
    R"sql(
CREATE TABLE approvals(
  id INTEGER PRIMARY KEY,
  result_id INTEGER NOT NULL UNIQUE REFERENCES results(id) ON DELETE CASCADE,
  approved_by TEXT NOT NULL,
  approved_unix_ms INTEGER NOT NULL);
)sql",
    // 9 -> 10 (issue 35): the central server's approvals of the results a laptop brought (daq
    // sync --from), read-only here: who approved there, when, the result's fingerprint and the
    // run's version there, and the server (its URI, password hidden). A report on the laptop is
    // issued as the server would issue it.
    R"sql(
CREATE TABLE central_approvals(
  id INTEGER PRIMARY KEY,
  result_id INTEGER NOT NULL UNIQUE REFERENCES results(id) ON DELETE CASCADE,
  result_fingerprint TEXT NOT NULL,
  run_version INTEGER NOT NULL,
  approved_by TEXT NOT NULL,
  approved_unix_ms INTEGER NOT NULL,
  server TEXT NOT NULL);
)sql",
    // 10 -> 11 (issue 35): machine models kept in the store (daq model build --store, daq model
    // store), each with a stable UUID (daq sync sends and brings it once), the model file's text
    // as written and its provenance (the runs it was built from, their versions; who stored it,
    // from where, when). A model is never changed once stored.
    R"sql(
CREATE TABLE models(
  id INTEGER PRIMARY KEY,
  uuid TEXT NOT NULL UNIQUE,
  machine_id INTEGER NOT NULL REFERENCES machines(id),
  name TEXT NOT NULL DEFAULT '',
  json TEXT NOT NULL CHECK(json <> ''),
  provenance_json TEXT NOT NULL DEFAULT '{}',
  stored_by TEXT NOT NULL DEFAULT '',
  stored_from TEXT NOT NULL DEFAULT '',
  stored_unix_ms INTEGER NOT NULL);
CREATE INDEX models_by_machine ON models(machine_id, id);
)sql",
};
static_assert(std::size(kMigrations) == schema_version);

constexpr std::int64_t kApplicationId = 0x43414C44;  // "CALD"

std::int64_t unix_ms_now() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace

namespace {

using detail::bind_all;
using detail::read_all;

void bind_text(sqlite3_stmt* s, int i, std::string_view v) { detail::bind_value(s, i, v); }

bool process_alive(std::int64_t pid) {
  if (pid <= 0) return false;
  return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM;
}

// The owner_pid of a run another store recorded (Store::import_run, daq sync --from): its
// acquisition is not a process here, so a running one is not interrupted when none here runs it.
constexpr std::int64_t kAcquiredElsewhere = -1;

// Whether a running run's writing process here is gone (kill -9, power loss, crash).
bool interrupted_here(std::int64_t owner_pid) {
  return owner_pid != kAcquiredElsewhere && !process_alive(owner_pid);
}

std::int64_t query_int(const Store::Impl& m, const char* sql, std::string_view what) {
  auto s = m.prepare(sql);
  if (sqlite3_step(s.get()) != SQLITE_ROW) m.fail(what);
  return sqlite3_column_int64(s.get(), 0);
}

// "file:" URI of a path, for SQLite's URI parameters: everything but unreserved characters
// and '/' percent-encoded.
std::string file_uri(const std::filesystem::path& path) {
  std::string uri = "file:";
  for (unsigned char c : std::filesystem::absolute(path).string()) {
    if (std::isalnum(c) || c == '/' || c == '-' || c == '_' || c == '.' || c == '~')
      uri += static_cast<char>(c);
    else
      uri += fmt::format("%{:02X}", c);
  }
  return uri;
}

// A reference to another row: NULL for 0 (none).
std::optional<std::int64_t> id_or_null(std::int64_t id) {
  return id > 0 ? std::optional(id) : std::nullopt;
}

// Every row of `sql`, with `params` bound to its parameters, as a T read by `read(stmt, T&)`.
template <class T, class Read, class... Params>
std::vector<T> rows_of(const Store::Impl& m, const std::string& sql, Read read,
                       const Params&... params) {
  auto s = m.prepare(sql.c_str());
  bind_all(s.get(), params...);
  std::vector<T> out;
  while (sqlite3_step(s.get()) == SQLITE_ROW) read(s.get(), out.emplace_back());
  return out;
}

constexpr std::string_view kInterrupted =
    "interrupted: the writing process ended without finishing the run";

}  // namespace

// A caldaq database, or a new empty one; refuses a file that is not a database, another
// program's SQLite database, and a newer schema. Reads only.
void Store::Impl::check_caldaq_database() {
  // The first statement reads the header: a file that is not a database fails here.
  auto s = prepare(
      "SELECT (SELECT count(*) FROM sqlite_master), "
      "(SELECT count(*) FROM sqlite_master WHERE type = 'table' AND name IN ('runs', "
      "'reading_chunks')), "
      "(SELECT group_concat(name, ', ') FROM (SELECT name FROM sqlite_master WHERE type = "
      "'table' ORDER BY name LIMIT 4))");
  if (sqlite3_step(s.get()) != SQLITE_ROW) fail("not a caldaq database");
  const auto objects = sqlite3_column_int64(s.get(), 0);
  const bool ours = sqlite3_column_int64(s.get(), 1) == 2;
  const auto* names_text = sqlite3_column_text(s.get(), 2);
  const std::string names = names_text ? reinterpret_cast<const char*>(names_text) : "";
  const auto app = query_int(*this, "PRAGMA application_id", "read the application id");
  version = static_cast<int>(query_int(*this, "PRAGMA user_version", "read schema version"));
  if (app != 0 && app != kApplicationId)
    throw StoreError(fmt::format(
        "{}: not a caldaq database: its SQLite application id is 0x{:08X} (another program's "
        "file); nothing was changed",
        path.string(), static_cast<std::uint32_t>(app)));
  if (objects > 0 && (!ours || version < 1))
    throw StoreError(fmt::format(
        "{}: not a caldaq database: an SQLite database with other tables ({}{}); nothing was "
        "changed",
        path.string(), names, objects > 4 ? ", ..." : ""));
  if (objects == 0 && read_only)
    throw StoreError(fmt::format(
        "{}: an empty SQLite database, not a caldaq one: there is nothing to read", path.string()));
  if (version > schema_version)
    throw StoreError(fmt::format(
        "{}: schema version {} is newer than this daq understands ({}); use a newer daq",
        path.string(), version, schema_version));
}

void Store::Impl::open_read_write(const StoreOptions& options) {
  sqlite3* raw = nullptr;
  const int rc =
      sqlite3_open_v2(path.c_str(), &raw, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr);
  db.reset(raw);
  if (rc != SQLITE_OK) fail("cannot open");
  sqlite3_busy_timeout(raw, 5000);  // a reader (daq runs) and the writer share the file
  check_caldaq_database();          // before anything is written to it
  // WAL is kept in the file: set by whichever command opens a new store first. Setting it needs
  // the file to itself, and SQLite does not wait for that through the busy timeout (no busy
  // handler for that lock: it could deadlock), so two commands opening one new store at once
  // (the demo writing it while another reads) failed with "database is locked". It is tried
  // again every 10 ms for up to the busy timeout's 5 s.
  for (int tries = 0;; ++tries) {
    const int wal = sqlite3_exec(raw, "PRAGMA journal_mode=WAL", nullptr, nullptr, nullptr);
    if (wal == SQLITE_OK) break;
    if (((wal & 0xff) != SQLITE_BUSY && (wal & 0xff) != SQLITE_LOCKED) || tries == 500)
      fail("set WAL mode");
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  exec(options.full_sync ? "PRAGMA synchronous=FULL" : "PRAGMA synchronous=NORMAL",
       "set synchronous");
  exec("PRAGMA foreign_keys=ON", "enable foreign keys");
  if (options.max_pages > 0)
    exec(fmt::format("PRAGMA max_page_count={}", options.max_pages).c_str(), "set max pages");
  while (version < schema_version) {
    Transaction tx(*this);  // BEGIN IMMEDIATE: the write lock before the version is read again
    // Another process may have migrated while this one waited for the lock (two commands
    // opening a new store at once: the second's migration 0 -> 1 failed with "table machines
    // already exists"): the version read under the lock decides.
    const int now =
        static_cast<int>(query_int(*this, "PRAGMA user_version", "read schema version"));
    if (now > schema_version)
      throw StoreError(fmt::format(
          "{}: schema version {} is newer than this daq understands ({}); use a newer daq",
          path.string(), now, schema_version));
    if (now != version) {
      version = now;  // migrated by the other: nothing of this transaction to keep
      continue;
    }
    const int v = version;
    exec(kMigrations[v], fmt::format("migrate schema {} -> {}", v, v + 1).c_str());
    exec(fmt::format("PRAGMA user_version={}", v + 1).c_str(), "set schema version");
    tx.commit();
    version = v + 1;
  }
}

// Read-only: SQLite's read-only mode, which writes nothing to the database. Reading a WAL
// database normally needs its -shm index; where that cannot be created (a read-only medium,
// a full disk) and no -wal file holds changes, the file is opened as immutable instead (no
// locks, no index: nothing else can be writing it then). With a non-empty -wal that cannot
// be read, the open fails rather than showing the database without those changes.
void Store::Impl::open_read_only() {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec))
    throw StoreError(fmt::format(
        "{}: no such database (a command that only reads does not create one; see --db and "
        "$CALDAQ_DB)",
        path.string()));
  const auto open = [&](const std::string& name, int flags) {
    sqlite3* raw = nullptr;
    const int rc = sqlite3_open_v2(name.c_str(), &raw, flags, nullptr);
    db.reset(raw);
    if (rc != SQLITE_OK) fail("cannot open for reading");
    sqlite3_busy_timeout(raw, 5000);
    sqlite3_extended_result_codes(raw, 1);
  };
  open(path.string(), SQLITE_OPEN_READONLY);
  // Probe: the first read (at prepare: the schema) opens the WAL index if there is one.
  {
    sqlite3_stmt* probe = nullptr;
    int rc =
        sqlite3_prepare_v2(db.get(), "SELECT count(*) FROM sqlite_master", -1, &probe, nullptr);
    if (rc == SQLITE_OK) rc = sqlite3_step(probe);
    sqlite3_finalize(probe);
    rc &= 0xff;
    if (rc != SQLITE_ROW && rc != SQLITE_CANTOPEN && rc != SQLITE_READONLY && rc != SQLITE_IOERR)
      fail("not a caldaq database");
    if (rc != SQLITE_ROW) {
      const std::filesystem::path wal = path.string() + "-wal";
      if (std::filesystem::exists(wal, ec) && std::filesystem::file_size(wal, ec) > 0)
        fail(fmt::format(
            "cannot read it here: {} holds changes not yet in the database (the writing "
            "program did not close it) and its index cannot be created (read-only or full "
            "disk); copy the database with its -wal file to a writable disk, or open it once "
            "with a command that writes",
            wal.string()));
      open(file_uri(path) + "?mode=ro&immutable=1", SQLITE_OPEN_READONLY | SQLITE_OPEN_URI);
    }
  }
  check_caldaq_database();
  if (version < 2) {
    // Schema 1 read as it is: what schema 2 added is presented by TEMP views and an empty TEMP
    // table, which live in the connection's temporary database (unqualified names find them
    // first), so the queries of today's schema read it and nothing is written to the file.
    // The superseded results are those migration 1 -> 2 would mark.
    exec(R"sql(
CREATE TEMP VIEW runs AS SELECT *, NULL AS origin_session_ns, NULL AS origin_unix_ns,
  NULL AS uuid FROM main.runs;
CREATE TEMP VIEW results AS SELECT r.*, '{}' AS provenance_json,
  (SELECT MIN(later.id) FROM main.results AS later
   WHERE later.run_id = r.run_id AND later.id > r.id
     AND (later.standard = r.standard OR later.standard LIKE '%(recompensated)'))
  AS superseded_by FROM main.results AS r;
CREATE TEMP TABLE missed_stops(run_id INTEGER, run_number INTEGER, direction TEXT,
  target_index INTEGER, nominal_mm REAL);
)sql",
         "present schema 1 as schema 2 (read-only)");
  }
  if (version < 4)  // before the ballbar calibrations: none (an empty TEMP table, as above)
    exec(R"sql(
CREATE TEMP TABLE ballbar_calibrations(id INTEGER PRIMARY KEY, bar TEXT, nominal_mm REAL,
  extensions TEXT, calibrator TEXT, calibrator_length_mm REAL, reading_mm REAL,
  zero_length_mm REAL, temperature_degc REAL, calibrated_unix_ms INTEGER, note TEXT);
)sql",
         "present an older schema without ballbar calibrations (read-only)");
  if (version < 5)  // before origins and compensations: not recorded, none
    exec(R"sql(
CREATE TEMP VIEW instruments AS SELECT *, '' AS origin, '' AS origin_detail FROM main.instruments;
CREATE TEMP TABLE compensations(id INTEGER PRIMARY KEY, machine_id INTEGER, source_run_id INTEGER,
  source TEXT, axis TEXT, format TEXT, created_unix_ms INTEGER, json TEXT);
)sql",
         "present an older schema without origins and compensations (read-only)");
  if (version < 6)  // before the operator's actions were recorded: none
    exec(R"sql(
CREATE TEMP TABLE operator_actions(id INTEGER PRIMARY KEY, run_id INTEGER, time_unix_ms INTEGER,
  action TEXT, source TEXT, operator TEXT, run_number INTEGER, direction TEXT,
  target_index INTEGER, nominal_mm REAL, detail TEXT);
)sql",
         "present an older schema without operator actions (read-only)");
  if (version >= 2 && version < 7)  // before the runs' UUIDs: none (RunRecord::uuid "")
    exec("CREATE TEMP VIEW runs AS SELECT *, NULL AS uuid FROM main.runs;",
         "present an older schema without run UUIDs (read-only)");
  if (version < 8)  // before the machines' UUIDs: none (MachineRecord::uuid "")
    exec("CREATE TEMP VIEW machines AS SELECT *, NULL AS uuid FROM main.machines;",
         "present an older schema without machine UUIDs (read-only)");
  if (version < 9)  // before sign-off: nothing approved
    exec(
        "CREATE TEMP TABLE approvals(id INTEGER PRIMARY KEY, result_id INTEGER, approved_by "
        "TEXT, approved_unix_ms INTEGER);",
        "present an older schema without approvals (read-only)");
  if (version < 10)  // before the central approvals were brought: none
    exec(
        "CREATE TEMP TABLE central_approvals(id INTEGER PRIMARY KEY, result_id INTEGER, "
        "result_fingerprint TEXT, run_version INTEGER, approved_by TEXT, approved_unix_ms "
        "INTEGER, server TEXT);",
        "present an older schema without central approvals (read-only)");
  if (version < 11)  // before models were kept: none
    exec(
        "CREATE TEMP TABLE models(id INTEGER PRIMARY KEY, uuid TEXT, machine_id INTEGER, name "
        "TEXT, json TEXT, provenance_json TEXT, stored_by TEXT, stored_from TEXT, stored_unix_ms "
        "INTEGER);",
        "present an older schema without models (read-only)");
  has_quality = version >= 5;  // older: read as it is, every run never checked
  auto has = prepare(
      "SELECT count(*) FROM pragma_table_info('reading_chunks') WHERE name IN "
      "('encoding', 'seq', 'crc')");
  chunk_checksums =
      sqlite3_step(has.get()) == SQLITE_ROW && sqlite3_column_int64(has.get(), 0) == 3;
}

Store::Store(const std::filesystem::path& path, StoreOptions options)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.path = path;
  m.read_only = options.read_only;
  if (m.read_only) {
    m.open_read_only();
    return;
  }
  m.open_read_write(options);
  // Runs whose writing process is gone were interrupted (kill -9, power loss, crash).
  std::vector<std::int64_t> orphans;
  {
    auto s = m.prepare("SELECT id, owner_pid FROM runs WHERE status = 'running'");
    while (sqlite3_step(s.get()) == SQLITE_ROW)
      if (interrupted_here(sqlite3_column_int64(s.get(), 1)))
        orphans.push_back(sqlite3_column_int64(s.get(), 0));
  }
  for (auto id : orphans) finish_run(id, RunStatus::incomplete, kInterrupted);
}

Store::~Store() = default;
Store::Store(Store&&) noexcept = default;
Store& Store::operator=(Store&&) noexcept = default;

const std::filesystem::path& Store::path() const { return impl_->path; }
std::string Store::name() const { return impl_->path.string(); }
int Store::version() const { return impl_->version; }
bool Store::read_only() const { return impl_->read_only; }

std::int64_t Store::add_machine(const MachineRecord& r) {
  impl_->need_writable("add machine");
  if (!r.uuid.empty() && !is_uuid(r.uuid))
    throw StoreError(fmt::format("{}: add machine '{}': '{}' is not a UUID", impl_->path.string(),
                                 r.name, r.uuid));
  auto s = impl_->prepare(
      "INSERT INTO machines(name, description, config_json, uuid) VALUES(?, ?, ?, ?)");
  bind_all(s.get(), r.name, r.description, r.config_json, r.uuid.empty() ? new_uuid() : r.uuid);
  impl_->step_done(s.get(), fmt::format("add machine '{}'", r.name));
  return sqlite3_last_insert_rowid(impl_->db.get());
}

namespace {
std::optional<MachineRecord> machine_row(sqlite3_stmt* s) {
  if (sqlite3_step(s) != SQLITE_ROW) return std::nullopt;
  MachineRecord r;
  read_all(s, r.id, r.name, r.description, r.config_json, r.uuid);
  return r;
}
}  // namespace

std::optional<MachineRecord> Store::machine_by_name(std::string_view name) const {
  auto s = impl_->prepare(
      "SELECT id, name, description, config_json, uuid FROM machines WHERE name = ?");
  bind_text(s.get(), 1, name);
  return machine_row(s.get());
}

std::optional<MachineRecord> Store::machine(std::int64_t id) const {
  auto s =
      impl_->prepare("SELECT id, name, description, config_json, uuid FROM machines WHERE id = ?");
  sqlite3_bind_int64(s.get(), 1, id);
  return machine_row(s.get());
}

std::optional<MachineRecord> Store::machine_by_uuid(std::string_view uuid) const {
  auto s = impl_->prepare(
      "SELECT id, name, description, config_json, uuid FROM machines WHERE uuid = ?");
  bind_text(s.get(), 1, uuid);
  return machine_row(s.get());
}

std::int64_t Store::begin_run(const RunRecord& r) {
  impl_->need_writable("begin run");
  auto s = impl_->prepare(
      "INSERT INTO runs(machine_id, campaign, kind, axis, settings_json, capture_path, "
      "software_version, started_unix_ms, status, note, owner_pid, uuid) "
      "VALUES(?, ?, ?, ?, ?, ?, ?, ?, 'running', ?, ?, ?)");
  if (!r.uuid.empty() && !is_uuid(r.uuid))
    throw StoreError(fmt::format("{}: begin run: '{}' is not a UUID (8-4-4-4-12 lower-case hex)",
                                 impl_->path.string(), r.uuid));
  bind_all(s.get(), id_or_null(r.machine_id), r.campaign, r.kind, r.axis, r.settings_json,
           r.capture_path, r.software_version,
           r.started_unix_ms ? r.started_unix_ms : unix_ms_now(), r.note, std::int64_t{::getpid()},
           r.uuid.empty() ? new_uuid() : r.uuid);
  impl_->step_done(s.get(), "begin run");
  return sqlite3_last_insert_rowid(impl_->db.get());
}

void Store::add_instrument(const InstrumentRecord& i) {
  impl_->need_writable("add instrument");
  auto s = impl_->prepare(
      "INSERT INTO instruments(run_id, device, driver, transport, settings_json, origin, "
      "origin_detail) VALUES(?, ?, ?, ?, ?, ?, ?)");
  bind_all(s.get(), i.run_id, i.device, i.driver, i.transport, i.settings_json, i.origin,
           i.origin_detail);
  impl_->step_done(s.get(), fmt::format("add instrument {} to run {}", i.device, i.run_id));
}

void Store::finish_run(std::int64_t run_id, RunStatus status, std::string_view note) {
  impl_->need_writable("finish run");
  auto s = impl_->prepare(
      "UPDATE runs SET status = ?, ended_unix_ms = ?, note = CASE WHEN ? = '' THEN note ELSE ? "
      "END WHERE id = ?");
  bind_text(s.get(), 1, to_string(status));
  sqlite3_bind_int64(s.get(), 2, unix_ms_now());
  bind_text(s.get(), 3, note);
  bind_text(s.get(), 4, note);
  sqlite3_bind_int64(s.get(), 5, run_id);
  impl_->step_done(s.get(), fmt::format("finish run {}", run_id));
  if (sqlite3_changes(impl_->db.get()) == 0)
    throw StoreError(fmt::format("{}: no run {}", impl_->path.string(), run_id));
}

void Store::set_capture_path(std::int64_t run_id, std::string_view path) {
  impl_->need_writable("set capture path");
  auto s = impl_->prepare("UPDATE runs SET capture_path = ? WHERE id = ?");
  bind_text(s.get(), 1, path);
  sqlite3_bind_int64(s.get(), 2, run_id);
  impl_->step_done(s.get(), "set capture path");
}

namespace {
constexpr const char* kRunColumns =
    "SELECT id, IFNULL(machine_id, 0), campaign, kind, axis, settings_json, capture_path, "
    "software_version, started_unix_ms, ended_unix_ms, status, note, owner_pid, "
    "origin_session_ns, origin_unix_ns, uuid FROM runs";

// A read-only store cannot mark an interrupted run, so it shows it as the writing open would
// have marked it, and says so.
RunRecord read_run(sqlite3_stmt* s, bool read_only) {
  RunRecord r;
  std::string status;
  std::int64_t owner_pid = 0;
  read_all(s, r.id, r.machine_id, r.campaign, r.kind, r.axis, r.settings_json, r.capture_path,
           r.software_version, r.started_unix_ms, r.ended_unix_ms, status, r.note, owner_pid,
           r.origin_session_ns, r.origin_unix_ns, r.uuid);
  r.status = status_from(status);
  if (read_only && r.status == RunStatus::running && interrupted_here(owner_pid)) {
    r.status = RunStatus::incomplete;
    r.note = fmt::format("{} (not yet marked so in the database, which was opened read-only)",
                         kInterrupted);
  }
  return r;
}
}  // namespace

std::vector<RunRecord> Store::runs() const {
  return rows_of<RunRecord>(
      *impl_, std::string(kRunColumns) + " ORDER BY id",
      [&](sqlite3_stmt* s, RunRecord& r) { r = read_run(s, impl_->read_only); });
}

std::optional<RunRecord> Store::run(std::int64_t run_id) const {
  auto s = impl_->prepare((std::string(kRunColumns) + " WHERE id = ?").c_str());
  sqlite3_bind_int64(s.get(), 1, run_id);
  if (sqlite3_step(s.get()) != SQLITE_ROW) return std::nullopt;
  return read_run(s.get(), impl_->read_only);
}

std::optional<RunRecord> Store::run_by_uuid(std::string_view uuid) const {
  auto s = impl_->prepare((std::string(kRunColumns) + " WHERE uuid = ?").c_str());
  bind_text(s.get(), 1, uuid);
  if (sqlite3_step(s.get()) != SQLITE_ROW) return std::nullopt;
  return read_run(s.get(), impl_->read_only);
}

std::vector<InstrumentRecord> Store::instruments(std::int64_t run_id) const {
  return rows_of<InstrumentRecord>(
      *impl_,
      "SELECT run_id, device, driver, transport, settings_json, origin, origin_detail FROM "
      "instruments WHERE run_id = ? ORDER BY device",
      [](sqlite3_stmt* s, InstrumentRecord& i) {
        read_all(s, i.run_id, i.device, i.driver, i.transport, i.settings_json, i.origin,
                 i.origin_detail);
      },
      run_id);
}

std::int64_t Store::add_compensation(const CompensationRecord& c) {
  impl_->need_writable("add compensation");
  auto s = impl_->prepare(
      "INSERT INTO compensations(machine_id, source_run_id, source, axis, format, "
      "created_unix_ms, json) VALUES(?, ?, ?, ?, ?, ?, ?)");
  bind_all(s.get(), id_or_null(c.machine_id), id_or_null(c.source_run_id), c.source, c.axis,
           c.format, c.created_unix_ms ? c.created_unix_ms : unix_ms_now(), c.json);
  impl_->step_done(s.get(), fmt::format("add the compensation of axis {} ({})", c.axis, c.format));
  return sqlite3_last_insert_rowid(impl_->db.get());
}

std::vector<CompensationRecord> Store::compensations(std::int64_t machine_id,
                                                     std::string_view axis) const {
  return rows_of<CompensationRecord>(
      *impl_,
      "SELECT id, IFNULL(machine_id, 0), IFNULL(source_run_id, 0), source, axis, format, "
      "created_unix_ms, json FROM compensations WHERE (? = 0 OR machine_id = ?) AND (? = '' OR "
      "axis = ?) ORDER BY created_unix_ms, id",
      [](sqlite3_stmt* s, CompensationRecord& c) {
        read_all(s, c.id, c.machine_id, c.source_run_id, c.source, c.axis, c.format,
                 c.created_unix_ms, c.json);
      },
      machine_id, machine_id, axis, axis);
}

std::int64_t Store::add_model(const ModelRecord& m) {
  Impl& impl = *impl_;
  impl.need_writable("store a model");
  if (!m.uuid.empty() && !is_uuid(m.uuid))
    throw StoreError(
        fmt::format("{}: store a model: '{}' is not a UUID (8-4-4-4-12 lower-case hex)",
                    impl.path.string(), m.uuid));
  if (m.json.empty())
    throw StoreError(fmt::format("{}: store a model: its text is empty", impl.path.string()));
  if (!machine(m.machine_id))
    throw StoreError(
        fmt::format("{}: store a model: no machine {} here", impl.path.string(), m.machine_id));
  const auto uuid = m.uuid.empty() ? new_uuid() : m.uuid;
  if (model_by_uuid(uuid))
    throw StoreError(
        fmt::format("{}: store a model: model {} is here already", impl.path.string(), uuid));
  auto s = impl.prepare(
      "INSERT INTO models(uuid, machine_id, name, json, provenance_json, stored_by, stored_from, "
      "stored_unix_ms) VALUES(?, ?, ?, ?, ?, ?, ?, ?)");
  bind_all(s.get(), uuid, m.machine_id, m.name, m.json, m.provenance_json, m.stored_by,
           m.stored_from, m.stored_unix_ms ? m.stored_unix_ms : unix_ms_now());
  impl.step_done(s.get(), fmt::format("store model {}", uuid));
  return sqlite3_last_insert_rowid(impl.db.get());
}

namespace {
constexpr const char* kModelColumns =
    "SELECT id, uuid, machine_id, name, json, provenance_json, stored_by, stored_from, "
    "stored_unix_ms FROM models";

void read_model(sqlite3_stmt* s, ModelRecord& m) {
  read_all(s, m.id, m.uuid, m.machine_id, m.name, m.json, m.provenance_json, m.stored_by,
           m.stored_from, m.stored_unix_ms);
}
}  // namespace

std::vector<ModelRecord> Store::models(std::int64_t machine_id) const {
  return rows_of<ModelRecord>(
      *impl_, std::string(kModelColumns) + " WHERE ? = 0 OR machine_id = ? ORDER BY id", read_model,
      machine_id, machine_id);
}

std::optional<ModelRecord> Store::model(std::int64_t id) const {
  auto rows =
      rows_of<ModelRecord>(*impl_, std::string(kModelColumns) + " WHERE id = ?", read_model, id);
  if (rows.empty()) return std::nullopt;
  return std::move(rows.front());
}

std::optional<ModelRecord> Store::model_by_uuid(std::string_view uuid) const {
  auto rows = rows_of<ModelRecord>(*impl_, std::string(kModelColumns) + " WHERE uuid = ?",
                                   read_model, uuid);
  if (rows.empty()) return std::nullopt;
  return std::move(rows.front());
}

void PreparedBatch::prepare(std::span<const RawReading> readings) {
  // Group by series (device, channel, quantity), keeping each series' order: one chunk each.
  // Batches hold a few series, interleaved: a linear search from the last hit is enough.
  // The columns are scratch kept per thread (a writer thread reuses them batch after batch).
  thread_local std::vector<chunk::Columns> columns;
  std::vector<std::uint32_t> keys;
  std::size_t g = 0;
  for (auto& c : columns) c.clear();
  for (const auto& r : readings) {
    const std::uint32_t key =
        (std::uint32_t{r.device} << 16) | (std::uint32_t{r.channel} << 8) | r.quantity;
    if (g >= keys.size() || keys[g] != key) {
      g = static_cast<std::size_t>(std::find(keys.begin(), keys.end(), key) - keys.begin());
      if (g == keys.size()) {
        keys.push_back(key);
        if (columns.size() < keys.size()) columns.emplace_back();
      }
    }
    columns[g].push(r);
  }
  used = keys.size();
  reading_count = readings.size();
  if (chunks.size() < used) chunks.resize(used);
  for (std::size_t k = 0; k < used; ++k) {
    const auto& c = columns[k];
    auto& out = chunks[k];
    chunk::encode(c, out.blob);
    const auto [lo, hi] = std::minmax_element(c.time_ns.begin(), c.time_ns.end());
    out.series = keys[k];
    out.first_ns = *lo;
    out.last_ns = *hi;
    out.count = static_cast<std::int64_t>(c.size());
  }
}

void Store::append_readings(std::int64_t run_id, std::span<const RawReading> readings) {
  impl_->need_writable("store readings");
  if (readings.empty()) return;
  impl_->prepared.prepare(readings);
  append_prepared(run_id, impl_->prepared);
}

void Store::append_prepared(std::int64_t run_id, const PreparedBatch& batch) {
  Impl& m = *impl_;
  m.need_writable("store readings");
  if (batch.used == 0) return;
  Impl::Transaction tx(m);
  if (!m.next_seq)
    m.next_seq = m.prepare(
        "SELECT IFNULL(MAX(seq), -1) + 1 FROM reading_chunks INDEXED BY reading_chunks_by_seq "
        "WHERE run_id = ?");
  if (!m.insert_chunk)
    m.insert_chunk = m.prepare(
        "INSERT INTO reading_chunks(run_id, device, channel, quantity, first_ns, last_ns, count, "
        "data, encoding, seq, crc) VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  sqlite3_bind_int64(m.next_seq.get(), 1, run_id);
  if (sqlite3_step(m.next_seq.get()) != SQLITE_ROW) m.fail("number the reading chunks");
  std::int64_t seq = sqlite3_column_int64(m.next_seq.get(), 0);
  sqlite3_reset(m.next_seq.get());
  sqlite3_stmt* s = m.insert_chunk.get();
  for (std::size_t k = 0; k < batch.used; ++k, ++seq) {
    const auto& c = batch.chunks[k];
    const chunk::Key key{.run_id = run_id,
                         .seq = seq,
                         .device = c.series >> 16,
                         .channel = (c.series >> 8) & 0xff,
                         .quantity = c.series & 0xff,
                         .first_ns = c.first_ns,
                         .last_ns = c.last_ns,
                         .count = c.count,
                         .encoding = chunk::columns_v2};
    bind_all(s, run_id, key.device, key.channel, key.quantity, key.first_ns, key.last_ns, key.count,
             c.blob, key.encoding, key.seq, std::int64_t{chunk::checksum(key, c.blob)});
    if (sqlite3_step(s) != SQLITE_DONE) {
      const std::string what = fmt::format("{}: store {} readings of run {}: {}", m.path.string(),
                                           c.count, run_id, sqlite3_errmsg(m.db.get()));
      sqlite3_reset(s);  // the cached statement is used again by the next batch
      throw StoreError(what);
    }
    sqlite3_reset(s);
  }
  tx.commit();
}

std::vector<Store::Series> Store::series(std::int64_t run_id) const {
  auto s = impl_->prepare(
      "SELECT device, channel, quantity, SUM(count), MIN(first_ns), MAX(last_ns) FROM "
      "reading_chunks WHERE run_id = ? GROUP BY device, channel, quantity ORDER BY device, "
      "channel, quantity");
  sqlite3_bind_int64(s.get(), 1, run_id);
  std::vector<Series> out;
  while (sqlite3_step(s.get()) == SQLITE_ROW)
    out.push_back({static_cast<std::uint16_t>(sqlite3_column_int(s.get(), 0)),
                   static_cast<std::uint8_t>(sqlite3_column_int(s.get(), 1)),
                   static_cast<std::uint8_t>(sqlite3_column_int(s.get(), 2)),
                   sqlite3_column_int64(s.get(), 3), sqlite3_column_int64(s.get(), 4),
                   sqlite3_column_int64(s.get(), 5)});
  return out;
}

// In the order written: by seq; the chunks of schema 1 and 2 (unnumbered) by row, and first,
// since a run's chunks are either all numbered or all unnumbered (schema 3 did not renumber).
std::vector<Store::StoredChunk> Store::stored_chunks(std::int64_t run_id, std::int64_t first,
                                                     std::size_t max_chunks) const {
  const Impl& m = *impl_;
  const std::string checks = m.chunk_checksums ? "encoding, seq, crc" : "1, NULL, NULL";
  auto s =
      m.prepare(("SELECT device, channel, quantity, first_ns, last_ns, count, data, " + checks +
                 " FROM reading_chunks WHERE run_id = ? ORDER BY seq IS NOT NULL, seq, id "
                 "LIMIT ? OFFSET ?")
                    .c_str());
  sqlite3_bind_int64(s.get(), 1, run_id);
  sqlite3_bind_int64(s.get(), 2, static_cast<std::int64_t>(max_chunks));
  sqlite3_bind_int64(s.get(), 3, first);
  std::vector<StoredChunk> out;
  for (std::int64_t place = first;; ++place) {
    const int rc = sqlite3_step(s.get());
    if (rc == SQLITE_DONE) break;
    if (rc != SQLITE_ROW) m.fail(fmt::format("read the reading chunks of run {}", run_id));
    StoredChunk c;
    std::optional<std::int64_t> seq, crc;
    read_all(s.get(), c.device, c.channel, c.quantity, c.first_ns, c.last_ns, c.count, c.data,
             c.encoding, seq, crc);
    c.stored_checksum = crc.has_value();
    c.seq = c.stored_checksum ? seq.value_or(0) : place;
    c.crc = chunk::checksum(chunk::key_of(run_id, c.seq, c), c.data);
    const char* damage = nullptr;
    if (c.stored_checksum && static_cast<std::uint32_t>(*crc) != c.crc)
      damage = "its checksum does not match its contents";
    else if (c.seq != place)
      damage = "the run's chunks are not numbered 0, 1, 2, ... (one is missing or twice)";
    if (damage)
      throw StoreError(fmt::format(
          "{}: run {}: reading chunk {} (device {}, channel {}, quantity {}; {} readings from {} "
          "ns) is damaged: {}",
          m.path.string(), run_id, c.seq, c.device, c.channel, c.quantity, c.count, c.first_ns,
          damage));
    out.push_back(std::move(c));
  }
  return out;
}

std::int64_t Store::chunk_count(std::int64_t run_id) const {
  auto s = impl_->prepare("SELECT count(*) FROM reading_chunks WHERE run_id = ?");
  sqlite3_bind_int64(s.get(), 1, run_id);
  if (sqlite3_step(s.get()) != SQLITE_ROW)
    impl_->fail(fmt::format("count the reading chunks of run {}", run_id));
  return sqlite3_column_int64(s.get(), 0);
}

std::int64_t Store::reading_count(std::int64_t run_id) const {
  auto s = impl_->prepare("SELECT IFNULL(SUM(count), 0) FROM reading_chunks WHERE run_id = ?");
  sqlite3_bind_int64(s.get(), 1, run_id);
  sqlite3_step(s.get());
  return sqlite3_column_int64(s.get(), 0);
}

namespace {
// The columns of a captured target, in the order of CapturedTarget's fields.
constexpr const char* kTargetColumns =
    "run_id, target_index, run_number, direction, nominal_mm, time_ns, raw_m, deviation_um, "
    "refractive_index, material_temperature_degc";
}  // namespace

void Store::Impl::insert_targets(std::span<const CapturedTarget> targets) {
  Impl& m = *this;
  auto s = m.prepare(fmt::format("INSERT INTO captured_targets({}) VALUES(?, ?, ?, ?, ?, ?, ?, ?, "
                                 "?, ?)",
                                 kTargetColumns)
                         .c_str());
  for (const auto& t : targets) {
    bind_all(s.get(), t.run_id, t.target_index, t.run_number, t.direction, t.nominal_mm, t.time_ns,
             t.raw_m, t.deviation_um, t.refractive_index, t.material_temperature_degc);
    m.step_done(s.get(), fmt::format("store target {} run {} {} of run {}", t.target_index,
                                     t.run_number, t.direction, t.run_id));
  }
}

void Store::add_targets(std::span<const CapturedTarget> targets) {
  Impl::Transaction tx(*impl_);
  impl_->insert_targets(targets);
  tx.commit();
}

void Store::replace_targets(std::int64_t run_id, std::span<const CapturedTarget> targets) {
  Impl::Transaction tx(*impl_);
  auto s = impl_->prepare("DELETE FROM captured_targets WHERE run_id = ?");
  sqlite3_bind_int64(s.get(), 1, run_id);
  impl_->step_done(s.get(), "delete targets");
  impl_->insert_targets(targets);
  tx.commit();
}

std::vector<CapturedTarget> Store::targets(std::int64_t run_id) const {
  return rows_of<CapturedTarget>(
      *impl_,
      fmt::format("SELECT {} FROM captured_targets WHERE run_id = ? ORDER BY time_ns, run_number, "
                  "target_index",
                  kTargetColumns),
      [](sqlite3_stmt* s, CapturedTarget& t) {
        read_all(s, t.run_id, t.target_index, t.run_number, t.direction, t.nominal_mm, t.time_ns,
                 t.raw_m, t.deviation_um, t.refractive_index, t.material_temperature_degc);
      },
      run_id);
}

std::int64_t Store::Impl::insert_result(const ResultRecord& r, Supersede how) {
  auto s = prepare(
      "INSERT INTO results(run_id, standard, json, created_unix_ms, provenance_json) "
      "VALUES(?, ?, ?, ?, ?)");
  bind_all(s.get(), r.run_id, r.standard, r.json,
           r.created_unix_ms ? r.created_unix_ms : unix_ms_now(),
           r.provenance_json.empty() ? std::string_view("{}") : r.provenance_json);
  step_done(s.get(), fmt::format("store result of run {}", r.run_id));
  const std::int64_t id = sqlite3_last_insert_rowid(db.get());
  if (how == Supersede::none) return id;
  auto u = prepare(how == Supersede::all
                       ? "UPDATE results SET superseded_by = ? WHERE run_id = ? AND id <> ? AND "
                         "superseded_by IS NULL"
                       : "UPDATE results SET superseded_by = ? WHERE run_id = ? AND id <> ? AND "
                         "superseded_by IS NULL AND standard = ?");
  bind_all(u.get(), id, r.run_id, id);
  if (how == Supersede::same_standard) bind_text(u.get(), 4, r.standard);
  step_done(u.get(), fmt::format("mark the results of run {} superseded", r.run_id));
  return id;
}

std::int64_t Store::add_result(const ResultRecord& r, Supersede how) {
  Impl::Transaction tx(*impl_);
  const auto id = impl_->insert_result(r, how);
  tx.commit();
  return id;
}

std::int64_t Store::replace_targets(std::int64_t run_id, std::span<const CapturedTarget> targets,
                                    const ResultRecord& result) {
  Impl::Transaction tx(*impl_);
  auto s = impl_->prepare("DELETE FROM captured_targets WHERE run_id = ?");
  sqlite3_bind_int64(s.get(), 1, run_id);
  impl_->step_done(s.get(), "delete targets");
  impl_->insert_targets(targets);
  const auto id = impl_->insert_result(result, Supersede::all);
  tx.commit();
  return id;
}

std::vector<ResultRecord> Store::results(std::int64_t run_id) const {
  return rows_of<ResultRecord>(
      *impl_,
      "SELECT run_id, standard, json, created_unix_ms, provenance_json, id, superseded_by "
      "FROM results WHERE run_id = ? ORDER BY id",
      [](sqlite3_stmt* s, ResultRecord& r) {
        read_all(s, r.run_id, r.standard, r.json, r.created_unix_ms, r.provenance_json, r.id,
                 r.superseded_by);
      },
      run_id);
}

void Store::set_missed_stops(std::int64_t run_id, std::span<const MissedStop> stops) {
  Impl::Transaction tx(*impl_);
  auto d = impl_->prepare("DELETE FROM missed_stops WHERE run_id = ?");
  sqlite3_bind_int64(d.get(), 1, run_id);
  impl_->step_done(d.get(), "delete missed stops");
  auto s = impl_->prepare(
      "INSERT INTO missed_stops(run_id, run_number, direction, target_index, nominal_mm) "
      "VALUES(?, ?, ?, ?, ?)");
  for (const auto& m : stops) {
    bind_all(s.get(), run_id, m.run_number, m.direction, m.target_index, m.nominal_mm);
    impl_->step_done(s.get(), fmt::format("store a missed stop of run {}", run_id));
  }
  tx.commit();
}

void Store::set_quality(std::int64_t run_id, const RunQuality& q) {
  if (q.state != "ok" && q.state != "suspect" && q.state != "not checked")
    throw StoreError(
        fmt::format("{}: run {}: unknown quality '{}'", impl_->path.string(), run_id, q.state));
  Impl::Transaction tx(*impl_);
  auto r = impl_->prepare("UPDATE runs SET quality = ?, quality_note = ? WHERE id = ?");
  bind_all(r.get(), q.state, q.summary, run_id);
  impl_->step_done(r.get(), fmt::format("store the quality of run {}", run_id));
  auto clear = impl_->prepare("UPDATE captured_targets SET suspect = NULL WHERE run_id = ?");
  sqlite3_bind_int64(clear.get(), 1, run_id);
  impl_->step_done(clear.get(), fmt::format("clear the suspect stops of run {}", run_id));
  auto mark = impl_->prepare(
      "UPDATE captured_targets SET suspect = ? WHERE run_id = ? AND run_number = ? AND "
      "direction = ? AND target_index = ?");
  for (const auto& m : q.suspects) {
    bind_all(mark.get(), m.reason, run_id, m.run_number, m.direction, m.target_index);
    impl_->step_done(mark.get(), fmt::format("mark a suspect stop of run {}", run_id));
  }
  tx.commit();
}

std::optional<RunQuality> Store::quality(std::int64_t run_id) const {
  if (!impl_->has_quality) return std::nullopt;
  auto r = impl_->prepare("SELECT quality, quality_note FROM runs WHERE id = ?");
  sqlite3_bind_int64(r.get(), 1, run_id);
  if (sqlite3_step(r.get()) != SQLITE_ROW || sqlite3_column_type(r.get(), 0) == SQLITE_NULL)
    return std::nullopt;
  RunQuality q;
  read_all(r.get(), q.state, q.summary);
  q.suspects = rows_of<StopMark>(
      *impl_,
      "SELECT run_number, direction, target_index, suspect FROM captured_targets "
      "WHERE run_id = ? AND suspect IS NOT NULL ORDER BY time_ns, run_number, target_index",
      [](sqlite3_stmt* s, StopMark& m) {
        read_all(s, m.run_number, m.direction, m.target_index, m.reason);
      },
      run_id);
  return q;
}

std::vector<MissedStop> Store::missed_stops(std::int64_t run_id) const {
  return rows_of<MissedStop>(
      *impl_,
      "SELECT run_id, run_number, direction, target_index, nominal_mm FROM missed_stops "
      "WHERE run_id = ? ORDER BY run_number, direction, target_index",
      [](sqlite3_stmt* s, MissedStop& m) {
        read_all(s, m.run_id, m.run_number, m.direction, m.target_index, m.nominal_mm);
      },
      run_id);
}

void Store::add_operator_action(const OperatorAction& a) {
  impl_->need_writable("store an operator action");
  auto s = impl_->prepare(
      "INSERT INTO operator_actions(run_id, time_unix_ms, action, source, operator, run_number, "
      "direction, target_index, nominal_mm, detail) VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  bind_all(s.get(), a.run_id, a.time_unix_ms ? a.time_unix_ms : unix_ms_now(), a.action, a.source,
           a.operator_name);
  if (a.stop) {
    const auto& m = *a.stop;
    detail::bind_value(s.get(), 6, m.run_number);
    detail::bind_value(s.get(), 7, m.direction);
    detail::bind_value(s.get(), 8, m.target_index);
    detail::bind_value(s.get(), 9, m.nominal_mm);
  }
  bind_text(s.get(), 10, a.detail);
  impl_->step_done(s.get(), fmt::format("store a {} action of run {}", a.action, a.run_id));
}

std::vector<OperatorAction> Store::operator_actions(std::int64_t run_id) const {
  return rows_of<OperatorAction>(
      *impl_,
      "SELECT run_id, time_unix_ms, action, source, operator, run_number, direction, "
      "target_index, nominal_mm, detail FROM operator_actions WHERE run_id = ? ORDER BY id",
      [](sqlite3_stmt* s, OperatorAction& a) {
        std::optional<int> run_number;
        MissedStop m;
        read_all(s, a.run_id, a.time_unix_ms, a.action, a.source, a.operator_name, run_number,
                 m.direction, m.target_index, m.nominal_mm, a.detail);
        if (run_number) {  // an action on a stop
          m.run_id = a.run_id;
          m.run_number = *run_number;
          a.stop = m;
        }
      },
      run_id);
}

void Store::set_time_origin(std::int64_t run_id, std::int64_t session_ns, std::int64_t unix_ns) {
  impl_->need_writable("set the time origin");
  auto s = impl_->prepare("UPDATE runs SET origin_session_ns = ?, origin_unix_ns = ? WHERE id = ?");
  bind_all(s.get(), session_ns, unix_ns, run_id);
  impl_->step_done(s.get(), fmt::format("set the time origin of run {}", run_id));
}

void Store::in_transaction(const std::function<void()>& f) {
  Impl::Transaction tx(*impl_);
  f();
  tx.commit();
}

std::int64_t Store::import_run(const RunRecord& r) {
  impl_->need_writable("import run");
  if (!is_uuid(r.uuid))
    throw StoreError(fmt::format("{}: import run: '{}' is not a UUID (8-4-4-4-12 lower-case hex)",
                                 impl_->path.string(), r.uuid));
  auto s = impl_->prepare(
      "INSERT INTO runs(machine_id, campaign, kind, axis, settings_json, capture_path, "
      "software_version, started_unix_ms, ended_unix_ms, status, note, origin_session_ns, "
      "origin_unix_ns, uuid, owner_pid) VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  bind_all(s.get(), id_or_null(r.machine_id), r.campaign, r.kind, r.axis, r.settings_json,
           r.capture_path, r.software_version, r.started_unix_ms, r.ended_unix_ms,
           to_string(r.status), r.note, r.origin_session_ns, r.origin_unix_ns, r.uuid,
           kAcquiredElsewhere);
  impl_->step_done(s.get(), fmt::format("import run {}", r.uuid));
  return sqlite3_last_insert_rowid(impl_->db.get());
}

void Store::add_stored_chunks(std::int64_t run_id, std::span<const StoredChunk> chunks) {
  Impl& m = *impl_;
  Impl::Transaction tx(m);
  std::int64_t next = chunk_count(run_id);
  auto s = m.prepare(
      "INSERT INTO reading_chunks(run_id, device, channel, quantity, first_ns, last_ns, count, "
      "data, encoding, seq, crc) VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  for (const auto& c : chunks) {
    if (c.seq != next++)
      throw StoreError(
          fmt::format("{}: run {}: reading chunk {} does not follow the run's {} "
                      "chunks",
                      m.path.string(), run_id, c.seq, next - 1));
    bind_all(s.get(), run_id, c.device, c.channel, c.quantity, c.first_ns, c.last_ns, c.count,
             std::span<const unsigned char>(c.data), c.encoding, c.seq,
             std::int64_t{chunk::checksum(chunk::key_of(run_id, c.seq, c), c.data)});
    m.step_done(s.get(), fmt::format("store reading chunk {} of run {}", c.seq, run_id));
  }
  tx.commit();
}

Approval Store::approve(std::int64_t run_id, std::int64_t result_id, std::string_view approved_by) {
  Impl& m = *impl_;
  m.need_writable("approve a result");
  Impl::Transaction tx(m);
  const auto results = this->results(run_id);
  const auto it = std::find_if(results.begin(), results.end(),
                               [&](const ResultRecord& r) { return r.id == result_id; });
  if (it == results.end())
    throw StoreError(
        fmt::format("{}: run {} has no result {}", m.path.string(), run_id, result_id));
  if (it->superseded_by)
    throw StoreError(fmt::format(
        "{}: result {} of run {} is superseded by result {} (re-analysed or re-compensated "
        "since): it cannot be approved; approve the current one",
        m.path.string(), result_id, run_id, *it->superseded_by));
  for (const auto& a : approvals(run_id))
    if (a.result_id == result_id)
      throw StoreError(
          fmt::format("{}: result {} of run {} is approved already (by {}, unix ms {}{})",
                      m.path.string(), result_id, run_id, a.approved_by, a.approved_unix_ms,
                      a.central_server.empty() ? "" : ", on the central server"));
  const Approval a{.result_id = result_id,
                   .approved_by = std::string(approved_by),
                   .approved_unix_ms = unix_ms_now()};
  auto s =
      m.prepare("INSERT INTO approvals(result_id, approved_by, approved_unix_ms) VALUES(?, ?, ?)");
  bind_all(s.get(), a.result_id, a.approved_by, a.approved_unix_ms);
  m.step_done(s.get(), fmt::format("approve result {} of run {}", result_id, run_id));
  tx.commit();
  return a;
}

// The central server's approvals (brought by daq sync --from) first: of a result approved both
// there and here, the server's is the one a report names.
std::vector<Approval> Store::approvals(std::int64_t run_id) const {
  return rows_of<Approval>(
      *impl_,
      "SELECT c.result_id, c.result_fingerprint, c.run_version, c.approved_by, "
      "c.approved_unix_ms, c.server, 0 AS here, c.id FROM central_approvals AS c JOIN results AS "
      "r ON r.id = c.result_id WHERE r.run_id = ?1 UNION ALL SELECT a.result_id, '', 0, "
      "a.approved_by, a.approved_unix_ms, '', 1, a.id FROM approvals AS a JOIN results AS r ON "
      "r.id = a.result_id WHERE r.run_id = ?1 ORDER BY 7, 5, 8",
      [](sqlite3_stmt* s, Approval& a) {
        read_all(s, a.result_id, a.result_fingerprint, a.run_version, a.approved_by,
                 a.approved_unix_ms, a.central_server);
      },
      run_id);
}

bool Store::add_central_approval(const Approval& a) {
  impl_->need_writable("store an approval brought from the central store");
  auto s = impl_->prepare(
      "INSERT OR IGNORE INTO central_approvals(result_id, result_fingerprint, run_version, "
      "approved_by, approved_unix_ms, server) VALUES(?, ?, ?, ?, ?, ?)");
  bind_all(s.get(), a.result_id, a.result_fingerprint, a.run_version, a.approved_by,
           a.approved_unix_ms, a.central_server);
  impl_->step_done(s.get(), fmt::format("store the central approval of result {}", a.result_id));
  return sqlite3_changes(impl_->db.get()) > 0;
}

bool Store::replace_imported_operator_actions(std::int64_t run_id,
                                              std::span<const OperatorAction> actions) {
  Impl& m = *impl_;
  m.need_writable("refresh the operator's actions of a run brought from the central store");
  Impl::Transaction tx(m);
  {
    auto is = m.prepare("SELECT 1 FROM runs WHERE id = ? AND owner_pid = ?");
    bind_all(is.get(), run_id, kAcquiredElsewhere);
    if (sqlite3_step(is.get()) != SQLITE_ROW) return false;  // acquired here (or no such run)
  }
  auto del = m.prepare("DELETE FROM operator_actions WHERE run_id = ?");
  bind_all(del.get(), run_id);
  m.step_done(del.get(), fmt::format("replace the operator's actions of run {}", run_id));
  for (auto a : actions) {
    a.run_id = run_id;
    if (a.stop) a.stop->run_id = run_id;
    add_operator_action(a);
  }
  tx.commit();
  return true;
}

bool Store::update_imported_run(const RunRecord& r) {
  impl_->need_writable("update a run brought from the central store");
  auto s = impl_->prepare(
      "UPDATE runs SET status = ?, ended_unix_ms = ?, note = ? WHERE id = ? AND owner_pid = ?");
  bind_all(s.get(), to_string(r.status), r.ended_unix_ms, r.note, r.id, kAcquiredElsewhere);
  impl_->step_done(s.get(), fmt::format("update run {}", r.id));
  return sqlite3_changes(impl_->db.get()) > 0;
}

void Store::set_superseded(std::int64_t result_id, std::int64_t by_result_id) {
  impl_->need_writable("mark a result superseded");
  auto s = impl_->prepare(
      "UPDATE results SET superseded_by = ? WHERE id = ? AND run_id = (SELECT run_id FROM "
      "results WHERE id = ?)");
  bind_all(s.get(), by_result_id, result_id, by_result_id);
  impl_->step_done(s.get(), fmt::format("mark result {} superseded", result_id));
  if (sqlite3_changes(impl_->db.get()) == 0)
    throw StoreError(fmt::format("{}: no result {} of the run of result {}", impl_->path.string(),
                                 result_id, by_result_id));
}

namespace {

constexpr const char* kCalibrationColumns =
    "id, bar, nominal_mm, extensions, calibrator, calibrator_length_mm, reading_mm, "
    "zero_length_mm, temperature_degc, calibrated_unix_ms, note";

BarCalibration calibration_row(sqlite3_stmt* s) {
  BarCalibration c;
  read_all(s, c.id, c.bar, c.nominal_mm, c.extensions, c.calibrator, c.calibrator_length_mm,
           c.reading_mm, c.zero_length_mm, c.temperature_degc, c.calibrated_unix_ms, c.note);
  return c;
}

}  // namespace

std::int64_t Store::add_bar_calibration(const BarCalibration& c) {
  const auto bad = [](double v) { return !std::isfinite(v) || !(v > 0); };
  if (c.bar.empty() || bad(c.nominal_mm) || bad(c.calibrator_length_mm) || bad(c.zero_length_mm) ||
      !std::isfinite(c.reading_mm) || (c.temperature_degc && !std::isfinite(*c.temperature_degc)))
    throw StoreError(fmt::format(
        "{}: ballbar calibration of '{}': the bar must be named and the lengths finite and > 0 "
        "(nominal {} mm, calibrator {} mm, zero length {} mm, reading {} mm)",
        impl_->path.string(), c.bar, c.nominal_mm, c.calibrator_length_mm, c.zero_length_mm,
        c.reading_mm));
  auto s = impl_->prepare(
      "INSERT INTO ballbar_calibrations(bar, nominal_mm, extensions, calibrator, "
      "calibrator_length_mm, reading_mm, zero_length_mm, temperature_degc, calibrated_unix_ms, "
      "note) VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  bind_all(s.get(), c.bar, c.nominal_mm, c.extensions, c.calibrator, c.calibrator_length_mm,
           c.reading_mm, c.zero_length_mm, c.temperature_degc,
           c.calibrated_unix_ms ? c.calibrated_unix_ms : unix_ms_now(), c.note);
  impl_->step_done(s.get(), fmt::format("add a calibration of ballbar '{}'", c.bar));
  return sqlite3_last_insert_rowid(impl_->db.get());
}

std::vector<BarCalibration> Store::bar_calibrations(std::string_view bar) const {
  return rows_of<BarCalibration>(
      *impl_,
      fmt::format("SELECT {} FROM ballbar_calibrations WHERE ? = '' OR bar = ? ORDER BY "
                  "calibrated_unix_ms, id",
                  kCalibrationColumns),
      [](sqlite3_stmt* s, BarCalibration& c) { c = calibration_row(s); }, bar, bar);
}

std::optional<BarCalibration> Store::bar_calibration(std::string_view bar, double nominal_mm,
                                                     std::int64_t at_unix_ms) const {
  auto s = impl_->prepare(
      fmt::format("SELECT {} FROM ballbar_calibrations WHERE bar = ? AND abs(nominal_mm - ?) < "
                  "1e-3 AND calibrated_unix_ms <= ? ORDER BY calibrated_unix_ms DESC, id DESC "
                  "LIMIT 1",
                  kCalibrationColumns)
          .c_str());
  bind_text(s.get(), 1, bar);
  sqlite3_bind_double(s.get(), 2, nominal_mm);
  sqlite3_bind_int64(s.get(), 3, at_unix_ms);
  if (sqlite3_step(s.get()) != SQLITE_ROW) return std::nullopt;
  return calibration_row(s.get());
}

}  // namespace cal::storage
