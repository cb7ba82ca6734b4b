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

#include "store_impl.hpp"

namespace cal::storage {

std::string_view to_string(RunStatus s) {
  switch (s) {
    case RunStatus::running:
      return "running";
    case RunStatus::complete:
      return "complete";
    case RunStatus::incomplete:
      return "incomplete";
    case RunStatus::aborted:
      return "aborted";
  }
  return "unknown";
}

namespace {

using detail::Stmt;

RunStatus status_from(std::string_view s) {
  if (s == "complete") return RunStatus::complete;
  if (s == "incomplete") return RunStatus::incomplete;
  if (s == "aborted") return RunStatus::aborted;
  return RunStatus::running;
}

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
UPDATE runs SET uuid = lower(hex(randomblob(4)) || '-' || hex(randomblob(2)) || '-4' ||
  substr(hex(randomblob(2)), 2) || '-' || substr('89AB', 1 + (abs(random()) % 4), 1) ||
  substr(hex(randomblob(2)), 2) || '-' || hex(randomblob(6)));
CREATE UNIQUE INDEX runs_by_uuid ON runs(uuid);
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

void bind_text(sqlite3_stmt* s, int i, std::string_view v) {
  // An empty view may have a null data(), which SQLite would store as NULL, not ''.
  sqlite3_bind_text(s, i, v.empty() ? "" : v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
}
std::string column_text(sqlite3_stmt* s, int i) {
  const auto* p = sqlite3_column_text(s, i);
  return p ? reinterpret_cast<const char*>(p) : "";
}

bool process_alive(std::int64_t pid) {
  if (pid <= 0) return false;
  return ::kill(static_cast<pid_t>(pid), 0) == 0 || errno == EPERM;
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
  exec("PRAGMA journal_mode=WAL", "set WAL mode");
  exec(options.full_sync ? "PRAGMA synchronous=FULL" : "PRAGMA synchronous=NORMAL",
       "set synchronous");
  exec("PRAGMA foreign_keys=ON", "enable foreign keys");
  if (options.max_pages > 0)
    exec(fmt::format("PRAGMA max_page_count={}", options.max_pages).c_str(), "set max pages");
  for (int v = version; v < schema_version; ++v) {
    Transaction tx(*this);
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
      if (!process_alive(sqlite3_column_int64(s.get(), 1)))
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
  auto s = impl_->prepare("INSERT INTO machines(name, description, config_json) VALUES(?, ?, ?)");
  bind_text(s.get(), 1, r.name);
  bind_text(s.get(), 2, r.description);
  bind_text(s.get(), 3, r.config_json);
  impl_->step_done(s.get(), fmt::format("add machine '{}'", r.name));
  return sqlite3_last_insert_rowid(impl_->db.get());
}

std::optional<MachineRecord> Store::machine_by_name(std::string_view name) const {
  auto s = impl_->prepare("SELECT id, name, description, config_json FROM machines WHERE name = ?");
  bind_text(s.get(), 1, name);
  if (sqlite3_step(s.get()) != SQLITE_ROW) return std::nullopt;
  return MachineRecord{sqlite3_column_int64(s.get(), 0), column_text(s.get(), 1),
                       column_text(s.get(), 2), column_text(s.get(), 3)};
}

std::optional<MachineRecord> Store::machine(std::int64_t id) const {
  auto s = impl_->prepare("SELECT id, name, description, config_json FROM machines WHERE id = ?");
  sqlite3_bind_int64(s.get(), 1, id);
  if (sqlite3_step(s.get()) != SQLITE_ROW) return std::nullopt;
  return MachineRecord{sqlite3_column_int64(s.get(), 0), column_text(s.get(), 1),
                       column_text(s.get(), 2), column_text(s.get(), 3)};
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
  if (r.machine_id > 0) sqlite3_bind_int64(s.get(), 1, r.machine_id);
  bind_text(s.get(), 2, r.campaign);
  bind_text(s.get(), 3, r.kind);
  bind_text(s.get(), 4, r.axis);
  bind_text(s.get(), 5, r.settings_json);
  bind_text(s.get(), 6, r.capture_path);
  bind_text(s.get(), 7, r.software_version);
  sqlite3_bind_int64(s.get(), 8, r.started_unix_ms ? r.started_unix_ms : unix_ms_now());
  bind_text(s.get(), 9, r.note);
  sqlite3_bind_int64(s.get(), 10, ::getpid());
  bind_text(s.get(), 11, r.uuid.empty() ? new_uuid() : r.uuid);
  impl_->step_done(s.get(), "begin run");
  return sqlite3_last_insert_rowid(impl_->db.get());
}

void Store::add_instrument(const InstrumentRecord& i) {
  impl_->need_writable("add instrument");
  auto s = impl_->prepare(
      "INSERT INTO instruments(run_id, device, driver, transport, settings_json, origin, "
      "origin_detail) VALUES(?, ?, ?, ?, ?, ?, ?)");
  sqlite3_bind_int64(s.get(), 1, i.run_id);
  sqlite3_bind_int(s.get(), 2, i.device);
  bind_text(s.get(), 3, i.driver);
  bind_text(s.get(), 4, i.transport);
  bind_text(s.get(), 5, i.settings_json);
  bind_text(s.get(), 6, i.origin);
  bind_text(s.get(), 7, i.origin_detail);
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
  r.id = sqlite3_column_int64(s, 0);
  r.machine_id = sqlite3_column_int64(s, 1);
  r.campaign = column_text(s, 2);
  r.kind = column_text(s, 3);
  r.axis = column_text(s, 4);
  r.settings_json = column_text(s, 5);
  r.capture_path = column_text(s, 6);
  r.software_version = column_text(s, 7);
  r.started_unix_ms = sqlite3_column_int64(s, 8);
  if (sqlite3_column_type(s, 9) != SQLITE_NULL) r.ended_unix_ms = sqlite3_column_int64(s, 9);
  r.status = status_from(column_text(s, 10));
  r.note = column_text(s, 11);
  if (read_only && r.status == RunStatus::running && !process_alive(sqlite3_column_int64(s, 12))) {
    r.status = RunStatus::incomplete;
    r.note = fmt::format("{} (not yet marked so in the database, which was opened read-only)",
                         kInterrupted);
  }
  if (sqlite3_column_type(s, 13) != SQLITE_NULL) r.origin_session_ns = sqlite3_column_int64(s, 13);
  if (sqlite3_column_type(s, 14) != SQLITE_NULL) r.origin_unix_ns = sqlite3_column_int64(s, 14);
  r.uuid = column_text(s, 15);
  return r;
}
}  // namespace

std::vector<RunRecord> Store::runs() const {
  auto s = impl_->prepare((std::string(kRunColumns) + " ORDER BY id").c_str());
  std::vector<RunRecord> out;
  while (sqlite3_step(s.get()) == SQLITE_ROW) out.push_back(read_run(s.get(), impl_->read_only));
  return out;
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
  auto s = impl_->prepare(
      "SELECT run_id, device, driver, transport, settings_json, origin, origin_detail FROM "
      "instruments WHERE run_id = ? ORDER BY device");
  sqlite3_bind_int64(s.get(), 1, run_id);
  std::vector<InstrumentRecord> out;
  while (sqlite3_step(s.get()) == SQLITE_ROW)
    out.push_back({sqlite3_column_int64(s.get(), 0), sqlite3_column_int(s.get(), 1),
                   column_text(s.get(), 2), column_text(s.get(), 3), column_text(s.get(), 4),
                   column_text(s.get(), 5), column_text(s.get(), 6)});
  return out;
}

std::int64_t Store::add_compensation(const CompensationRecord& c) {
  impl_->need_writable("add compensation");
  auto s = impl_->prepare(
      "INSERT INTO compensations(machine_id, source_run_id, source, axis, format, "
      "created_unix_ms, json) VALUES(?, ?, ?, ?, ?, ?, ?)");
  if (c.machine_id > 0) sqlite3_bind_int64(s.get(), 1, c.machine_id);
  if (c.source_run_id > 0) sqlite3_bind_int64(s.get(), 2, c.source_run_id);
  bind_text(s.get(), 3, c.source);
  bind_text(s.get(), 4, c.axis);
  bind_text(s.get(), 5, c.format);
  sqlite3_bind_int64(s.get(), 6, c.created_unix_ms ? c.created_unix_ms : unix_ms_now());
  bind_text(s.get(), 7, c.json);
  impl_->step_done(s.get(), fmt::format("add the compensation of axis {} ({})", c.axis, c.format));
  return sqlite3_last_insert_rowid(impl_->db.get());
}

std::vector<CompensationRecord> Store::compensations(std::int64_t machine_id,
                                                     std::string_view axis) const {
  auto s = impl_->prepare(
      "SELECT id, IFNULL(machine_id, 0), IFNULL(source_run_id, 0), source, axis, format, "
      "created_unix_ms, json FROM compensations WHERE (? = 0 OR machine_id = ?) AND (? = '' OR "
      "axis = ?) ORDER BY created_unix_ms, id");
  sqlite3_bind_int64(s.get(), 1, machine_id);
  sqlite3_bind_int64(s.get(), 2, machine_id);
  bind_text(s.get(), 3, axis);
  bind_text(s.get(), 4, axis);
  std::vector<CompensationRecord> out;
  while (sqlite3_step(s.get()) == SQLITE_ROW)
    out.push_back({.id = sqlite3_column_int64(s.get(), 0),
                   .machine_id = sqlite3_column_int64(s.get(), 1),
                   .source_run_id = sqlite3_column_int64(s.get(), 2),
                   .source = column_text(s.get(), 3),
                   .axis = column_text(s.get(), 4),
                   .format = column_text(s.get(), 5),
                   .created_unix_ms = sqlite3_column_int64(s.get(), 6),
                   .json = column_text(s.get(), 7)});
  return out;
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
    sqlite3_bind_int64(s, 1, run_id);
    sqlite3_bind_int64(s, 2, key.device);
    sqlite3_bind_int64(s, 3, key.channel);
    sqlite3_bind_int64(s, 4, key.quantity);
    sqlite3_bind_int64(s, 5, key.first_ns);
    sqlite3_bind_int64(s, 6, key.last_ns);
    sqlite3_bind_int64(s, 7, key.count);
    sqlite3_bind_blob64(s, 8, c.blob.data(), c.blob.size(), SQLITE_STATIC);
    sqlite3_bind_int64(s, 9, key.encoding);
    sqlite3_bind_int64(s, 10, key.seq);
    sqlite3_bind_int64(s, 11, chunk::checksum(key, c.blob));
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
    c.device = sqlite3_column_int64(s.get(), 0);
    c.channel = sqlite3_column_int64(s.get(), 1);
    c.quantity = sqlite3_column_int64(s.get(), 2);
    c.first_ns = sqlite3_column_int64(s.get(), 3);
    c.last_ns = sqlite3_column_int64(s.get(), 4);
    c.count = sqlite3_column_int64(s.get(), 5);
    const auto* data = static_cast<const unsigned char*>(sqlite3_column_blob(s.get(), 6));
    c.data.assign(data, data + sqlite3_column_bytes(s.get(), 6));
    c.encoding = sqlite3_column_int64(s.get(), 7);
    c.stored_checksum = sqlite3_column_type(s.get(), 9) != SQLITE_NULL;
    c.seq = c.stored_checksum ? sqlite3_column_int64(s.get(), 8) : place;
    const chunk::Key key{.run_id = run_id,
                         .seq = c.seq,
                         .device = c.device,
                         .channel = c.channel,
                         .quantity = c.quantity,
                         .first_ns = c.first_ns,
                         .last_ns = c.last_ns,
                         .count = c.count,
                         .encoding = c.encoding};
    c.crc = chunk::checksum(key, c.data);
    const char* damage = nullptr;
    if (c.stored_checksum && static_cast<std::uint32_t>(sqlite3_column_int64(s.get(), 9)) != c.crc)
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

void Store::Impl::insert_targets(std::span<const CapturedTarget> targets) {
  Impl& m = *this;
  auto s = m.prepare(
      "INSERT INTO captured_targets(run_id, target_index, run_number, direction, nominal_mm, "
      "time_ns, raw_m, deviation_um, refractive_index, material_temperature_degc) "
      "VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  for (const auto& t : targets) {
    sqlite3_bind_int64(s.get(), 1, t.run_id);
    sqlite3_bind_int(s.get(), 2, t.target_index);
    sqlite3_bind_int(s.get(), 3, t.run_number);
    bind_text(s.get(), 4, std::string_view(&t.direction, 1));
    sqlite3_bind_double(s.get(), 5, t.nominal_mm);
    sqlite3_bind_int64(s.get(), 6, t.time_ns);
    sqlite3_bind_double(s.get(), 7, t.raw_m);
    sqlite3_bind_double(s.get(), 8, t.deviation_um);
    sqlite3_bind_double(s.get(), 9, t.refractive_index);
    sqlite3_bind_double(s.get(), 10, t.material_temperature_degc);
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
  auto s = impl_->prepare(
      "SELECT run_id, target_index, run_number, direction, nominal_mm, time_ns, raw_m, "
      "deviation_um, refractive_index, material_temperature_degc FROM captured_targets "
      "WHERE run_id = ? ORDER BY time_ns, run_number, target_index");
  sqlite3_bind_int64(s.get(), 1, run_id);
  std::vector<CapturedTarget> out;
  while (sqlite3_step(s.get()) == SQLITE_ROW) {
    CapturedTarget t;
    t.run_id = sqlite3_column_int64(s.get(), 0);
    t.target_index = sqlite3_column_int(s.get(), 1);
    t.run_number = sqlite3_column_int(s.get(), 2);
    t.direction = column_text(s.get(), 3).front();
    t.nominal_mm = sqlite3_column_double(s.get(), 4);
    t.time_ns = sqlite3_column_int64(s.get(), 5);
    t.raw_m = sqlite3_column_double(s.get(), 6);
    t.deviation_um = sqlite3_column_double(s.get(), 7);
    t.refractive_index = sqlite3_column_double(s.get(), 8);
    t.material_temperature_degc = sqlite3_column_double(s.get(), 9);
    out.push_back(t);
  }
  return out;
}

std::int64_t Store::Impl::insert_result(const ResultRecord& r, Supersede how) {
  auto s = prepare(
      "INSERT INTO results(run_id, standard, json, created_unix_ms, provenance_json) "
      "VALUES(?, ?, ?, ?, ?)");
  sqlite3_bind_int64(s.get(), 1, r.run_id);
  bind_text(s.get(), 2, r.standard);
  bind_text(s.get(), 3, r.json);
  sqlite3_bind_int64(s.get(), 4, r.created_unix_ms ? r.created_unix_ms : unix_ms_now());
  bind_text(s.get(), 5, r.provenance_json.empty() ? std::string_view("{}") : r.provenance_json);
  step_done(s.get(), fmt::format("store result of run {}", r.run_id));
  const std::int64_t id = sqlite3_last_insert_rowid(db.get());
  if (how == Supersede::none) return id;
  auto u = prepare(how == Supersede::all
                       ? "UPDATE results SET superseded_by = ? WHERE run_id = ? AND id <> ? AND "
                         "superseded_by IS NULL"
                       : "UPDATE results SET superseded_by = ? WHERE run_id = ? AND id <> ? AND "
                         "superseded_by IS NULL AND standard = ?");
  sqlite3_bind_int64(u.get(), 1, id);
  sqlite3_bind_int64(u.get(), 2, r.run_id);
  sqlite3_bind_int64(u.get(), 3, id);
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
  auto s = impl_->prepare(
      "SELECT run_id, standard, json, created_unix_ms, provenance_json, id, superseded_by "
      "FROM results WHERE run_id = ? ORDER BY id");
  sqlite3_bind_int64(s.get(), 1, run_id);
  std::vector<ResultRecord> out;
  while (sqlite3_step(s.get()) == SQLITE_ROW) {
    ResultRecord r{.run_id = sqlite3_column_int64(s.get(), 0),
                   .standard = column_text(s.get(), 1),
                   .json = column_text(s.get(), 2),
                   .created_unix_ms = sqlite3_column_int64(s.get(), 3),
                   .provenance_json = column_text(s.get(), 4),
                   .id = sqlite3_column_int64(s.get(), 5)};
    if (sqlite3_column_type(s.get(), 6) != SQLITE_NULL)
      r.superseded_by = sqlite3_column_int64(s.get(), 6);
    out.push_back(std::move(r));
  }
  return out;
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
    sqlite3_bind_int64(s.get(), 1, run_id);
    sqlite3_bind_int(s.get(), 2, m.run_number);
    bind_text(s.get(), 3, std::string_view(&m.direction, 1));
    sqlite3_bind_int(s.get(), 4, m.target_index);
    sqlite3_bind_double(s.get(), 5, m.nominal_mm);
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
  bind_text(r.get(), 1, q.state);
  bind_text(r.get(), 2, q.summary);
  sqlite3_bind_int64(r.get(), 3, run_id);
  impl_->step_done(r.get(), fmt::format("store the quality of run {}", run_id));
  auto clear = impl_->prepare("UPDATE captured_targets SET suspect = NULL WHERE run_id = ?");
  sqlite3_bind_int64(clear.get(), 1, run_id);
  impl_->step_done(clear.get(), fmt::format("clear the suspect stops of run {}", run_id));
  auto mark = impl_->prepare(
      "UPDATE captured_targets SET suspect = ? WHERE run_id = ? AND run_number = ? AND "
      "direction = ? AND target_index = ?");
  for (const auto& m : q.suspects) {
    bind_text(mark.get(), 1, m.reason);
    sqlite3_bind_int64(mark.get(), 2, run_id);
    sqlite3_bind_int(mark.get(), 3, m.run_number);
    bind_text(mark.get(), 4, std::string_view(&m.direction, 1));
    sqlite3_bind_int(mark.get(), 5, m.target_index);
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
  RunQuality q{.state = column_text(r.get(), 0), .summary = column_text(r.get(), 1)};
  auto s = impl_->prepare(
      "SELECT run_number, direction, target_index, suspect FROM captured_targets "
      "WHERE run_id = ? AND suspect IS NOT NULL ORDER BY time_ns, run_number, target_index");
  sqlite3_bind_int64(s.get(), 1, run_id);
  while (sqlite3_step(s.get()) == SQLITE_ROW)
    q.suspects.push_back({.run_number = sqlite3_column_int(s.get(), 0),
                          .direction = column_text(s.get(), 1).front(),
                          .target_index = sqlite3_column_int(s.get(), 2),
                          .reason = column_text(s.get(), 3)});
  return q;
}

std::vector<MissedStop> Store::missed_stops(std::int64_t run_id) const {
  auto s = impl_->prepare(
      "SELECT run_id, run_number, direction, target_index, nominal_mm FROM missed_stops "
      "WHERE run_id = ? ORDER BY run_number, direction, target_index");
  sqlite3_bind_int64(s.get(), 1, run_id);
  std::vector<MissedStop> out;
  while (sqlite3_step(s.get()) == SQLITE_ROW)
    out.push_back({.run_id = sqlite3_column_int64(s.get(), 0),
                   .run_number = sqlite3_column_int(s.get(), 1),
                   .direction = column_text(s.get(), 2).front(),
                   .target_index = sqlite3_column_int(s.get(), 3),
                   .nominal_mm = sqlite3_column_double(s.get(), 4)});
  return out;
}

void Store::add_operator_action(const OperatorAction& a) {
  impl_->need_writable("store an operator action");
  auto s = impl_->prepare(
      "INSERT INTO operator_actions(run_id, time_unix_ms, action, source, operator, run_number, "
      "direction, target_index, nominal_mm, detail) VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
  sqlite3_bind_int64(s.get(), 1, a.run_id);
  sqlite3_bind_int64(s.get(), 2, a.time_unix_ms ? a.time_unix_ms : unix_ms_now());
  bind_text(s.get(), 3, a.action);
  bind_text(s.get(), 4, a.source);
  bind_text(s.get(), 5, a.operator_name);
  if (a.stop) {
    sqlite3_bind_int(s.get(), 6, a.stop->run_number);
    bind_text(s.get(), 7, std::string_view(&a.stop->direction, 1));
    sqlite3_bind_int(s.get(), 8, a.stop->target_index);
    sqlite3_bind_double(s.get(), 9, a.stop->nominal_mm);
  }
  bind_text(s.get(), 10, a.detail);
  impl_->step_done(s.get(), fmt::format("store a {} action of run {}", a.action, a.run_id));
}

std::vector<OperatorAction> Store::operator_actions(std::int64_t run_id) const {
  auto s = impl_->prepare(
      "SELECT run_id, time_unix_ms, action, source, operator, run_number, direction, "
      "target_index, nominal_mm, detail FROM operator_actions WHERE run_id = ? ORDER BY id");
  sqlite3_bind_int64(s.get(), 1, run_id);
  std::vector<OperatorAction> out;
  while (sqlite3_step(s.get()) == SQLITE_ROW) {
    OperatorAction a{.run_id = sqlite3_column_int64(s.get(), 0),
                     .time_unix_ms = sqlite3_column_int64(s.get(), 1),
                     .action = column_text(s.get(), 2),
                     .source = column_text(s.get(), 3),
                     .operator_name = column_text(s.get(), 4),
                     .detail = column_text(s.get(), 9)};
    if (sqlite3_column_type(s.get(), 5) != SQLITE_NULL) {
      const auto dir = column_text(s.get(), 6);
      a.stop = MissedStop{.run_id = a.run_id,
                          .run_number = sqlite3_column_int(s.get(), 5),
                          .direction = dir.empty() ? '+' : dir.front(),
                          .target_index = sqlite3_column_int(s.get(), 7),
                          .nominal_mm = sqlite3_column_double(s.get(), 8)};
    }
    out.push_back(std::move(a));
  }
  return out;
}

void Store::set_time_origin(std::int64_t run_id, std::int64_t session_ns, std::int64_t unix_ns) {
  impl_->need_writable("set the time origin");
  auto s = impl_->prepare("UPDATE runs SET origin_session_ns = ?, origin_unix_ns = ? WHERE id = ?");
  sqlite3_bind_int64(s.get(), 1, session_ns);
  sqlite3_bind_int64(s.get(), 2, unix_ns);
  sqlite3_bind_int64(s.get(), 3, run_id);
  impl_->step_done(s.get(), fmt::format("set the time origin of run {}", run_id));
}

namespace {

constexpr const char* kCalibrationColumns =
    "id, bar, nominal_mm, extensions, calibrator, calibrator_length_mm, reading_mm, "
    "zero_length_mm, temperature_degc, calibrated_unix_ms, note";

BarCalibration calibration_row(sqlite3_stmt* s) {
  BarCalibration c{.id = sqlite3_column_int64(s, 0),
                   .bar = column_text(s, 1),
                   .nominal_mm = sqlite3_column_double(s, 2),
                   .extensions = column_text(s, 3),
                   .calibrator = column_text(s, 4),
                   .calibrator_length_mm = sqlite3_column_double(s, 5),
                   .reading_mm = sqlite3_column_double(s, 6),
                   .zero_length_mm = sqlite3_column_double(s, 7),
                   .calibrated_unix_ms = sqlite3_column_int64(s, 9),
                   .note = column_text(s, 10)};
  if (sqlite3_column_type(s, 8) != SQLITE_NULL) c.temperature_degc = sqlite3_column_double(s, 8);
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
  bind_text(s.get(), 1, c.bar);
  sqlite3_bind_double(s.get(), 2, c.nominal_mm);
  bind_text(s.get(), 3, c.extensions);
  bind_text(s.get(), 4, c.calibrator);
  sqlite3_bind_double(s.get(), 5, c.calibrator_length_mm);
  sqlite3_bind_double(s.get(), 6, c.reading_mm);
  sqlite3_bind_double(s.get(), 7, c.zero_length_mm);
  if (c.temperature_degc) sqlite3_bind_double(s.get(), 8, *c.temperature_degc);
  sqlite3_bind_int64(s.get(), 9, c.calibrated_unix_ms ? c.calibrated_unix_ms : unix_ms_now());
  bind_text(s.get(), 10, c.note);
  impl_->step_done(s.get(), fmt::format("add a calibration of ballbar '{}'", c.bar));
  return sqlite3_last_insert_rowid(impl_->db.get());
}

std::vector<BarCalibration> Store::bar_calibrations(std::string_view bar) const {
  auto s = impl_->prepare(fmt::format("SELECT {} FROM ballbar_calibrations WHERE ? = '' OR bar = ? "
                                      "ORDER BY calibrated_unix_ms, id",
                                      kCalibrationColumns)
                              .c_str());
  bind_text(s.get(), 1, bar);
  bind_text(s.get(), 2, bar);
  std::vector<BarCalibration> out;
  while (sqlite3_step(s.get()) == SQLITE_ROW) out.push_back(calibration_row(s.get()));
  return out;
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
