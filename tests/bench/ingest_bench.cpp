// End-to-end ingest benchmark (method in docs/benchmarks.md):
//   1. write a capture of a 10 kHz length stream (ten 13-byte gauge lines per 1 ms record, as a
//      USB-serial interferometer or gauge delivers them) plus 1 Hz PTU300 air lines, for
//      `seconds` of recorded time;
//   2. replay it as fast as possible through the real replay bus, the real gauge and PTU300
//      instruments (codecs, state machine), the environmental compensation of every laser
//      reading, and the batch writer into SQLite (WAL, synchronous=FULL);
//   3. report readings/s, and the peak RSS after each simulated 10 minutes (it must stay flat);
//   4. measure, in the same process, a bare SQLite insert loop (one row per reading, prepared
//      statement, 16384 rows per transaction) for the fraction.
// Usage: ingest_bench [seconds=600] [dir=/tmp]
#include <sqlite3.h>
#include <sys/resource.h>
#include <unistd.h>

#include <boost/asio/io_context.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>

#include "cal/daq/env_stage.hpp"
#include "cal/replay/capture.hpp"
#include "cal/replay/session.hpp"
#include "cal/storage/store.hpp"
#include "cal/storage/writer.hpp"
#include "line_gauge/instrument.hpp"
#include "ptu300/instrument.hpp"

namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

long rss_kib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

void write_capture(const fs::path& path, int seconds) {
  cal::replay::CaptureWriter w(path, R"({"format": "ingest bench"})");
  const auto bytes = [](const std::string& s) {
    return std::as_bytes(std::span(s.data(), s.size()));
  };
  w.event(0, 0, "opened");
  w.event(0, 1, "opened");
  std::string chunk;
  char line[32];
  for (std::int64_t ms = 0; ms < seconds * 1000LL; ++ms) {
    chunk.clear();
    for (int k = 0; k < 10; ++k) {
      std::snprintf(line, sizeof line, "%+011.6f\r\n",
                    100.0 + 1e-6 * static_cast<double>((ms * 10 + k) % 977));
      chunk += line;
    }
    w.record(ms * 1'000'000, 0, cal::replay::RecordKind::received, bytes(chunk));
    if (ms % 1000 == 0)
      w.record(ms * 1'000'000, 1, cal::replay::RecordKind::received,
               bytes("P= 1013.25 hPa T=  20.00 'C RH=  50.0 %RH\r\n"));
  }
  w.close();
}

double bare_sqlite(const fs::path& path, std::int64_t rows) {
  sqlite3* db = nullptr;
  sqlite3_open(path.c_str(), &db);
  sqlite3_exec(
      db, "PRAGMA journal_mode=WAL; PRAGMA synchronous=FULL; CREATE TABLE r(t INTEGER, v REAL)",
      nullptr, nullptr, nullptr);
  sqlite3_stmt* s = nullptr;
  sqlite3_prepare_v2(db, "INSERT INTO r VALUES(?, ?)", -1, &s, nullptr);
  const auto t0 = Clock::now();
  for (std::int64_t i = 0; i < rows;) {
    sqlite3_exec(db, "BEGIN", nullptr, nullptr, nullptr);
    for (int k = 0; k < 16384 && i < rows; ++k, ++i) {
      sqlite3_bind_int64(s, 1, i * 100'000);
      sqlite3_bind_double(s, 2, 0.1 + 1e-9 * static_cast<double>(i % 977));
      sqlite3_step(s);
      sqlite3_reset(s);
    }
    sqlite3_exec(db, "COMMIT", nullptr, nullptr, nullptr);
  }
  const double secs = std::chrono::duration<double>(Clock::now() - t0).count();
  sqlite3_finalize(s);
  sqlite3_close(db);
  return static_cast<double>(rows) / secs;
}

}  // namespace

