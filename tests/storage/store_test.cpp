// The run store: round trips are bit-exact, a crashed writer (a real child process killed
// with SIGKILL) leaves a readable database with every committed batch and the run marked
// incomplete, and bad files and a full disk give errors that name the file.
#include "cal/storage/store.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sqlite3.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <vector>

#include "../support/temp_dir.hpp"
#include "cal/storage/chunk.hpp"

namespace {

namespace fs = std::filesystem;
using cal::storage::RawReading;
using cal::storage::RunStatus;
using cal::storage::Store;
using cal::storage::StoreError;

struct TempDir : cal::test::TempDir {
  TempDir() : cal::test::TempDir("caldaq-store") {}
};

std::vector<RawReading> make_readings(std::size_t n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<RawReading> v(n);
  for (std::size_t i = 0; i < n; ++i)
    v[i] = {.time_ns = static_cast<std::int64_t>(i) * 100'000,
            .device = static_cast<std::uint16_t>(i % 3),
            .channel = static_cast<std::uint8_t>(i % 2),
            .quantity = static_cast<std::uint8_t>(i % 3 == 2 ? 2 : 0),
            .status = static_cast<std::uint8_t>(i % 17 == 0),
            .value = u(rng) * 1e-3};
  return v;
}

TEST(Store, CreatesTheSchemaAndReopensIt) {
  TempDir dir;
  const auto file = dir.path / "site.sqlite";
  { EXPECT_EQ(Store(file).version(), cal::storage::schema_version); }
  Store again(file);
  EXPECT_EQ(again.version(), cal::storage::schema_version);
  EXPECT_TRUE(again.runs().empty());
}

TEST(Store, SimultaneousReadingsComeBackInOneOrderWhateverTheBatches) {
  // Two devices read at the same instant (an air sample and a material temperature stamped
  // with the same capture time). Written in opposite orders and split at different batch
  // boundaries -- as a live run and its replay may be -- they read back in the same order:
  // by time, then device, channel, quantity.
  TempDir dir;
  Store store(dir.path / "site.sqlite");
  const auto machine = store.add_machine({.name = "VMC-1"});
  const RawReading air{.time_ns = 500, .device = 2, .quantity = 3, .value = 100678.0};
  const RawReading material{.time_ns = 500, .device = 1, .quantity = 5, .value = 20.66};
  const RawReading later{.time_ns = 600, .device = 0, .quantity = 0, .value = 1e-3};
  const auto a = store.begin_run({.machine_id = machine, .kind = "linear", .axis = "X"});
  store.append_readings(a, std::vector{air});
  store.append_readings(a, std::vector{material, later});
  const auto b = store.begin_run({.machine_id = machine, .kind = "linear", .axis = "X"});
  store.append_readings(b, std::vector{material, air, later});
  for (const auto run : {a, b}) {
    const auto back = store.readings(run);
    ASSERT_EQ(back.size(), 3u);
    EXPECT_EQ(back[0].value, 20.66) << "run " << run;  // device 1 before device 2
    EXPECT_EQ(back[1].value, 100678.0) << "run " << run;
    EXPECT_EQ(back[2].value, 1e-3) << "run " << run;
  }
}

TEST(Store, RunLifeCycleAndBitExactReadings) {
  TempDir dir;
  Store store(dir.path / "site.sqlite");
  const auto machine = store.add_machine({.name = "VMC-1", .description = "3-axis mill"});
  EXPECT_EQ(store.machine_by_name("VMC-1")->id, machine);
  EXPECT_EQ(store.machine(machine)->description, "3-axis mill");
  EXPECT_FALSE(store.machine(machine + 1));
  EXPECT_FALSE(store.machine_by_name("nope"));
  const auto run = store.begin_run({.machine_id = machine,
                                    .kind = "linear",
                                    .axis = "X",
                                    .settings_json = R"({"targets": 11})"});
  store.add_instrument(
      {.run_id = run, .device = 1, .driver = "ids3010", .transport = "tcp 127.0.0.1:9090"});
  const auto readings = make_readings(10'000, 7);
  // Two batches, split unevenly, must come back as one time-ordered stream.
  store.append_readings(run, std::span(readings).first(3333));
  store.append_readings(run, std::span(readings).subspan(3333));
  EXPECT_EQ(store.reading_count(run), 10'000);
  const auto back = store.readings(run);
  ASSERT_EQ(back.size(), readings.size());
  for (std::size_t i = 0; i < back.size(); ++i) {
    EXPECT_EQ(back[i].time_ns, readings[i].time_ns);
    EXPECT_EQ(back[i].device, readings[i].device);
    EXPECT_EQ(back[i].channel, readings[i].channel);
    EXPECT_EQ(back[i].quantity, readings[i].quantity);
    EXPECT_EQ(back[i].status, readings[i].status);
    EXPECT_EQ(std::memcmp(&back[i].value, &readings[i].value, 8), 0) << i;  // bit-exact
  }
  // Quantity 2 only: every third reading (i % 3 == 2), still in time order.
  const std::uint8_t q2[] = {2};
  const auto only2 = store.readings(run, q2);
  ASSERT_EQ(only2.size(), 3333u);
  for (std::size_t i = 0; i < only2.size(); ++i) {
    EXPECT_EQ(only2[i].time_ns, readings[3 * i + 2].time_ns);
    EXPECT_EQ(only2[i].quantity, 2);
  }
  EXPECT_EQ(store.run(run)->status, RunStatus::running);
  store.add_targets(std::vector<cal::storage::CapturedTarget>{{.run_id = run,
                                                               .target_index = 0,
                                                               .run_number = 1,
                                                               .direction = '+',
                                                               .nominal_mm = 0.0,
                                                               .deviation_um = 1.5},
                                                              {.run_id = run,
                                                               .target_index = 1,
                                                               .run_number = 1,
                                                               .direction = '+',
                                                               .nominal_mm = 50.0,
                                                               .time_ns = 10,
                                                               .deviation_um = -2.25}});
  store.add_result({.run_id = run, .standard = "ISO 230-2:2014", .json = "{}"});
  store.finish_run(run, RunStatus::complete);
  const auto r = store.run(run);
  EXPECT_EQ(r->status, RunStatus::complete);
  EXPECT_TRUE(r->ended_unix_ms.has_value());
  EXPECT_EQ(r->settings_json, R"({"targets": 11})");
  EXPECT_EQ(store.instruments(run).at(0).driver, "ids3010");
  EXPECT_EQ(store.targets(run).at(1).deviation_um, -2.25);
  EXPECT_EQ(store.results(run).at(0).standard, "ISO 230-2:2014");
  EXPECT_THROW(store.finish_run(run + 100, RunStatus::complete), StoreError);
}

// Commands opening a new store at the same moment (the demo writing it while a test or `daq
// runs` peeks at it): every one opens it. Each waits on the others' write lock and reads the
// schema version again under it; before, the second to get the lock ran migration 0 -> 1 on the
// migrated file and failed with "table machines already exists". Four processes released
// together on each of 12 new files.
TEST(Store, CommandsOpeningANewStoreAtOnceAllOpenIt) {
  TempDir dir;
  for (int round = 0; round < 12; ++round) {
    const auto file = dir.path / fmt::format("new-{}.sqlite", round);
    int go[2];
    ASSERT_EQ(::pipe(go), 0);
    std::vector<pid_t> children;
    for (int k = 0; k < 4; ++k) {
      const pid_t child = ::fork();
      ASSERT_GE(child, 0);
      if (child == 0) {
        ::close(go[1]);
        char c = 0;
        if (::read(go[0], &c, 1) != 0) ::_exit(3);  // released when the parent closes its end
        try {
          Store store(file);
          (void)store.runs();
          ::_exit(0);
        } catch (const StoreError& e) {
          std::fprintf(stderr, "round %d, process %d: %s\n", round, k, e.what());
          ::_exit(1);
        }
      }
      children.push_back(child);
    }
    ::close(go[0]);
    ::close(go[1]);
    for (const pid_t child : children) {
      int status = 0;
      ::waitpid(child, &status, 0);
      EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "round " << round;
    }
    Store after(file);
    EXPECT_TRUE(after.runs().empty());
  }
}

// The child writes batches of 1000 readings and tells the parent after each commit; the
// parent kills it with SIGKILL mid-stream. Every reported batch must be there, and the count
// a whole number of batches (a transaction is all or nothing).
TEST(Store, KillDashNineLeavesEveryCommittedBatchAndAnIncompleteRun) {
  TempDir dir;
  const auto file = dir.path / "site.sqlite";
  { Store create(file); }
  int pipe_fd[2];
  ASSERT_EQ(::pipe(pipe_fd), 0);
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    ::close(pipe_fd[0]);
    Store store(file);
    const auto run = store.begin_run({.kind = "linear", .axis = "X"});
    const auto batch = make_readings(1000, 1);
    for (int i = 0;; ++i) {
      store.append_readings(run, batch);
      const char one = 1;
      if (::write(pipe_fd[1], &one, 1) != 1) ::_exit(3);
    }
  }
  ::close(pipe_fd[1]);
  int committed = 0;
  char c = 0;
  while (committed < 25 && ::read(pipe_fd[0], &c, 1) == 1) ++committed;
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));
  // Batches committed after the 25th report may also be there, but never part of one.
  while (::read(pipe_fd[0], &c, 1) == 1) ++committed;
  ::close(pipe_fd[0]);

