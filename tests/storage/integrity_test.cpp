// Stored data you can trust: read-only opening writes nothing (not to a database of today's
// schema, not to one written by the schema-1 code, whose crashed run it shows as interrupted
// without marking it); it never creates a database or reads another program's; the old
// database reads bit for bit and migrates when opened for writing; and a damaged file never
// gives silently different readings: a flipped byte is an error that names the run and the
// chunk, or it lies where no reading is.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <unistd.h>

#include <bit>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>

#include "../support/temp_dir.hpp"
#include "cal/storage/store.hpp"

namespace {

namespace fs = std::filesystem;
using cal::storage::RawReading;
using cal::storage::RunStatus;
using cal::storage::Store;
using cal::storage::StoreError;

struct TempDir : cal::test::TempDir {
  TempDir() : cal::test::TempDir("caldaq-integrity") {}
};

std::string bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}
void write_bytes(const fs::path& p, const std::string& b) {
  std::ofstream(p, std::ios::binary | std::ios::trunc) << b;
}

const fs::path kSchema1 = fs::path(CALDAQ_STORAGE_DATA) / "schema1.sqlite";

bool same(const RawReading& a, const RawReading& b) {
  return a.time_ns == b.time_ns && a.device == b.device && a.channel == b.channel &&
         a.quantity == b.quantity && a.status == b.status &&
         std::bit_cast<std::uint64_t>(a.value) == std::bit_cast<std::uint64_t>(b.value);
}

// The readings of the fixture's run 1, from the formulas of make_schema1.cpp (not from any
// reading code), in stream order: at equal times device 0 (length) before device 1 (air),
// the air by quantity.
std::vector<RawReading> schema1_run1() {
  std::vector<RawReading> v;
  for (std::int64_t i = 0; i < 12000; ++i) {
    v.push_back({.time_ns = i * 100000,
                 .device = 0,
                 .quantity = 1,
                 .status = static_cast<std::uint8_t>(i % 1000 == 999 ? 1 : 0),
                 .value = 0.1 + 1e-9 * static_cast<double>(i % 977)});
    if (i % 2000 == 0) {
      const double s = static_cast<double>(i / 2000);
      v.push_back({.time_ns = i * 100000, .device = 1, .quantity = 2, .value = 20.0 + 0.01 * s});
      v.push_back({.time_ns = i * 100000, .device = 1, .quantity = 3, .value = 101325.0 - s});
      v.push_back({.time_ns = i * 100000, .device = 1, .quantity = 4, .value = 45.0 + 0.1 * s});
    }
  }
  return v;
}

void expect_schema1_readings(const Store& store) {
  const auto want = schema1_run1();
  const auto got = store.readings(1);
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) ASSERT_TRUE(same(got[i], want[i])) << i;
  const auto run2 = store.readings(2);
  ASSERT_EQ(run2.size(), 1000u);
  for (std::int64_t k = 0; k < 1000; ++k) {
    ASSERT_EQ(run2[k].time_ns, k * 1000);
    ASSERT_EQ(run2[k].value, -0.25 + static_cast<double>(k) * 1e-6);
  }
}

TEST(ReadOnly, ASchema1DatabaseReadsAsItIsAndStaysByteForByteTheSame) {
  TempDir dir;
  const auto file = dir.path / "old.sqlite";
  fs::copy_file(kSchema1, file);
  const auto before = bytes_of(file);
  {
    Store store(file, {.read_only = true});
    EXPECT_TRUE(store.read_only());
    EXPECT_EQ(store.version(), 1);  // not migrated
    expect_schema1_readings(store);
    // The crashed run shows as interrupted, without a write.
    const auto r2 = store.run(2);
    ASSERT_TRUE(r2);
    EXPECT_EQ(r2->status, RunStatus::incomplete);
    EXPECT_NE(r2->note.find("opened read-only"), std::string::npos) << r2->note;
    EXPECT_EQ(store.runs().at(1).status, RunStatus::incomplete);
    EXPECT_EQ(store.targets(1).size(), 1u);
    EXPECT_EQ(store.results(1).at(0).json, R"({"fixture": true})");
    EXPECT_EQ(store.reading_count(1), 12018);
    // Every writing method refuses.
    EXPECT_THROW(store.begin_run({.kind = "linear"}), StoreError);
    EXPECT_THROW(store.finish_run(2, RunStatus::aborted), StoreError);
    EXPECT_THROW(store.append_readings(1, std::vector<RawReading>(1)), StoreError);
    EXPECT_THROW(store.add_result({.run_id = 1, .standard = "x", .json = "{}"}), StoreError);
  }
  EXPECT_EQ(bytes_of(file), before);
  EXPECT_FALSE(fs::exists(file.string() + "-wal") && fs::file_size(file.string() + "-wal") > 0);
}