int main(int argc, char** argv) {
  const int seconds = argc > 1 ? std::atoi(argv[1]) : 600;
  const fs::path dir = argc > 2 ? argv[2] : fs::temp_directory_path();
  const auto tag = std::to_string(::getpid());
  const fs::path capture = dir / ("caldaq-ingest-" + tag + ".cdq");
  const fs::path db = dir / ("caldaq-ingest-" + tag + ".sqlite");
  const fs::path bare = dir / ("caldaq-ingest-bare-" + tag + ".sqlite");

  auto t0 = Clock::now();
  write_capture(capture, seconds);
  std::printf("capture: %d s of a 10 kHz stream, %.1f MB, written in %.2f s\n", seconds,
              static_cast<double>(fs::file_size(capture)) / 1e6,
              std::chrono::duration<double>(Clock::now() - t0).count());

  std::int64_t run = 0;
  { run = cal::storage::Store(db).begin_run({.kind = "ingest-bench"}); }
  boost::asio::io_context io;
  cal::replay::ReplayBus bus(io, capture, 0.0);
  cal::storage::BatchWriter writer(db, run);
  cal::daq::EnvStage env({}, 0);
  std::uint64_t readings = 0;
  double sink = 0.0;
  std::int64_t next_report_ns = 600'000'000'000;
  const auto on_reading = [&](const cal::drivers::Reading& r) {
    ++readings;
    writer.push({.time_ns = r.time_ns,
                 .device = r.device,
                 .quantity = static_cast<std::uint8_t>(r.quantity),
                 .value = r.value});
    switch (r.quantity) {
      case cal::drivers::Quantity::air_temperature_degc:
        return env.add_air(r.time_ns, cal::daq::AirQuantity::temperature_degc, r.value);
      case cal::drivers::Quantity::air_pressure_pa:
        return env.add_air(r.time_ns, cal::daq::AirQuantity::pressure_pa, r.value);
      case cal::drivers::Quantity::air_humidity_pct:
        return env.add_air(r.time_ns, cal::daq::AirQuantity::humidity_pct, r.value);
      case cal::drivers::Quantity::length_m:
        sink += env.compensate(r.time_ns, r.value).length_m;
        if (r.time_ns >= next_report_ns) {
          std::printf("  at %4lld s of recorded time: peak RSS %ld KiB\n",
                      static_cast<long long>(r.time_ns / 1'000'000'000), rss_kib());
          next_report_ns += 600'000'000'000;
        }
        return;
      default:
        return;
    }
  };
  auto laser = cal::drivers::make_gauge(io, bus.transport(0, "laser"),
                                        {.device = 0, .clock = bus.clock(), .replay = true});
  auto air = cal::drivers::make_ptu300(io, bus.transport(1, "air"),
                                       {.device = 1, .clock = bus.clock(), .replay = true});
  laser->start({.reading = on_reading});
  air->start({.reading = on_reading});
  bool done = false;
  t0 = Clock::now();
  bus.start([&](const cal::replay::ReplayEnd&) { done = true; });
  while (!done) io.run_one();
  writer.flush();
  const double secs = std::chrono::duration<double>(Clock::now() - t0).count();
  const double rate = static_cast<double>(readings) / secs;
  const auto stats = writer.stats();
  std::printf(
      "ingest: %llu readings in %.2f s: %.0f readings/s (%.1f x a 50 kHz stream); "
      "committed %llu; producer waits %llu (%.2f s); peak RSS %ld KiB; checksum %.3f\n",
      static_cast<unsigned long long>(readings), secs, rate, rate / 50e3,
      static_cast<unsigned long long>(stats.readings_committed),
      static_cast<unsigned long long>(stats.overload_waits),
      std::chrono::duration<double>(stats.overload_time).count(), rss_kib(), sink);
  const double bare_rate =
      bare_sqlite(bare, static_cast<std::int64_t>(std::min<std::uint64_t>(readings, 5'000'000)));
  std::printf("bare SQLite insert loop: %.0f rows/s; ingest is %.2f x that\n", bare_rate,
              rate / bare_rate);
  for (const auto& p : {capture, db, bare})
    for (const char* s : {"", "-wal", "-shm"}) fs::remove(p.string() + s);
  return stats.readings_committed == readings ? 0 : 1;
}