  Store store(file);
  const auto runs = store.runs();
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].status, RunStatus::incomplete);
  EXPECT_NE(runs[0].note.find("interrupted"), std::string::npos);
  const auto n = store.reading_count(runs[0].id);
  EXPECT_GE(n, 1000 * committed);
  EXPECT_LE(n, 1000 * (committed + 1));
  EXPECT_EQ(n % 1000, 0);
  EXPECT_EQ(static_cast<std::int64_t>(store.readings(runs[0].id).size()), n);
}

TEST(Store, AFullDiskFailsTheBatchAndKeepsWhatWasStored) {
  TempDir dir;
  Store store(dir.path / "small.sqlite", {.max_pages = 64});  // 64 x 4 KiB
  const auto run = store.begin_run({.kind = "linear"});
  const auto batch = make_readings(1000, 3);  // 17 kB per batch
  int stored = 0;
  try {
    for (; stored < 100; ++stored) store.append_readings(run, batch);
    FAIL() << "the cap was never reached";
  } catch (const StoreError& e) {
    EXPECT_NE(std::string(e.what()).find("small.sqlite"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("full"), std::string::npos) << e.what();
  }
  EXPECT_GT(stored, 0);
  EXPECT_EQ(store.reading_count(run), 1000 * stored);
}

TEST(Store, RefusesAFileThatIsNotADatabase) {
  TempDir dir;
  const auto file = dir.path / "notes.txt";
  std::ofstream(file) << "this is a text file, not a database, and long enough to have a header";
  try {
    Store store(file);
    FAIL() << "opened";
  } catch (const StoreError& e) {
    EXPECT_NE(std::string(e.what()).find("notes.txt"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not a"), std::string::npos) << e.what();
  }
}

// Runs `sql` on the file through SQLite itself, as an older version's code would have left it
// (to take a database back to an older schema); SQLite's error, or "" when it ran.
std::string exec_sql(const fs::path& file, const std::string& sql) {
  sqlite3* db = nullptr;
  std::string error;
  if (sqlite3_open(file.c_str(), &db) != SQLITE_OK) {
    error = "cannot open " + file.string();
  } else {
    char* message = nullptr;
    if (sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &message) != SQLITE_OK)
      error = message ? message : "failed";
    sqlite3_free(message);
  }
  sqlite3_close(db);
  return error;
}

TEST(Store, RefusesANewerSchema) {
  TempDir dir;
  const auto file = dir.path / "future.sqlite";
  ASSERT_EQ(exec_sql(file, "PRAGMA user_version=99"), "");
  try {
    Store store(file);
    FAIL() << "opened";
  } catch (const StoreError& e) {
    EXPECT_NE(std::string(e.what()).find("schema version 99 is newer"), std::string::npos)
        << e.what();
  }
}

TEST(Store, NamesAPathThatCannotBeCreated) {
  try {
    Store store("/nonexistent-dir/caldaq/site.sqlite");
    FAIL() << "opened";
  } catch (const StoreError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/caldaq/site.sqlite"), std::string::npos)
        << e.what();
  }
}

}  // namespace

namespace {
std::int64_t a_run(Store& store) {
  return store.begin_run({.campaign = "c", .kind = "linear", .axis = "X"});
}

// A new database file with one run in it; the run's id.
std::int64_t a_run_in(const fs::path& file) {
  Store store(file);
  return a_run(store);
}

}  // namespace

TEST(Store, ANewResultSupersedesTheSameStandardOnlyAndKeepsTheOldOne) {
  TempDir dir;
  Store store(dir.path / "site.sqlite");
  const auto run = a_run(store);
  const auto first = store.add_result({.run_id = run, .standard = "ISO 230-2:2014", .json = "{}"});
  const auto vdi = store.add_result({.run_id = run, .standard = "VDI/DGQ 3441", .json = "{}"});
  const auto second = store.add_result({.run_id = run,
                                        .standard = "ISO 230-2:2014",
                                        .json = "{}",
                                        .provenance_json = R"({"how":"reanalysed"})"});
  const auto rs = store.results(run);
  ASSERT_EQ(rs.size(), 3u);
  EXPECT_EQ(rs[0].id, first);
  EXPECT_EQ(rs[0].superseded_by, second);  // the same standard, later
  EXPECT_TRUE(rs[1].current());            // another standard stays current
  EXPECT_TRUE(rs[2].current());
  EXPECT_EQ(rs[1].id, vdi);
  EXPECT_EQ(rs[2].provenance_json, R"({"how":"reanalysed"})");
  EXPECT_EQ(rs[0].provenance_json, "{}");
}

// Sign-off (schema 9): an approval names the exact result and who approved it; a result of
// another run, one superseded since and one approved already are refused; a re-analysis after
// the approval leaves the new result unapproved. A version 8 file has none, read-only.
TEST(Store, AnApprovalNamesTheExactCurrentResult) {
  TempDir dir;
  const auto file = dir.path / "site.sqlite";
  Store store(file);
  const auto run = a_run(store), other = a_run(store);
  const auto first = store.add_result({.run_id = run, .standard = "ISO 230-2:2014", .json = "{}"});
  const auto second = store.add_result({.run_id = run, .standard = "ISO 230-2:2014", .json = "{}"});
  const auto elsewhere =
      store.add_result({.run_id = other, .standard = "ISO 230-2:2014", .json = "{}"});
  EXPECT_THROW(store.approve(run, first, "rev"), StoreError);      // superseded by `second`
  EXPECT_THROW(store.approve(run, elsewhere, "rev"), StoreError);  // not this run's
  EXPECT_TRUE(store.approvals(run).empty());
  const auto a = store.approve(run, second, "rev");
  EXPECT_EQ(a.result_id, second);
  EXPECT_EQ(a.approved_by, "rev");
  EXPECT_GT(a.approved_unix_ms, 0);
  EXPECT_THROW(store.approve(run, second, "other"), StoreError);  // approved already
  const auto third = store.add_result({.run_id = run, .standard = "ISO 230-2:2014", .json = "{}"});
  const auto kept = store.approvals(run);
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept[0].result_id, second);  // not the re-analysis
  EXPECT_EQ(kept[0].approved_by, "rev");
  EXPECT_EQ(kept[0].approved_unix_ms, a.approved_unix_ms);
  EXPECT_NE(third, second);
  EXPECT_TRUE(store.approvals(other).empty());
}