TEST(ReadOnly, ASchema1DatabaseMigratesWhenOpenedForWritingAndKeepsEveryReading) {
  TempDir dir;
  const auto file = dir.path / "old.sqlite";
  fs::copy_file(kSchema1, file);
  {
    Store store(file);
    EXPECT_EQ(store.version(), cal::storage::schema_version);
    expect_schema1_readings(store);
    EXPECT_EQ(store.run(2)->status, RunStatus::incomplete);  // now marked in the file
    // New chunks beside the old ones: both read, in one order.
    store.append_readings(2, std::vector<RawReading>{{.time_ns = 999'500, .value = 9.0}});
    const auto r = store.readings(2);
    ASSERT_EQ(r.size(), 1001u);
    EXPECT_EQ(r[999].time_ns, 999'000);
    EXPECT_EQ(r[1000].value, 9.0);
  }
  Store again(file, {.read_only = true});
  EXPECT_EQ(again.run(2)->note.find("opened read-only"), std::string::npos);
  EXPECT_EQ(again.readings(2).size(), 1001u);
}

TEST(ReadOnly, AMissingFileIsAnErrorNamingItAndNothingIsCreated) {
  TempDir dir;
  const auto file = dir.path / "typo" / "site.sqlite";
  try {
    Store store(file, {.read_only = true});
    FAIL() << "opened";
  } catch (const StoreError& e) {
    EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("no such database"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir.path / "typo"));
}

TEST(ReadOnly, AnotherProgramsSqliteFileIsRefusedInEitherModeAndLeftAsItWas) {
  TempDir dir;
  const auto file = dir.path / "photos.db";
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  sqlite3_exec(db, "CREATE TABLE albums(id INTEGER, name TEXT); INSERT INTO albums VALUES(1, 'x')",
               nullptr, nullptr, nullptr);
  sqlite3_close(db);
  const auto before = bytes_of(file);
  for (bool read_only : {true, false}) {
    try {
      Store store(file, {.read_only = read_only});
      FAIL() << "opened";
    } catch (const StoreError& e) {
      EXPECT_NE(std::string(e.what()).find("not a caldaq database"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("albums"), std::string::npos) << e.what();
    }
    EXPECT_EQ(bytes_of(file), before) << read_only;
  }
  // Another program's application id is refused even with no tables.
  const auto other = dir.path / "other.db";
  ASSERT_EQ(sqlite3_open(other.c_str(), &db), SQLITE_OK);
  sqlite3_exec(db, "PRAGMA application_id = 1234", nullptr, nullptr, nullptr);
  sqlite3_close(db);
  EXPECT_THROW(Store(other, {.read_only = false}), StoreError);
  // An empty file is nothing to read (a writer would make it a new database).
  const auto empty = dir.path / "empty.sqlite";
  write_bytes(empty, "");
  EXPECT_THROW(Store(empty, {.read_only = true}), StoreError);
  EXPECT_EQ(fs::file_size(empty), 0u);
}

TEST(ReadOnly, ACleanDatabaseOpensWithoutItsWalIndexAsOnAReadOnlyMedium) {
  // A database closed cleanly has no -wal; where its -shm index cannot be created the store
  // opens it immutable. Simulated here by a -shm path that cannot be a file (a directory).
  TempDir dir;
  const auto file = dir.path / "site.sqlite";
  {
    Store store(file);
    const auto run = store.begin_run({.kind = "linear"});
    store.append_readings(run, std::vector<RawReading>{{.time_ns = 5, .value = 1.5}});
    store.finish_run(run, RunStatus::complete);
  }
  ASSERT_FALSE(fs::exists(file.string() + "-wal"));
  fs::create_directory(file.string() + "-shm");
  Store store(file, {.read_only = true});
  EXPECT_EQ(store.readings(1).at(0).value, 1.5);
  EXPECT_EQ(store.run(1)->status, RunStatus::complete);
}

// A run of several chunks and series, closed (checkpointed) so that everything is in the file.
fs::path damaged_candidate(const fs::path& dir, std::vector<RawReading>& all) {
  const auto file = dir / "site.sqlite";
  Store store(file);
  const auto run = store.begin_run({.kind = "linear", .settings_json = R"({"note": "flips"})"});
  std::mt19937_64 rng(9);
  std::int64_t t = 0;
  for (int b = 0; b < 8; ++b) {
    std::vector<RawReading> batch;
    for (int k = 0; k < 3000; ++k, t += 100'000) {
      batch.push_back({.time_ns = t, .quantity = 1, .value = 0.1 + 1e-9 * double(rng() % 5000)});
      if (k % 500 == 0)
        batch.push_back({.time_ns = t, .device = 1, .quantity = 2, .value = 20.0 + 1e-3 * b});
    }
    store.append_readings(run, batch);
  }
  store.finish_run(run, RunStatus::complete);
  all = store.readings(run);
  return file;
}

// Reads every run; true when it ended in an error (StoreError), false when it read everything.
bool read_everything(const fs::path& file, std::vector<RawReading>& got, std::string& error) {
  try {
    Store store(file, {.read_only = true});
    got = store.readings(1);
    return false;
  } catch (const StoreError& e) {
    error = e.what();
    return true;
  }
}

TEST(Integrity, AFlippedByteInAChunkIsReportedWithItsRunAndChunk) {
  TempDir dir;
  std::vector<RawReading> all;
  const auto file = damaged_candidate(dir.path, all);
  const auto clean = bytes_of(file);
  // Find where each chunk's BLOB starts in the file (its first 24 bytes are unique there).
  std::vector<std::pair<std::size_t, std::int64_t>> starts;  // file offset, seq
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open_v2(file.c_str(), &db, SQLITE_OPEN_READONLY, nullptr), SQLITE_OK);
    sqlite3_stmt* s = nullptr;
    sqlite3_prepare_v2(db, "SELECT data, seq FROM reading_chunks ORDER BY id", -1, &s, nullptr);
    while (sqlite3_step(s) == SQLITE_ROW) {
      const std::string head(static_cast<const char*>(sqlite3_column_blob(s, 0)), 24);
      const auto at = clean.find(head);
      ASSERT_NE(at, std::string::npos);
      starts.emplace_back(at, sqlite3_column_int64(s, 1));
    }
    sqlite3_finalize(s);
    sqlite3_close(db);
  }
  ASSERT_EQ(starts.size(), 16u);
  const auto copy = dir.path / "copy.sqlite";
  for (const auto& [at, seq] : starts)
    for (std::size_t k : {std::size_t{0}, std::size_t{9}, std::size_t{23}}) {
      auto b = clean;
      b[at + k] = static_cast<char>(b[at + k] ^ 0x04);
      write_bytes(copy, b);
      std::vector<RawReading> got;
      std::string error;
      ASSERT_TRUE(read_everything(copy, got, error)) << "byte " << at + k << " not detected";
      EXPECT_NE(error.find("run 1"), std::string::npos) << error;
      EXPECT_NE(error.find("reading chunk " + std::to_string(seq) + " "), std::string::npos)
          << error;
      EXPECT_NE(error.find("copy.sqlite"), std::string::npos) << error;
    }
}

TEST(Integrity, RandomByteFlipsAnywhereNeverChangeAReadingSilently) {
  // As in the issue's reproduction: 20 random flips in the file at once, many times over, and
  // single flips: each damaged copy either reads exactly the original readings or fails with
  // an error. Flips that change nothing read are fine (free space, other tables).
  TempDir dir;
  std::vector<RawReading> all;
  const auto file = damaged_candidate(dir.path, all);
  const auto clean = bytes_of(file);
  const auto copy = dir.path / "copy.sqlite";
  std::mt19937_64 rng(2024);
  int detected = 0, harmless = 0;
  for (int trial = 0; trial < 300; ++trial) {
    auto b = clean;
    const int flips = trial % 2 ? 20 : 1;
    for (int f = 0; f < flips; ++f) {
      const std::size_t at = rng() % b.size();
      b[at] = static_cast<char>(b[at] ^ static_cast<char>(1 + rng() % 255));
    }
    write_bytes(copy, b);
    std::vector<RawReading> got;
    std::string error;
    if (read_everything(copy, got, error)) {
      ++detected;
      continue;
    }
    ++harmless;
    ASSERT_EQ(got.size(), all.size()) << "trial " << trial << ": readings silently lost";
    for (std::size_t i = 0; i < all.size(); ++i)
      ASSERT_TRUE(same(got[i], all[i]))
          << "trial " << trial << ": reading " << i << " silently changed";
  }
  EXPECT_GT(detected, 100);  // most of the file is reading chunks
  RecordProperty("detected", detected);
  RecordProperty("harmless", harmless);
}

TEST(Integrity, AChunkHiddenByADamagedIndexIsReportedMissing) {
  // A chunk's row is still there but the time index no longer leads to it (as a flipped
  // byte in an index page can do): the stream compares with the other index and says so.
  TempDir dir;
  std::vector<RawReading> all;
  const auto file = damaged_candidate(dir.path, all);
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
  // Build the time index without the chunk of seq 5 (a partial index), then make the schema
  // call it a whole index: SQLite now trusts an index that lacks one entry, as damage to an
  // index page would leave it.
  ASSERT_EQ(sqlite3_exec(db,
                         "DROP INDEX reading_chunks_by_run; "
                         "CREATE INDEX reading_chunks_by_run ON reading_chunks(run_id, first_ns) "
                         "WHERE seq IS NOT 5; "
                         "PRAGMA writable_schema = ON; "
                         "UPDATE sqlite_master SET sql = 'CREATE INDEX reading_chunks_by_run ON "
                         "reading_chunks(run_id, first_ns)' WHERE name = 'reading_chunks_by_run'; "
                         "PRAGMA writable_schema = OFF;",
                         nullptr, nullptr, nullptr),
            SQLITE_OK)
      << sqlite3_errmsg(db);
  sqlite3_close(db);
  std::vector<RawReading> got;
  std::string error;
  ASSERT_TRUE(read_everything(file, got, error));
  EXPECT_NE(error.find("run 1: chunk 5 is missing"), std::string::npos) << error;
}

}  // namespace

namespace {

// Read-only, schema 1 is presented in today's shape by temporary views: the results must read
// as migration 1 -> 2 marks them (the older of two of a standard and everything before a
// re-compensation superseded), with nothing written; opened for writing, the migration gives
// the same.
TEST(ReadOnly, ASchema1DatabasesResultsReadAsTheMigrationMarksThem) {
  TempDir dir;
  const auto file = dir.path / "old.sqlite";
  fs::copy_file(kSchema1, file);
  {
    sqlite3* db = nullptr;
    ASSERT_EQ(sqlite3_open(file.c_str(), &db), SQLITE_OK);
    ASSERT_EQ(sqlite3_exec(db,
                           "INSERT INTO results(run_id, standard, json, created_unix_ms) VALUES "
                           "(1, 'ISO 230-2:2014', '{}', 2), (1, 'VDI/DGQ 3441', '{}', 3), "
                           "(1, 'ISO 230-2:2014 (recompensated)', '{}', 4)",
                           nullptr, nullptr, nullptr),
              SQLITE_OK);
    sqlite3_exec(db, "PRAGMA wal_checkpoint(TRUNCATE)", nullptr, nullptr, nullptr);
    sqlite3_close(db);
  }
  const auto before = bytes_of(file);
  std::vector<std::pair<std::string, bool>> read_only, migrated;
  {
    Store store(file, {.read_only = true});
    for (const auto& r : store.results(1)) read_only.emplace_back(r.standard, r.current());
    EXPECT_TRUE(store.missed_stops(1).empty());
    EXPECT_FALSE(store.run(1)->origin_unix_ns.has_value());
  }
  EXPECT_EQ(bytes_of(file), before);
  {
    Store store(file);
    for (const auto& r : store.results(1)) migrated.emplace_back(r.standard, r.current());
  }
  ASSERT_EQ(read_only.size(), 4u);
  EXPECT_EQ(read_only, migrated);
  // By hand: "fixture" and the first ISO 230-2 and VDI results precede the re-compensation.
  EXPECT_FALSE(read_only[0].second);
  EXPECT_FALSE(read_only[1].second);
  EXPECT_FALSE(read_only[2].second);
  EXPECT_TRUE(read_only[3].second);
}

}  // namespace
