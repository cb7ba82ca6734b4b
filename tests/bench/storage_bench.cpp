// Storage throughput: the chunked run store against a bare SQLite insert loop (one row per
// reading, prepared statement, one transaction per batch) measured in the same process, so
// the ratio is meaningful on any machine. Method: docs/benchmarks.md.
#include <benchmark/benchmark.h>
#include <sqlite3.h>
#include <unistd.h>

#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "cal/storage/store.hpp"
#include "cal/storage/writer.hpp"

namespace {

namespace fs = std::filesystem;
using cal::storage::RawReading;

fs::path temp_db(const char* name) {
  const auto p = fs::temp_directory_path() / (std::string("caldaq-bench-") + name + "-" +
                                              std::to_string(::getpid()) + ".sqlite");
  for (const char* s : {"", "-wal", "-shm"}) fs::remove(p.string() + s);
  return p;
}
void remove_db(const fs::path& p) {
  for (const char* s : {"", "-wal", "-shm"}) fs::remove(p.string() + s);
}

std::vector<RawReading> batch(std::size_t n) {
  std::vector<RawReading> v(n);
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, 1e-7);
  for (std::size_t i = 0; i < n; ++i)
    v[i] = {.time_ns = static_cast<std::int64_t>(i) * 100'000, .device = 1, .value = 0.1 + noise(rng)};
  return v;
}

constexpr std::size_t kBatch = 16384;

void BM_StoreAppendChunked(benchmark::State& state) {
  const auto path = temp_db("chunked");
  {
    cal::storage::Store store(path);
    const auto run = store.begin_run({.kind = "bench"});
    const auto b = batch(kBatch);
    for (auto _ : state) store.append_readings(run, b);
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kBatch));
  }
  remove_db(path);
}
BENCHMARK(BM_StoreAppendChunked)->Unit(benchmark::kMillisecond);

void BM_BatchWriterThread(benchmark::State& state) {
  // The producer side as the event loop sees it: push, with commits on the writer thread.
  const auto path = temp_db("writer");
  std::int64_t run = 0;
  { run = cal::storage::Store(path).begin_run({.kind = "bench"}); }
  {
    cal::storage::BatchWriter writer(path, run);
    const auto b = batch(kBatch);
    for (auto _ : state) {
      for (const auto& r : b) writer.push(r);
    }
    writer.flush();  // the last batches' commit counts too
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kBatch));
    state.counters["overload_waits"] = static_cast<double>(writer.stats().overload_waits);
  }
  remove_db(path);
}
BENCHMARK(BM_BatchWriterThread)->Unit(benchmark::kMillisecond)->UseRealTime();

// The reference: what SQLite itself does with one row per reading, same durability settings.
void BM_BareSqliteRowPerReading(benchmark::State& state) {
  const auto path = temp_db("bare");
  sqlite3* db = nullptr;
  sqlite3_open(path.c_str(), &db);
  sqlite3_exec(db, "PRAGMA journal_mode=WAL; PRAGMA synchronous=FULL;"
                   "CREATE TABLE r(run INTEGER, device INTEGER, channel INTEGER, quantity INTEGER,"
                   " t INTEGER, status INTEGER, value REAL)",
               nullptr, nullptr, nullptr);
  sqlite3_stmt* s = nullptr;
  sqlite3_prepare_v2(db, "INSERT INTO r VALUES(1, ?, ?, ?, ?, ?, ?)", -1, &s, nullptr);
  const auto b = batch(kBatch);
  for (auto _ : state) {
    sqlite3_exec(db, "BEGIN", nullptr, nullptr, nullptr);
    for (const auto& r : b) {
      sqlite3_bind_int(s, 1, r.device);
      sqlite3_bind_int(s, 2, r.channel);
      sqlite3_bind_int(s, 3, r.quantity);
      sqlite3_bind_int64(s, 4, r.time_ns);
      sqlite3_bind_int(s, 5, r.status);
      sqlite3_bind_double(s, 6, r.value);
      sqlite3_step(s);
      sqlite3_reset(s);
    }
    sqlite3_exec(db, "COMMIT", nullptr, nullptr, nullptr);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kBatch));
  sqlite3_finalize(s);
  sqlite3_close(db);
  remove_db(path);
}
BENCHMARK(BM_BareSqliteRowPerReading)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