TEST(Store, ReplacingTheTargetsSupersedesEveryResultInOneTransaction) {
  TempDir dir;
  Store store(dir.path / "site.sqlite");
  const auto run = a_run(store);
  const cal::storage::CapturedTarget t{
      .run_id = run, .run_number = 1, .direction = '+', .nominal_mm = 0, .deviation_um = 1.0};
  store.add_targets(std::span(&t, 1));
  store.add_result({.run_id = run, .standard = "ISO 230-2:2014", .json = "{}"});
  store.add_result({.run_id = run, .standard = "VDI/DGQ 3441", .json = "{}"});
  auto changed = t;
  changed.deviation_um = 2.5;
  const auto id = store.replace_targets(
      run, std::span(&changed, 1), {.run_id = run, .standard = "ISO 230-2:2014", .json = "{}"});
  const auto rs = store.results(run);
  ASSERT_EQ(rs.size(), 3u);
  EXPECT_EQ(rs[0].superseded_by, id);
  EXPECT_EQ(rs[1].superseded_by, id);  // made from the old deviations
  EXPECT_TRUE(rs[2].current());
  EXPECT_EQ(store.targets(run).at(0).deviation_um, 2.5);
}

// The compensations of one machine and axis; a missing machine or source run reads as 0.
TEST(Store, CompensationsByMachineAndAxis) {
  TempDir dir;
  Store store(dir.path / "site.sqlite");
  const auto run = a_run(store);
  const auto machine = store.add_machine({.name = "mill"});
  store.add_compensation({.machine_id = machine,
                          .source_run_id = run,
                          .source = "run 1",
                          .axis = "X",
                          .format = "siemens",
                          .created_unix_ms = 5,
                          .json = "{}"});
  store.add_compensation({.source = "model m.json", .axis = "Y", .format = "fanuc", .json = "[]"});
  const auto all = store.compensations(0, "");
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[0].machine_id, machine);
  EXPECT_EQ(all[0].source_run_id, run);
  EXPECT_EQ(all[0].format, "siemens");
  EXPECT_EQ(all[1].machine_id, 0);
  EXPECT_EQ(all[1].source_run_id, 0);
  EXPECT_EQ(all[1].json, "[]");
  EXPECT_EQ(store.compensations(machine, "X").size(), 1u);
  EXPECT_TRUE(store.compensations(machine, "Y").empty());
}

TEST(Store, MissedStopsAndTheTimeOriginRoundTrip) {
  TempDir dir;
  Store store(dir.path / "site.sqlite");
  const auto run = a_run(store);
  EXPECT_FALSE(store.run(run)->origin_unix_ns.has_value());
  const cal::storage::MissedStop m[] = {
      {.run_number = 2, .direction = '-', .target_index = 3, .nominal_mm = 150.25},
      {.run_number = 2, .direction = '+', .target_index = 7, .nominal_mm = 350.0}};
  store.set_missed_stops(run, m);
  const auto back = store.missed_stops(run);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].direction, '+');  // in the order of the test: run, up before down
  EXPECT_EQ(back[0].target_index, 7);
  EXPECT_EQ(back[1].nominal_mm, 150.25);
  store.set_time_origin(run, 123'456'789, 1'780'000'000'123'456'789);
  EXPECT_EQ(store.run(run)->origin_session_ns, 123'456'789);
  EXPECT_EQ(store.run(run)->origin_unix_ns, 1'780'000'000'123'456'789);
}

// A database written by schema 1 (before provenance): migrated in place, its results kept and
// marked: the older of two results of one standard, and a result followed by a
// re-compensation, are superseded.
TEST(Store, MigratesASchemaOneDatabaseAndMarksItsResults) {
  TempDir dir;
  const auto file = dir.path / "old.sqlite";
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
    const char* v1 = R"sql(
CREATE TABLE machines(id INTEGER PRIMARY KEY, name TEXT NOT NULL UNIQUE,
  description TEXT NOT NULL DEFAULT '', config_json TEXT NOT NULL DEFAULT '{}');
CREATE TABLE runs(id INTEGER PRIMARY KEY, machine_id INTEGER REFERENCES machines(id),
  campaign TEXT NOT NULL DEFAULT '', kind TEXT NOT NULL, axis TEXT NOT NULL DEFAULT '',
  settings_json TEXT NOT NULL DEFAULT '{}', capture_path TEXT NOT NULL DEFAULT '',
  software_version TEXT NOT NULL DEFAULT '', started_unix_ms INTEGER NOT NULL,
  ended_unix_ms INTEGER, status TEXT NOT NULL CHECK(status IN ('running', 'complete',
  'incomplete', 'aborted')), note TEXT NOT NULL DEFAULT '', owner_pid INTEGER NOT NULL DEFAULT 0);
CREATE TABLE instruments(run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  device INTEGER NOT NULL, driver TEXT NOT NULL, transport TEXT NOT NULL,
  settings_json TEXT NOT NULL DEFAULT '{}', PRIMARY KEY(run_id, device));
CREATE TABLE reading_chunks(id INTEGER PRIMARY KEY, run_id INTEGER NOT NULL REFERENCES runs(id)
  ON DELETE CASCADE, device INTEGER NOT NULL, channel INTEGER NOT NULL, quantity INTEGER NOT NULL,
  first_ns INTEGER NOT NULL, last_ns INTEGER NOT NULL, count INTEGER NOT NULL, data BLOB NOT NULL);
CREATE INDEX reading_chunks_by_run ON reading_chunks(run_id, first_ns);
CREATE TABLE captured_targets(run_id INTEGER NOT NULL REFERENCES runs(id) ON DELETE CASCADE,
  target_index INTEGER NOT NULL, run_number INTEGER NOT NULL, direction TEXT NOT NULL
  CHECK(direction IN ('+', '-')), nominal_mm REAL NOT NULL, time_ns INTEGER NOT NULL,
  raw_m REAL NOT NULL, deviation_um REAL NOT NULL, refractive_index REAL NOT NULL,
  material_temperature_degc REAL NOT NULL, PRIMARY KEY(run_id, run_number, direction, target_index));
CREATE TABLE results(id INTEGER PRIMARY KEY, run_id INTEGER NOT NULL REFERENCES runs(id)
  ON DELETE CASCADE, standard TEXT NOT NULL, json TEXT NOT NULL, created_unix_ms INTEGER NOT NULL);
INSERT INTO runs(id, kind, started_unix_ms, status) VALUES(1, 'linear', 1, 'complete');
INSERT INTO results(run_id, standard, json, created_unix_ms) VALUES
  (1, 'ISO 230-2:2014', '{}', 1), (1, 'VDI/DGQ 3441', '{}', 2),
  (1, 'ISO 230-2:2014 (recompensated)', '{}', 3), (1, 'ISO 230-2:2014 (recompensated)', '{}', 4);
PRAGMA user_version = 1;
)sql";
    ASSERT_EQ(sqlite3_exec(db, v1, nullptr, nullptr, nullptr), SQLITE_OK);
    sqlite3_close(db);
  }
  Store store(file);
  EXPECT_EQ(store.version(), cal::storage::schema_version);
  const auto rs = store.results(1);
  ASSERT_EQ(rs.size(), 4u);
  EXPECT_EQ(rs[0].superseded_by, rs[2].id);  // the original, by the first re-compensation
  EXPECT_EQ(rs[1].superseded_by, rs[2].id);  // made from the deviations before it
  EXPECT_EQ(rs[2].superseded_by, rs[3].id);
  EXPECT_TRUE(rs[3].current());
  EXPECT_EQ(rs[3].provenance_json, "{}");
  EXPECT_TRUE(store.missed_stops(1).empty());
}

TEST(Store, BallbarCalibrationsByBarLengthAndDate) {
  // Two bars; bar A calibrated at 100 mm twice (day 1 and day 10) and at 150 mm (day 5). A test
  // on day 7 at 100 mm uses day 1's; on day 12, day 10's; at 150 mm on day 3, none yet.
  TempDir dir;
  Store store(dir.path / "site.sqlite");
  constexpr std::int64_t day = 86'400'000;
  const auto a1 = store.add_bar_calibration({.bar = "A",
                                             .nominal_mm = 100,
                                             .calibrator = "Zerodur 7",
                                             .calibrator_length_mm = 100.0021,
                                             .reading_mm = 0.0012,
                                             .zero_length_mm = 100.0009,
                                             .temperature_degc = 20.4,
                                             .calibrated_unix_ms = 1 * day});
  store.add_bar_calibration({.bar = "A",
                             .nominal_mm = 100,
                             .calibrator_length_mm = 100.0021,
                             .reading_mm = -0.0030,
                             .zero_length_mm = 100.0051,
                             .calibrated_unix_ms = 10 * day});
  store.add_bar_calibration({.bar = "A",
                             .nominal_mm = 150,
                             .extensions = "50 mm",
                             .calibrator_length_mm = 150.0,
                             .reading_mm = 0.0,
                             .zero_length_mm = 150.0,
                             .calibrated_unix_ms = 5 * day});
  store.add_bar_calibration({.bar = "B",
                             .nominal_mm = 100,
                             .calibrator_length_mm = 100.0,
                             .reading_mm = 0.0,
                             .zero_length_mm = 100.0,
                             .calibrated_unix_ms = 2 * day});
  const auto d7 = store.bar_calibration("A", 100.0, 7 * day);
  ASSERT_TRUE(d7);
  EXPECT_EQ(d7->id, a1);
  EXPECT_EQ(d7->zero_length_mm, 100.0009);
  EXPECT_EQ(d7->calibrator, "Zerodur 7");
  EXPECT_EQ(d7->temperature_degc, 20.4);
  EXPECT_EQ(store.bar_calibration("A", 100.0, 12 * day)->zero_length_mm, 100.0051);
  EXPECT_FALSE(store.bar_calibration("A", 150.0, 3 * day));
  EXPECT_EQ(store.bar_calibration("A", 150.0, 6 * day)->extensions, "50 mm");
  EXPECT_FALSE(store.bar_calibration("A", 120.0, 12 * day));  // no such length
  EXPECT_FALSE(store.bar_calibration("C", 100.0, 12 * day));  // no such bar
  EXPECT_FALSE(store.bar_calibration("A", 100.0, 12 * day)->temperature_degc);
  EXPECT_EQ(store.bar_calibrations("A").size(), 3u);
  EXPECT_EQ(store.bar_calibrations().size(), 4u);
  EXPECT_EQ(store.bar_calibrations().front().bar, "A");  // oldest first
  // Refused: no bar, a length that is not finite and > 0; nothing is stored then.
  EXPECT_THROW(store.add_bar_calibration(
                   {.nominal_mm = 100, .calibrator_length_mm = 100, .zero_length_mm = 100}),
               cal::storage::StoreError);
  EXPECT_THROW(store.add_bar_calibration({.bar = "A",
                                          .nominal_mm = 100,
                                          .calibrator_length_mm = std::nan(""),
                                          .zero_length_mm = 100}),
               cal::storage::StoreError);
  EXPECT_EQ(store.bar_calibrations().size(), 4u);
}

// What schema 7 added (the runs' UUIDs), taken off a new file to make a version 6 one; a macro so
// that it prefixes the other undo strings as a literal.
#define CALDAQ_UNDO_SCHEMA11 "DROP TABLE models; "
#define CALDAQ_UNDO_SCHEMA10 CALDAQ_UNDO_SCHEMA11 "DROP TABLE central_approvals; "
#define CALDAQ_UNDO_SCHEMA9 CALDAQ_UNDO_SCHEMA10 "DROP TABLE approvals; "
#define CALDAQ_UNDO_SCHEMA8 \
  CALDAQ_UNDO_SCHEMA9 "DROP INDEX machines_by_uuid; ALTER TABLE machines DROP COLUMN uuid; "
#define CALDAQ_UNDO_SCHEMA7 \
  CALDAQ_UNDO_SCHEMA8 "DROP INDEX runs_by_uuid; ALTER TABLE runs DROP COLUMN uuid; "
// What schema 5 added (origins, compensations, the stop quality), taken off a new file to
// make a version 4 one (schema 7's and 6's go first).
constexpr const char* kUndoSchema5 = CALDAQ_UNDO_SCHEMA7
    "DROP TABLE operator_actions; DROP INDEX compensations_by_machine; DROP TABLE compensations; "
    "ALTER TABLE instruments DROP COLUMN origin; ALTER TABLE instruments DROP COLUMN "
    "origin_detail; ALTER TABLE captured_targets DROP COLUMN suspect; ALTER TABLE runs DROP "
    "COLUMN quality; ALTER TABLE runs DROP COLUMN quality_note; ";
constexpr const char* kUndoQuality = kUndoSchema5;

// Issue 26: the instruments' origin and the compensations written. A version 4 database reads
// read-only as not recorded / none, and the next writing open migrates it.
TEST(Store, OriginsAndCompensationsAndTheVersionBefore) {
  TempDir dir;
  const auto file = dir.path / "v4.sqlite";
  std::int64_t run = 0;
  {
    Store store(file);
    run = a_run(store);
    store.add_instrument({.run_id = run,
                          .device = 7,
                          .driver = "laser",
                          .transport = "tcp x",
                          .origin = "simulated",
                          .origin_detail = "a twin"});
    const auto id = store.add_compensation({.machine_id = 0,
                                            .source_run_id = run,
                                            .source = "run 1",
                                            .axis = "X",
                                            .format = "siemens",
                                            .json = "{}"});
    const auto all = store.compensations(0, "X");
    ASSERT_EQ(all.size(), 1u);
    EXPECT_EQ(all[0].id, id);
    EXPECT_EQ(all[0].source_run_id, run);
    EXPECT_TRUE(store.compensations(0, "Y").empty());
    const auto inst = store.instruments(run);
    ASSERT_FALSE(inst.empty());
    EXPECT_EQ(inst.back().origin, "simulated");
    EXPECT_EQ(inst.back().origin_detail, "a twin");
  }
  const auto undo = std::string(kUndoSchema5) + "PRAGMA user_version = 4;";
  ASSERT_EQ(exec_sql(file, undo), "");
  {
    Store ro(file, {.read_only = true});
    EXPECT_EQ(ro.version(), 4);
    EXPECT_TRUE(ro.compensations().empty());
    EXPECT_EQ(ro.instruments(run).back().origin, "");  // not recorded, never "real"
  }
  Store rw(file);
  EXPECT_EQ(rw.version(), cal::storage::schema_version);
  EXPECT_EQ(rw.instruments(run).back().origin, "");
  EXPECT_TRUE(rw.compensations().empty());
}

// A database at the version before the ballbar calibrations (schema 3 with a run in it):
// opened, it gains the table by the migrations, keeps its run, and stores a calibration.
TEST(Store, MigratesTheVersionBeforeBallbarCalibrations) {
  TempDir dir;
  const auto file = dir.path / "prev.sqlite";
  const std::int64_t run = a_run_in(file);
  const auto undo = std::string(kUndoSchema5) +
                    "DROP INDEX ballbar_calibrations_by_bar; DROP TABLE ballbar_calibrations; "
                    "PRAGMA user_version = 3;";
  ASSERT_EQ(exec_sql(file, undo), "");
  Store store(file);
  EXPECT_EQ(store.version(), cal::storage::schema_version);
  EXPECT_TRUE(store.run(run).has_value());
  EXPECT_TRUE(store.bar_calibrations().empty());
  store.add_bar_calibration({.bar = "A",
                             .nominal_mm = 100,
                             .calibrator_length_mm = 100.0,
                             .reading_mm = 0.001,
                             .zero_length_mm = 99.999,
                             .calibrated_unix_ms = 1});
  EXPECT_EQ(store.bar_calibration("A", 100.0, 2)->zero_length_mm, 99.999);
}

// Read-only, a database of schema 3 is read as it is: no calibrations, nothing written.
TEST(Store, ReadOnlyThePreviousVersionHasNoBallbarCalibrations) {
  TempDir dir;
  const auto file = dir.path / "prev.sqlite";
  { Store store(file); }
  const auto undo = std::string(kUndoSchema5) +
                    "DROP INDEX ballbar_calibrations_by_bar; DROP TABLE ballbar_calibrations; "
                    "PRAGMA user_version = 3;";
  ASSERT_EQ(exec_sql(file, undo), "");
  {
    Store ro(file, {.read_only = true});
    EXPECT_TRUE(ro.bar_calibrations().empty());
    EXPECT_FALSE(ro.bar_calibration("A", 100.0, 1));
  }
  Store rw(file);  // the next writing open migrates it
  EXPECT_EQ(rw.version(), cal::storage::schema_version);
}

// A stored run's stop quality (issue 26): stored and read back with its suspect stops; set
// again, it replaces what was there.
TEST(Store, StoresARunsStopQuality) {
  TempDir dir;
  Store store(dir.path / "q.sqlite");
  const auto run = a_run(store);
  EXPECT_FALSE(store.quality(run));  // never checked
  std::vector<cal::storage::CapturedTarget> stops;
  for (int k = 0; k < 3; ++k)
    for (const char d : {'+', '-'})
      stops.push_back({.run_id = run,
                       .target_index = k,
                       .run_number = 1,
                       .direction = d,
                       .nominal_mm = 100.0 * k,
                       .time_ns = k * 10 + (d == '-')});
  store.add_targets(stops);
  store.set_quality(run, {.state = "suspect",
                          .summary = "suspect: 1 stop",
                          .suspects = {{.run_number = 1,
                                        .direction = '-',
                                        .target_index = 2,
                                        .reason = "run 1 down at 200 mm: far off"}}});
  const auto q = store.quality(run);
  ASSERT_TRUE(q);
  EXPECT_EQ(q->state, "suspect");
  EXPECT_EQ(q->summary, "suspect: 1 stop");
  ASSERT_EQ(q->suspects.size(), 1u);
  EXPECT_EQ(q->suspects[0].target_index, 2);
  EXPECT_EQ(q->suspects[0].direction, '-');
  EXPECT_EQ(q->suspects[0].reason, "run 1 down at 200 mm: far off");
  store.set_quality(run, {.state = "ok", .summary = "ok"});
  EXPECT_EQ(store.quality(run)->state, "ok");
  EXPECT_TRUE(store.quality(run)->suspects.empty());
  EXPECT_THROW(store.set_quality(run, {.state = "fine"}), cal::storage::StoreError);
}

// A schema 4 database: read-only, read as it is (its runs never checked, nothing written);
// opened for writing, migrated to 5, its run still unchecked until a quality is stored.
TEST(Store, ASchema4DatabaseReadsItsRunsAsNeverChecked) {
  TempDir dir;
  const auto file = dir.path / "v4.sqlite";
  const std::int64_t run = a_run_in(file);
  const auto undo = std::string(kUndoQuality) + "PRAGMA user_version = 4;";
  ASSERT_EQ(exec_sql(file, undo), "");
  {
    Store ro(file, {.read_only = true});
    EXPECT_EQ(ro.version(), 4);
    EXPECT_TRUE(ro.run(run).has_value());
    EXPECT_FALSE(ro.quality(run));
    EXPECT_TRUE(ro.targets(run).empty());
  }
  Store rw(file);
  EXPECT_EQ(rw.version(), cal::storage::schema_version);
  EXPECT_FALSE(rw.quality(run));
  rw.set_quality(run, {.state = "ok", .summary = "ok"});
  EXPECT_EQ(rw.quality(run)->state, "ok");
}

// Issue 29: the operator's actions of a run, stored as they happen and read back in order; an
// unknown action is refused; a schema 5 file reads as none, and migrates.
TEST(Store, OperatorActionsAreKeptInOrderAndAnOlderFileHasNone) {
  TempDir dir;
  const auto file = dir.path / "v5.sqlite";
  std::int64_t run = 0;
  {
    Store store(file);
    run = a_run(store);
    store.add_operator_action({.run_id = run, .action = "pause", .source = "web page"});
    store.add_operator_action(
        {.run_id = run,
         .time_unix_ms = 1700000000123,
         .action = "capture",
         .source = "web page",
         .operator_name = "A. Operator",
         .stop =
             cal::storage::MissedStop{
                 .run_number = 2, .direction = '-', .target_index = 3, .nominal_mm = 150.0},
         .detail = "+1.250 um"});
    EXPECT_THROW(store.add_operator_action({.run_id = run, .action = "dance"}),
                 cal::storage::StoreError);
    const auto a = store.operator_actions(run);
    ASSERT_EQ(a.size(), 2u);
    EXPECT_EQ(a[0].action, "pause");
    EXPECT_FALSE(a[0].stop);
    EXPECT_GT(a[0].time_unix_ms, 0);
    EXPECT_EQ(a[1].action, "capture");
    EXPECT_EQ(a[1].time_unix_ms, 1700000000123);
    EXPECT_EQ(a[1].operator_name, "A. Operator");
    ASSERT_TRUE(a[1].stop);
    EXPECT_EQ(a[1].stop->run_number, 2);
    EXPECT_EQ(a[1].stop->direction, '-');
    EXPECT_EQ(a[1].stop->target_index, 3);
    EXPECT_DOUBLE_EQ(a[1].stop->nominal_mm, 150.0);
    EXPECT_EQ(a[1].detail, "+1.250 um");
  }
  ASSERT_EQ(
      exec_sql(file, CALDAQ_UNDO_SCHEMA7 "DROP TABLE operator_actions; PRAGMA user_version = 5;"),
      "");
  {
    Store ro(file, {.read_only = true});
    EXPECT_EQ(ro.version(), 5);
    EXPECT_TRUE(ro.operator_actions(run).empty());
  }
  Store rw(file);
  EXPECT_EQ(rw.version(), cal::storage::schema_version);
  EXPECT_TRUE(rw.operator_actions(run).empty());
}

// Issue 35: every run has a stable identity, a random UUID: given at begin_run unless the run
// brings its own, kept on reopening, found by run_by_uuid; a malformed one is refused.
TEST(Store, EveryRunHasItsOwnUuid) {
  TempDir dir;
  const auto file = dir.path / "uuid.sqlite";
  std::string first;
  {
    Store store(file);
    const auto a = a_run(store);
    const auto b = a_run(store);
    first = store.run(a)->uuid;
    EXPECT_TRUE(cal::storage::is_uuid(first)) << first;
    EXPECT_EQ(first[14], '4');                                                   // version 4
    EXPECT_NE(std::string("89ab").find(first[19]), std::string::npos) << first;  // variant 10
    EXPECT_NE(store.run(b)->uuid, first);
    const std::string given = "0d3c1a52-8e5f-4b7a-9c1d-2e3f4a5b6c7d";
    const auto c = store.begin_run({.kind = "linear", .uuid = given});
    EXPECT_EQ(store.run(c)->uuid, given);
    EXPECT_EQ(store.run_by_uuid(given)->id, c);
    EXPECT_FALSE(store.run_by_uuid("00000000-0000-4000-8000-000000000000"));
    EXPECT_THROW(store.begin_run({.kind = "linear", .uuid = "not-a-uuid"}), StoreError);
    EXPECT_THROW(store.begin_run({.kind = "linear", .uuid = given}), StoreError);  // unique
  }
  Store again(file);
  EXPECT_EQ(again.runs().front().uuid, first);
  std::set<std::string> seen;
  for (int i = 0; i < 10000; ++i) EXPECT_TRUE(seen.insert(cal::storage::new_uuid()).second);
  EXPECT_FALSE(cal::storage::is_uuid("0D3C1A52-8E5F-4B7A-9C1D-2E3F4A5B6C7D"));  // upper case
  EXPECT_FALSE(cal::storage::is_uuid("0d3c1a528e5f4b7a9c1d2e3f4a5b6c7d"));
}

// Migration 6 -> 7 gives the runs already stored each their own UUID; read-only, a version 6
// file shows none (and is not changed).
TEST(Store, MigrationSevenGivesEveryStoredRunAUuid) {
  TempDir dir;
  const auto file = dir.path / "v6.sqlite";
  {
    Store store(file);
    for (int i = 0; i < 50; ++i) a_run(store);
  }
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
    ASSERT_EQ(
        sqlite3_exec(db, CALDAQ_UNDO_SCHEMA7 "PRAGMA user_version = 6;", nullptr, nullptr, nullptr),
        SQLITE_OK);
    sqlite3_close(db);
  }
  {
    Store ro(file, {.read_only = true});
    EXPECT_EQ(ro.version(), 6);
    EXPECT_EQ(ro.runs().front().uuid, "");
  }
  Store rw(file);
  EXPECT_EQ(rw.version(), cal::storage::schema_version);
  std::set<std::string> seen;
  for (const auto& r : rw.runs()) {
    EXPECT_TRUE(cal::storage::is_uuid(r.uuid)) << r.uuid;
    EXPECT_EQ(r.uuid[14], '4') << r.uuid;
    EXPECT_NE(std::string("89ab").find(r.uuid[19]), std::string::npos) << r.uuid;
    seen.insert(r.uuid);
  }
  EXPECT_EQ(seen.size(), 50u);
}

// Migration 7 -> 8 gives the machines already stored each their own UUID (two sites' machines of
// one name stay apart centrally) and keeps every stored run as it was (its UUID, machine,
// readings, stops and results); read-only, a version 7 file shows none; add_machine keeps a
// UUID given (a machine brought by daq sync --from) and refuses one that is not.
TEST(Store, MigrationEightGivesEveryMachineAUuid) {
  TempDir dir;
  const auto file = dir.path / "v7.sqlite";
  std::vector<cal::storage::RunRecord> before;
  {
    Store store(file);
    const auto mill1 = store.add_machine({.name = "Mill 1"});
    const auto mill2 = store.add_machine({.name = "Mill 2"});
    for (int i = 0; i < 20; ++i) {
      const auto run = store.begin_run({.machine_id = i % 2 ? mill2 : mill1, .kind = "linear"});
      store.append_readings(run, std::vector<RawReading>{{.time_ns = i, .value = 1e-3 * i}});
      store.add_targets(std::vector<cal::storage::CapturedTarget>{
          {.run_id = run, .target_index = i, .direction = '+', .deviation_um = 0.5 * i}});
      store.add_result({.run_id = run, .standard = "ISO 230-2:2014", .json = "{}"});
    }
    before = store.runs();
  }
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
    ASSERT_EQ(
        sqlite3_exec(db, CALDAQ_UNDO_SCHEMA8 "PRAGMA user_version = 7;", nullptr, nullptr, nullptr),
        SQLITE_OK);
    sqlite3_close(db);
  }
  {
    Store ro(file, {.read_only = true});
    EXPECT_EQ(ro.version(), 7);
    EXPECT_TRUE(ro.approvals(before.front().id).empty());  // before sign-off: none
    EXPECT_EQ(ro.machine_by_name("Mill 1")->uuid, "");
    EXPECT_EQ(ro.runs().size(), before.size());
  }
  Store rw(file);
  EXPECT_EQ(rw.version(), cal::storage::schema_version);
  const auto one = rw.machine_by_name("Mill 1")->uuid, two = rw.machine_by_name("Mill 2")->uuid;
  EXPECT_TRUE(cal::storage::is_uuid(one)) << one;
  EXPECT_TRUE(cal::storage::is_uuid(two)) << two;
  EXPECT_NE(one, two);
  const auto after = rw.runs();
  ASSERT_EQ(after.size(), before.size());
  for (std::size_t i = 0; i < after.size(); ++i) {
    const auto& r = after[i];
    EXPECT_EQ(r.id, before[i].id);
    EXPECT_EQ(r.uuid, before[i].uuid);
    EXPECT_TRUE(cal::storage::is_uuid(r.uuid)) << r.uuid;
    EXPECT_EQ(r.machine_id, before[i].machine_id);
    const auto readings = rw.readings(r.id);
    ASSERT_EQ(readings.size(), 1u) << "run " << r.id;
    EXPECT_EQ(readings[0].value, 1e-3 * static_cast<double>(i));
    const auto stops = rw.targets(r.id);
    ASSERT_EQ(stops.size(), 1u) << "run " << r.id;
    EXPECT_EQ(stops[0].deviation_um, 0.5 * static_cast<double>(i));
    EXPECT_EQ(rw.results(r.id).size(), 1u) << "run " << r.id;
  }
  const std::string given = "0b6a4f1e-2c3d-4e5f-8a9b-0c1d2e3f4a5b";
  const auto id = rw.add_machine({.name = "Mill 3", .uuid = given});
  EXPECT_EQ(rw.machine(id)->uuid, given);
  EXPECT_THROW(rw.add_machine({.name = "Mill 4", .uuid = "Mill 4"}), StoreError);
}

// Schema 10 (daq sync --from): the central server's approvals of results brought here, read-only:
// listed before the local ones with their server, fingerprint and version; a second one of the
// same result not stored; a result approved there refused by a local approve (approved already);
// the operator's actions of a run brought here replaced as the server has them, those of a run
// acquired here left alone. A version 9 file, read-only, has no central approvals; migrated, it
// keeps its local approval.
TEST(Store, CentralApprovalsAndOperatorActionsBroughtFromTheServer) {
  TempDir dir;
  const auto file = dir.path / "laptop.sqlite";
  std::int64_t local_result = 0, own = 0;
  {
    Store store(file);
    own = a_run(store);
    local_result = store.add_result({.run_id = own, .standard = "ISO 230-2:2014", .json = "{}"});
    store.approve(own, local_result, "me");
  }
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db, CALDAQ_UNDO_SCHEMA10 "PRAGMA user_version = 9;", nullptr, nullptr,
                           nullptr),
              SQLITE_OK);
    sqlite3_close(db);
    Store ro(file, {.read_only = true});
    EXPECT_EQ(ro.version(), 9);
    ASSERT_EQ(ro.approvals(own).size(), 1u);
    EXPECT_EQ(ro.approvals(own)[0].central_server, "");
  }
  Store store(file);
  EXPECT_EQ(store.version(), cal::storage::schema_version);
  ASSERT_EQ(store.approvals(own).size(), 1u);
  const auto brought = store.import_run({.kind = "linear",
                                         .status = RunStatus::complete,
                                         .uuid = "0b6a4f1e-2c3d-4e5f-8a9b-0c1d2e3f4a5b"});
  const auto result =
      store.add_result({.run_id = brought, .standard = "ISO 230-2:2014", .json = "{}"});
  const cal::storage::Approval there{.result_id = result,
                                     .result_fingerprint = "0123456789abcdef0123456789abcdef",
                                     .run_version = 2,
                                     .approved_by = "rev",
                                     .approved_unix_ms = 1764000000000,
                                     .central_server = "postgresql://central/caldaq"};
  EXPECT_TRUE(store.add_central_approval(there));
  EXPECT_FALSE(store.add_central_approval({.result_id = result,
                                           .result_fingerprint = "x",
                                           .approved_by = "other",
                                           .central_server = "postgresql://central/caldaq"}));
  EXPECT_THROW(store.approve(brought, result, "me"), StoreError);  // approved there already
  const auto approvals = store.approvals(brought);
  ASSERT_EQ(approvals.size(), 1u);
  EXPECT_EQ(approvals[0].result_id, result);
  EXPECT_EQ(approvals[0].approved_by, "rev");
  EXPECT_EQ(approvals[0].approved_unix_ms, 1764000000000);
  EXPECT_EQ(approvals[0].result_fingerprint, "0123456789abcdef0123456789abcdef");
  EXPECT_EQ(approvals[0].run_version, 2);
  EXPECT_EQ(approvals[0].central_server, "postgresql://central/caldaq");
  // A result approved there and here: the server's first.
  EXPECT_TRUE(store.add_central_approval({.result_id = local_result,
                                          .result_fingerprint = "f",
                                          .run_version = 1,
                                          .approved_by = "rev",
                                          .approved_unix_ms = 1,
                                          .central_server = "postgresql://central/caldaq"}));
  const auto both = store.approvals(own);
  ASSERT_EQ(both.size(), 2u);
  EXPECT_EQ(both[0].approved_by, "rev");
  EXPECT_EQ(both[1].approved_by, "me");
  EXPECT_EQ(both[1].central_server, "");

  // The operator's actions: the brought run's replaced, the run acquired here's kept.
  store.add_operator_action({.run_id = brought, .time_unix_ms = 5, .action = "pause"});
  store.add_operator_action({.run_id = own, .time_unix_ms = 6, .action = "pause"});
  const std::vector<cal::storage::OperatorAction> theirs{
      {.time_unix_ms = 7,
       .action = "capture",
       .source = "web page",
       .operator_name = "J. Smith",
       .stop =
           cal::storage::MissedStop{
               .run_number = 1, .direction = '-', .target_index = 3, .nominal_mm = 150.0},
       .detail = "captured by hand"},
      {.time_unix_ms = 8, .action = "resume", .source = "web page"}};
  EXPECT_TRUE(store.replace_imported_operator_actions(brought, theirs));
  EXPECT_FALSE(store.replace_imported_operator_actions(own, theirs));
  const auto now = store.operator_actions(brought);
  ASSERT_EQ(now.size(), 2u);
  EXPECT_EQ(now[0].action, "capture");
  EXPECT_EQ(now[0].run_id, brought);
  ASSERT_TRUE(now[0].stop.has_value());
  EXPECT_EQ(now[0].stop->target_index, 3);
  EXPECT_EQ(now[0].stop->direction, '-');
  EXPECT_EQ(now[1].action, "resume");
  const auto kept = store.operator_actions(own);
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_EQ(kept[0].time_unix_ms, 6);
}

// What daq sync --from writes: another store's run imported with its UUID, status and times,
// under another id; its chunks stored with checksums for the id here (read back and verified);
// a UUID already here, or a chunk that does not follow, refused; in_transaction all or nothing.
// A run still running where it was recorded is not "interrupted" by opening this store.
TEST(Store, AnImportedRunKeepsItsIdentityAndItsReadings) {
  TempDir dir;
  Store source(dir.path / "site.sqlite");
  a_run(source);  // the ids differ between the two stores
  const auto run = a_run(source);
  for (int batch = 0; batch < 3; ++batch)
    source.append_readings(run, make_readings(200, static_cast<std::uint64_t>(batch)));
  const auto record = *source.run(run);  // still running
  const auto chunks = source.stored_chunks(run, 0, 100);
  ASSERT_GT(chunks.size(), 2u);
  const auto laptop_file = dir.path / "laptop.sqlite";
  std::int64_t here = 0;
  {
    Store laptop(laptop_file);
    here = laptop.import_run(record);
    EXPECT_NE(here, run);
    EXPECT_THROW(laptop.import_run(record), StoreError);  // its UUID is here
    EXPECT_THROW(laptop.import_run({.kind = "linear", .uuid = "x"}), StoreError);
    laptop.add_stored_chunks(here, std::span(chunks).first(2));
    EXPECT_THROW(laptop.add_stored_chunks(here, std::span(chunks).subspan(3)), StoreError);
    EXPECT_EQ(laptop.chunk_count(here), 2);
    // A failure inside in_transaction takes back what the inner writes did.
    EXPECT_THROW(laptop.in_transaction([&] {
      laptop.add_stored_chunks(here, std::span(chunks).subspan(2));
      throw StoreError("cut");
    }),
                 StoreError);
    EXPECT_EQ(laptop.chunk_count(here), 2);
    laptop.in_transaction([&] { laptop.add_stored_chunks(here, std::span(chunks).subspan(2)); });
  }
  {
    Store ro(laptop_file, {.read_only = true});
    EXPECT_EQ(ro.run(here)->status, RunStatus::running);
  }
  Store laptop(laptop_file);  // a writing open marks the interrupted runs: not this one
  const auto back = *laptop.run(here);
  EXPECT_EQ(back.uuid, record.uuid);
  EXPECT_EQ(back.status, RunStatus::running);
  EXPECT_EQ(back.started_unix_ms, record.started_unix_ms);
  EXPECT_EQ(laptop.run_by_uuid(record.uuid)->id, here);
  const auto readings = laptop.readings(here), original = source.readings(run);
  ASSERT_EQ(readings.size(), original.size());
  for (std::size_t i = 0; i < readings.size(); ++i) {
    EXPECT_EQ(readings[i].time_ns, original[i].time_ns);
    EXPECT_EQ(readings[i].value, original[i].value);
  }
  for (const auto& c : laptop.stored_chunks(here, 0, 100))  // checksums for the id here
    EXPECT_EQ(c.crc,
              cal::storage::chunk::checksum(cal::storage::chunk::key_of(here, c.seq, c), c.data));
}

// The chunks as stored, for daq sync: in the order written, paged, each checksum verified; a
// damaged chunk is an error naming it.
TEST(Store, StoredChunksComeInOrderWithTheirChecksumsVerified) {
  TempDir dir;
  const auto file = dir.path / "chunks.sqlite";
  Store store(file);
  const auto run = a_run(store);
  for (int batch = 0; batch < 4; ++batch)
    store.append_readings(run, make_readings(300, static_cast<std::uint64_t>(batch)));
  const auto count = store.chunk_count(run);
  EXPECT_EQ(count, 4 * 6);  // 6 series per batch (make_readings: device i % 3, channel i % 2)
  std::vector<Store::StoredChunk> all;
  for (std::int64_t first = 0; first < count; first += 7) {
    auto page = store.stored_chunks(run, first, 7);
    all.insert(all.end(), page.begin(), page.end());
  }
  ASSERT_EQ(static_cast<std::int64_t>(all.size()), count);
  for (std::size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(all[i].seq, static_cast<std::int64_t>(i));
    EXPECT_TRUE(all[i].stored_checksum);
    const cal::storage::chunk::Key key{.run_id = run,
                                       .seq = all[i].seq,
                                       .device = all[i].device,
                                       .channel = all[i].channel,
                                       .quantity = all[i].quantity,
                                       .first_ns = all[i].first_ns,
                                       .last_ns = all[i].last_ns,
                                       .count = all[i].count,
                                       .encoding = all[i].encoding};
    EXPECT_EQ(all[i].crc, cal::storage::chunk::checksum(key, all[i].data));
  }
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db, "UPDATE reading_chunks SET count = count + 1 WHERE seq = 9", nullptr,
                           nullptr, nullptr),
              SQLITE_OK);
    sqlite3_close(db);
  }
  EXPECT_NO_THROW(store.stored_chunks(run, 0, 9));
  try {
    store.stored_chunks(run, 0, 20);
    ADD_FAILURE() << "a damaged chunk was read";
  } catch (const StoreError& e) {
    EXPECT_NE(std::string(e.what()).find("reading chunk 9 "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("checksum does not match"), std::string::npos) << e.what();
  }
}

namespace {

// Issue 35: models kept in the store (schema 11). A schema 10 file (with a run) is read
// read-only as having none and migrated in place by the next writing open, its run kept; a model
// is kept with its text, provenance and who stored it, under a new UUID or the one it came with
// (brought from the central store), never twice, and only for a machine of the store.
TEST(Store, ModelsAreKeptWithTheirUuidAndASchema10FileMigratesInPlace) {
  TempDir dir;
  const auto file = dir.path / "laptop.sqlite";
  std::int64_t mill = 0, run = 0;
  std::string run_uuid;
  {
    Store store(file);
    mill = store.add_machine({.name = "Mill 1"});
    run = store.begin_run({.machine_id = mill, .kind = "linear", .axis = "X"});
    run_uuid = store.run(run)->uuid;
  }
  ASSERT_EQ(exec_sql(file, CALDAQ_UNDO_SCHEMA11 "PRAGMA user_version = 10;"), "");
  {
    Store ro(file, {.read_only = true});
    EXPECT_EQ(ro.version(), 10);
    EXPECT_TRUE(ro.models().empty());
    EXPECT_FALSE(ro.model(1));
    EXPECT_THROW(ro.add_model({.machine_id = mill, .json = "{}"}), StoreError);
  }
  const std::string text = R"({"schema": "caldaq.model.v1", "name": "Mill 1"})";
  const std::string provenance = R"({"schema": "caldaq.model-provenance.v1", "runs": []})";
  std::int64_t first = 0;
  std::string first_uuid;
  {
    Store store(file);
    EXPECT_EQ(store.version(), 11);
    EXPECT_EQ(store.run(run)->uuid, run_uuid);  // the run kept as it was
    first = store.add_model({.machine_id = mill,
                             .name = "Mill 1",
                             .json = text,
                             .provenance_json = provenance,
                             .stored_by = "anna",
                             .stored_from = "laptop-a",
                             .stored_unix_ms = 1764000000000});
    first_uuid = store.model(first)->uuid;
    EXPECT_TRUE(cal::storage::is_uuid(first_uuid)) << first_uuid;
    const auto brought = store.add_model(
        {.uuid = "0b6a4f1e-2c3d-4e5f-8a9b-0c1d2e3f4a5b", .machine_id = mill, .json = text});
    EXPECT_EQ(brought, first + 1);
    EXPECT_THROW(store.add_model({.uuid = first_uuid, .machine_id = mill, .json = text}),
                 StoreError);  // here already
    EXPECT_THROW(store.add_model({.uuid = "not-a-uuid", .machine_id = mill, .json = text}),
                 StoreError);
    EXPECT_THROW(store.add_model({.machine_id = mill + 7, .json = text}), StoreError);
    EXPECT_THROW(store.add_model({.machine_id = mill, .json = ""}), StoreError);
  }
  Store ro(file, {.read_only = true});
  const auto all = ro.models();
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[0].id, first);
  EXPECT_EQ(all[0].uuid, first_uuid);
  EXPECT_EQ(all[0].machine_id, mill);
  EXPECT_EQ(all[0].name, "Mill 1");
  EXPECT_EQ(all[0].json, text);
  EXPECT_EQ(all[0].provenance_json, provenance);
  EXPECT_EQ(all[0].stored_by, "anna");
  EXPECT_EQ(all[0].stored_from, "laptop-a");
  EXPECT_EQ(all[0].stored_unix_ms, 1764000000000);
  EXPECT_GT(all[1].stored_unix_ms, 1764000000000);  // 0 given: now (after 2025-11-24)
  EXPECT_EQ(ro.model_by_uuid("0b6a4f1e-2c3d-4e5f-8a9b-0c1d2e3f4a5b")->id, first + 1);
  EXPECT_FALSE(ro.model_by_uuid("0b6a4f1e-2c3d-4e5f-8a9b-0c1d2e3f4a5c"));
  EXPECT_EQ(ro.models(mill).size(), 2u);
  EXPECT_TRUE(ro.models(mill + 7).empty());
}

}  // namespace
