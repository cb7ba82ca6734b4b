// daq bench: benchmarks of this machine (method in docs/benchmarks.md).
//
// daq bench ingest: the end-to-end ingest benchmark with its ceilings measured in the same run.
//
//   1. A capture of `seconds` of a 10 kHz length stream (ten 13-byte gauge lines per 1 ms
//      record, as a USB-serial gauge or interferometer delivers them) plus 1 Hz PTU300 air
//      lines is written once.
//   2. Each round replays it as fast as possible through the real replay bus, the real gauge
//      and PTU300 instruments (codecs, state machines), the environmental compensation of every
//      length reading and the batch writer into a fresh SQLite store (WAL, synchronous=FULL).
//   3. In the same round, the two ceilings for the bytes that ingest stored:
//      - blob insert: the very rows ingest wrote (every column, the chunk BLOBs as stored) are
//        inserted into a fresh store with the same schema and settings, committing at the same
//        points (one transaction per writer batch), with nothing else to do: what SQLite
//        itself costs for those bytes;
//      - raw write: the same BLOB bytes written to a plain file with one fdatasync per commit.
//      The rows are read from the ingest database untimed, one commit's worth at a time.
//   4. Also the pipeline alone (no storage) for where the time goes.
// Rounds alternate ingest and ceilings so that a change of load on the machine touches both;
// the fraction is the median of the per-round ratios.
//
// daq bench export: memory and time after the run. A store is filled with runs of a 10 kHz
// length stream plus 1 Hz air (temperature, pressure, humidity), written as the batch writer
// writes them, of 1/k ... k/k of the given length; `daq export` (CSV and JSON) and `daq report`
// are run on each as child processes of this same binary, and each child's peak RSS (wait4)
// and wall time are reported: flat memory and linear time are what is asked. Each length is
// generated twice (--values both): quantised as a 1 nm gauge's driver stores it, as real
// readings are stored, and unquantised (16 - 17 digits); --peer-daq measures another build's
// exports of the same runs beside this one's.
#include <fcntl.h>
#include <fmt/format.h>
#include <pthread.h>
#include <sched.h>
#include <spawn.h>
#include <sqlite3.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include "bench_common.hpp"
#include "cal/analysis/error.hpp"
#include "cal/daq/env_stage.hpp"
#include "cal/drivers/codec/common.hpp"
#include "cal/drivers/registry.hpp"
#include "cal/replay/capture.hpp"
#include "cal/replay/session.hpp"
#include "cal/storage/chunk.hpp"
#include "cal/storage/pg/copy_ceiling.hpp"
#include "cal/storage/pg/sync.hpp"
#include "cal/storage/store.hpp"
#include "cal/storage/writer.hpp"
#include "cli_checks.hpp"
#include "command.hpp"
#include "commands.hpp"

namespace daq {
namespace bench {  // shared with daq bench replay (bench_common.hpp)

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// CPU time (user and system) of the process, or of this thread (RUSAGE_THREAD: the ceilings').
double cpu_seconds(int who = RUSAGE_SELF) {
  rusage u{};
  getrusage(who, &u);
  return static_cast<double>(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
         1e-6 * static_cast<double>(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

long peak_rss_kib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

long current_rss_kib() {
  std::ifstream statm("/proc/self/statm");
  long pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * (::sysconf(_SC_PAGESIZE) / 1024);
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

void remove_db(const fs::path& p) {
  for (const char* s : {"", "-wal", "-shm"}) fs::remove(p.string() + s);
}

void write_capture(const fs::path& path, int seconds) {
  cal::replay::CaptureWriter w(path, R"({"format": "daq bench ingest"})");
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
  // On the disk before the rounds: otherwise the first rounds' commits wait behind the
  // writeback of the capture's dirty pages (hundreds of MB), a cost of the set-up, not of
  // ingest or the ceilings.
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd >= 0) {
    ::fsync(fd);
    ::close(fd);
  }
}

// Runs this thread on `cpu` until destroyed, then where it ran before.
class PinThisThread {
 public:
  explicit PinThisThread(int cpu) {
    if (cpu < 0) return;
    if (pthread_getaffinity_np(pthread_self(), sizeof before_, &before_) != 0)
      throw cal::InputError("bench: cannot read the event loop's CPU affinity");
    cpu_set_t set;
    CPU_ZERO(&set);
    CPU_SET(cpu, &set);
    if (pthread_setaffinity_np(pthread_self(), sizeof set, &set) != 0)
      throw cal::InputError(fmt::format("bench: cannot run the event loop on CPU {}", cpu));
    active_ = true;
  }
  ~PinThisThread() {
    if (active_) pthread_setaffinity_np(pthread_self(), sizeof before_, &before_);
  }
  PinThisThread(const PinThisThread&) = delete;
  PinThisThread& operator=(const PinThisThread&) = delete;

 private:
  cpu_set_t before_{};
  bool active_ = false;
};

// The ingest pipeline; `db` empty: the pipeline alone, readings go nowhere.
IngestResult ingest(const fs::path& capture, const fs::path& db, std::size_t batch_readings,
                    Placement where) {
  IngestResult res;
  std::int64_t run = 0;
  std::unique_ptr<cal::storage::BatchWriter> writer;
  if (!db.empty()) {
    run = cal::storage::Store(db).begin_run({.kind = "bench"});
    cal::storage::WriterOptions options{.batch_readings = batch_readings};
    if (where.pinned()) {
      options.writer_cpus = {where.storage_cpu};
      options.encoder_cpus = {where.storage_cpu};
    }
    writer = std::make_unique<cal::storage::BatchWriter>(db, run, options);
  }
  const PinThisThread pin(where.loop_cpu);
  boost::asio::io_context io;
  cal::replay::ReplayBus bus(io, capture, 0.0);
  cal::daq::EnvStage env({}, 0);
  std::int64_t next_mark_ns = 600'000'000'000;
  const auto on_reading = [&](const cal::drivers::Reading& r) {
    ++res.readings;
    if (writer)
      writer->push({.time_ns = r.time_ns,
                    .device = r.device,
                    .channel = r.channel,
                    .quantity = static_cast<std::uint8_t>(r.quantity),
                    .status = static_cast<std::uint8_t>(r.status),
                    .value = r.value});
    switch (r.quantity) {
      case cal::drivers::Quantity::air_temperature_degc:
        return env.add_air(r.time_ns, cal::daq::AirQuantity::temperature_degc, r.value);
      case cal::drivers::Quantity::air_pressure_pa:
        return env.add_air(r.time_ns, cal::daq::AirQuantity::pressure_pa, r.value);
      case cal::drivers::Quantity::air_humidity_pct:
        return env.add_air(r.time_ns, cal::daq::AirQuantity::humidity_pct, r.value);
      case cal::drivers::Quantity::length_m:
        res.checksum += env.compensated_length_m(r.time_ns, r.value);
        if (r.time_ns >= next_mark_ns) {
          res.rss_marks.emplace_back(static_cast<int>(r.time_ns / 60'000'000'000),
                                     current_rss_kib());
          next_mark_ns += 600'000'000'000;
        }
        return;
      default:
        return;
    }
  };
  // The benchmark's workload is a line gauge and a PTU300 with their default options, made by
  // the registry as a run makes them.
  const auto instrument = [&](std::string_view driver, std::uint16_t device, const char* role) {
    const auto& d = cal::drivers::driver(driver);
    return d.make_instrument(io, bus.transport(device, role),
                             {.device = device, .clock = bus.clock(), .replay = true},
                             cal::drivers::options_from_text(d, {}), {.role = role});
  };
  // The gauge's readings come a chunk at a time (ten lines per capture record): one call, one
  // hand-over to the writer, then the compensation of each, as a run's storage stage would do.
  std::vector<cal::storage::RawReading> raw;
  const auto on_lengths = [&](std::span<const cal::drivers::Reading> rs) {
    ++res.handovers;
    res.readings += rs.size();
    if (writer) {
      raw.resize(rs.size());  // capacity kept: no allocation, no per-reading call
      for (std::size_t i = 0; i < rs.size(); ++i)
        raw[i] = {.time_ns = rs[i].time_ns,
                  .device = rs[i].device,
                  .channel = rs[i].channel,
                  .quantity = static_cast<std::uint8_t>(rs[i].quantity),
                  .status = static_cast<std::uint8_t>(rs[i].status),
                  .value = rs[i].value};
      writer->push(raw);
    }
    for (const auto& r : rs) res.checksum += env.compensated_length_m(r.time_ns, r.value);
    if (!rs.empty() && rs.back().time_ns >= next_mark_ns) {
      res.rss_marks.emplace_back(static_cast<int>(rs.back().time_ns / 60'000'000'000),
                                 current_rss_kib());
      next_mark_ns += 600'000'000'000;
    }
  };
  auto laser = instrument("gauge", std::uint16_t{0}, "laser");
  auto air = instrument("ptu300", std::uint16_t{1}, "air");
  laser->start({.reading = on_reading, .readings = on_lengths});
  air->start({.reading = on_reading});
  bool done = false;
  const double cpu0 = cpu_seconds();
  const auto t0 = Clock::now();
  bus.start([&](const cal::replay::ReplayEnd&) { done = true; });
  while (!done) io.run_one();
  if (writer) {
    writer->flush();
    res.writer = writer->stats();
  }
  res.wall_s = seconds_since(t0);
  res.cpu_s = cpu_seconds() - cpu0;
  return res;
}

}  // namespace bench
namespace {
using namespace bench;

struct SqliteDb {
  sqlite3* db = nullptr;
  explicit SqliteDb(const fs::path& p) {
    if (sqlite3_open_v2(p.c_str(), &db, SQLITE_OPEN_READWRITE, nullptr) != SQLITE_OK)
      throw cal::InputError(fmt::format("{}: cannot open: {}", p.string(), sqlite3_errmsg(db)));
    sqlite3_busy_timeout(db, 5000);
  }
  ~SqliteDb() { sqlite3_close_v2(db); }
  SqliteDb(const SqliteDb&) = delete;
  SqliteDb& operator=(const SqliteDb&) = delete;
  void exec(const char* sql) const {
    if (sqlite3_exec(db, sql, nullptr, nullptr, nullptr) != SQLITE_OK)
      throw cal::InputError(fmt::format("bench: {}: {}", sql, sqlite3_errmsg(db)));
  }
};

struct Stmt {
  sqlite3_stmt* s = nullptr;
  Stmt(const SqliteDb& db, const std::string& sql) {
    if (sqlite3_prepare_v2(db.db, sql.c_str(), -1, &s, nullptr) != SQLITE_OK)
      throw cal::InputError(fmt::format("bench: {}: {}", sql, sqlite3_errmsg(db.db)));
  }
  ~Stmt() { sqlite3_finalize(s); }
  Stmt(const Stmt&) = delete;
  Stmt& operator=(const Stmt&) = delete;
};

// One stored chunk row, every column as SQLite holds it.
struct Row {
  std::vector<sqlite3_value*> values;
  Row() = default;
  Row(const Row&) = delete;
  Row& operator=(const Row&) = delete;
  Row(Row&& o) noexcept : values(std::move(o.values)) {}
  ~Row() {
    for (auto* v : values) sqlite3_value_free(v);
  }
};

// Reads the chunk rows of the ingest database in the order they were written, one commit's
// worth (`batch_readings` readings, as the writer cut them) per call.
class ChunkSource {
 public:
  ChunkSource(const fs::path& db, std::size_t batch_readings)
      : db_(db), batch_(batch_readings), stmt_(db_, "SELECT * FROM reading_chunks ORDER BY id") {
    columns_ = sqlite3_column_count(stmt_.s);
    for (int i = 0; i < columns_; ++i) {
      names_.push_back(sqlite3_column_name(stmt_.s, i));
      if (names_.back() == "count") count_column_ = i;
      if (names_.back() == "data") data_column_ = i;
    }
  }
  const std::vector<std::string>& names() const { return names_; }
  int data_column() const { return data_column_; }
  bool next_commit(std::vector<Row>& rows) {
    rows.clear();
    std::size_t readings = 0;
    // (A statement stepped after SQLITE_DONE starts again from the first row.)
    while (!done_ && readings < batch_) {
      if (sqlite3_step(stmt_.s) != SQLITE_ROW) {
        done_ = true;
        break;
      }
      Row r;
      for (int i = 0; i < columns_; ++i)
        r.values.push_back(sqlite3_value_dup(sqlite3_column_value(stmt_.s, i)));
      readings += static_cast<std::size_t>(sqlite3_column_int64(stmt_.s, count_column_));
      rows.push_back(std::move(r));
    }
    return !rows.empty();
  }

 private:
  SqliteDb db_;
  std::size_t batch_;
  Stmt stmt_;
  int columns_ = 0, count_column_ = 0, data_column_ = 0;
  bool done_ = false;
  std::vector<std::string> names_;
};

struct CeilingResult {
  double seconds = 0.0;
  double cpu_s = 0.0;  // of the timed parts (SQLite's or the kernel's own work, user and system)
  std::uint64_t commits = 0, bytes = 0;
};

// The same rows into a fresh store (same schema and settings), same commits, nothing else.
// The schema-1 form of a stored chunk: its readings as 17-byte records (for the comparison
// of what the denser encoding does to the ceiling).
std::vector<unsigned char> as_schema1(const ChunkSource& src, const Row& r) {
  const auto value = [&](const char* name) {
    const auto& names = src.names();
    const auto i =
        static_cast<std::size_t>(std::find(names.begin(), names.end(), name) - names.begin());
    return r.values.at(i);
  };
  auto* data = value("data");
  std::vector<cal::storage::RawReading> readings;
  cal::storage::chunk::decode(sqlite3_value_int(value("encoding")),
                              {static_cast<const unsigned char*>(sqlite3_value_blob(data)),
                               static_cast<std::size_t>(sqlite3_value_bytes(data))},
                              static_cast<std::size_t>(sqlite3_value_int64(value("count"))), 0, 0,
                              0, readings);
  std::vector<unsigned char> out(readings.size() * 17);
  for (std::size_t i = 0; i < readings.size(); ++i) {
    std::memcpy(&out[17 * i], &readings[i].time_ns, 8);
    out[17 * i + 8] = readings[i].status;
    std::memcpy(&out[17 * i + 9], &readings[i].value, 8);
  }
  return out;
}

// schema1: the chunks' BLOBs replaced by the 17-byte records of schemas 1 and 2 (prepared untimed).
CeilingResult blob_ceiling(const fs::path& from, const fs::path& to, std::size_t batch,
                           bool schema1 = false) {
  { cal::storage::Store(to).begin_run({.kind = "bench"}); }
  ChunkSource src(from, batch);
  SqliteDb dst(to);
  dst.exec("PRAGMA synchronous=FULL");
  std::string sql = "INSERT INTO reading_chunks VALUES(";
  for (std::size_t i = 0; i < src.names().size(); ++i) sql += i ? ", ?" : "?";
  sql += ")";
  Stmt insert(dst, sql);
  Stmt begin(dst, "BEGIN IMMEDIATE"), commit(dst, "COMMIT");
  CeilingResult res;
  std::vector<Row> rows;
  std::vector<std::vector<unsigned char>> old_blobs;
  const auto data_column = static_cast<std::size_t>(src.data_column());
  while (src.next_commit(rows)) {
    old_blobs.clear();
    if (schema1)
      for (const auto& r : rows) old_blobs.push_back(as_schema1(src, r));
    const auto t0 = Clock::now();
    const double cpu0 = cpu_seconds(RUSAGE_THREAD);
    sqlite3_step(begin.s);
    sqlite3_reset(begin.s);
    for (std::size_t k = 0; k < rows.size(); ++k) {
      const auto& r = rows[k];
      for (std::size_t i = 0; i < r.values.size(); ++i) {
        if (schema1 && i == data_column) {
          sqlite3_bind_blob64(insert.s, static_cast<int>(i + 1), old_blobs[k].data(),
                              old_blobs[k].size(), SQLITE_STATIC);
          res.bytes += old_blobs[k].size();
        } else {
          sqlite3_bind_value(insert.s, static_cast<int>(i + 1), r.values[i]);
        }
      }
      if (sqlite3_step(insert.s) != SQLITE_DONE)
        throw cal::InputError(
            fmt::format("bench: blob ceiling insert: {}", sqlite3_errmsg(dst.db)));
      sqlite3_reset(insert.s);
    }
    if (sqlite3_step(commit.s) != SQLITE_DONE)
      throw cal::InputError(fmt::format("bench: blob ceiling commit: {}", sqlite3_errmsg(dst.db)));
    sqlite3_reset(commit.s);
    res.seconds += seconds_since(t0);
    res.cpu_s += cpu_seconds(RUSAGE_THREAD) - cpu0;
    ++res.commits;
  }
  return res;
}

// The chunk BLOB bytes to a plain file, one fdatasync per commit.
CeilingResult raw_ceiling(const fs::path& from, const fs::path& to, std::size_t batch) {
  ChunkSource src(from, batch);
  const int fd = ::open(to.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  if (fd < 0) throw cal::InputError(fmt::format("{}: cannot create", to.string()));
  CeilingResult res;
  std::vector<Row> rows;
  while (src.next_commit(rows)) {
    const auto t0 = Clock::now();
    for (const auto& r : rows) {
      auto* v = r.values[static_cast<std::size_t>(src.data_column())];
      const auto n = static_cast<std::size_t>(sqlite3_value_bytes(v));
      if (::write(fd, sqlite3_value_blob(v), n) != static_cast<ssize_t>(n)) {
        ::close(fd);
        throw cal::InputError(fmt::format("{}: write failed", to.string()));
      }
      res.bytes += n;
    }
    ::fdatasync(fd);
    res.seconds += seconds_since(t0);
    ++res.commits;
  }
  ::close(fd);
  return res;
}

struct BenchOptions {
  int seconds = 600;
  int rounds = 3;
  std::string dir;
  std::size_t batch_readings = 16384;
  int loop_cpu = -1, storage_cpu = -1;  // both set: each round also ingests with them pinned
};

void bench_ingest(const BenchOptions& o) {
  if (o.seconds < 1 || o.rounds < 1)
    throw cal::InputError("bench ingest: --seconds and --rounds must be at least 1");
  if (o.batch_readings < 1 || o.batch_readings > 10'000'000)
    throw cal::InputError(
        fmt::format("bench ingest: --batch {}: expected 1 to 10000000 readings", o.batch_readings));
  if ((o.loop_cpu < 0) != (o.storage_cpu < 0))
    throw cal::InputError("bench ingest: give both --loop-cpu and --storage-cpu, or neither");
  if (o.loop_cpu >= 0) {  // before the capture is written: a wrong CPU fails at once
    cal::storage::check_cpus(std::vector<int>{o.loop_cpu, o.storage_cpu});
    const PinThisThread trial(o.loop_cpu);
  }
  const fs::path dir = o.dir.empty() ? fs::temp_directory_path() : fs::path(o.dir);
  const auto tag = std::to_string(::getpid());
  const fs::path capture = dir / ("caldaq-bench-" + tag + ".cdq");
  const fs::path db = dir / ("caldaq-bench-" + tag + ".sqlite");
  const fs::path copy = dir / ("caldaq-bench-ceiling-" + tag + ".sqlite");
  const fs::path raw = dir / ("caldaq-bench-raw-" + tag + ".bin");
  const Cleanup cleanup({capture, db, copy, raw});

  auto t0 = Clock::now();
  write_capture(capture, o.seconds);
  fmt::print(
      "capture: {} s of a 10 kHz gauge stream and 1 Hz PTU300 lines, {:.1f} MB, written "
      "in {:.2f} s\n",
      o.seconds, static_cast<double>(fs::file_size(capture)) / 1e6, seconds_since(t0));

  std::vector<double> ingest_rate, blob_rate, raw_rate, pipeline_rate, ratio_blob, ratio_raw;
  std::vector<double> blob17_rate, pinned_rate, ratio_pinned;
  const Placement where{.loop_cpu = o.loop_cpu, .storage_cpu = o.storage_cpu};
  double bytes_per_reading = 0.0, file_bytes_per_reading = 0.0;
  std::vector<double> per_core;
  for (int round = 1; round <= o.rounds; ++round) {
    remove_db(db);
    const auto in = ingest(capture, db, o.batch_readings);
    const auto n = static_cast<double>(in.readings);
    remove_db(copy);
    const auto blob = blob_ceiling(db, copy, o.batch_readings);
    remove_db(copy);
    const auto blob17 = blob_ceiling(db, copy, o.batch_readings, true);
    const auto bare = raw_ceiling(db, raw, o.batch_readings);
    const auto alone = ingest(capture, {}, o.batch_readings);
    bytes_per_reading = static_cast<double>(bare.bytes) / n;
    file_bytes_per_reading =
        static_cast<double>(fs::file_size(db) + (fs::exists(db.string() + "-wal")
                                                     ? fs::file_size(db.string() + "-wal")
                                                     : 0)) /
        n;
    ingest_rate.push_back(n / in.wall_s);
    blob_rate.push_back(n / blob.seconds);
    blob17_rate.push_back(n / blob17.seconds);
    raw_rate.push_back(n / bare.seconds);
    pipeline_rate.push_back(n / alone.wall_s);
    ratio_blob.push_back(blob.seconds / in.wall_s);
    ratio_raw.push_back(bare.seconds / in.wall_s);
    per_core.push_back(n / in.cpu_s);
    fmt::print(
        "round {}: ingest {:.0f} readings/s ({} readings in {:.2f} s, CPU {:.2f} s, {} gauge "
        "hand-overs, {} commits, encoder {:.2f} s and writer {:.2f} s busy, producer waits {}); "
        "blob-insert ceiling {:.0f}/s ({} commits, {:.2f} s, CPU {:.2f} s; {:.0f}/s with schema-1 "
        "records); raw write ceiling {:.0f}/s; pipeline without storage {:.0f}/s (CPU {:.2f} s); "
        "checksum {:.6f}\n",
        round, n / in.wall_s, in.readings, in.wall_s, in.cpu_s, in.handovers,
        in.writer.batches_committed, std::chrono::duration<double>(in.writer.encode_time).count(),
        std::chrono::duration<double>(in.writer.store_time).count(), in.writer.overload_waits,
        n / blob.seconds, blob.commits, blob.seconds, blob.cpu_s, n / blob17.seconds,
        n / bare.seconds, n / alone.wall_s, alone.cpu_s, in.checksum);
    if (where.pinned()) {  // the same ingest, its threads placed; the same ceiling
      remove_db(db);
      const auto p = ingest(capture, db, o.batch_readings, where);
      if (p.readings != in.readings || p.checksum != in.checksum)
        throw cal::InputError("bench: the pinned ingest did not give the same readings");
      pinned_rate.push_back(n / p.wall_s);
      ratio_pinned.push_back(blob.seconds / p.wall_s);
      fmt::print(
          "round {}: pinned (event loop on CPU {}, encoder and writer on CPU {}): ingest {:.0f} "
          "readings/s ({:.2f} s, CPU {:.2f} s, encoder {:.2f} s and writer {:.2f} s busy, "
          "producer waits {}): {:.0f} % of the blob-insert ceiling\n",
          round, where.loop_cpu, where.storage_cpu, n / p.wall_s, p.wall_s, p.cpu_s,
          std::chrono::duration<double>(p.writer.encode_time).count(),
          std::chrono::duration<double>(p.writer.store_time).count(), p.writer.overload_waits,
          100.0 * blob.seconds / p.wall_s);
    }
    if (in.writer.readings_committed != in.readings)
      throw cal::InputError(fmt::format("bench: {} readings ingested but {} committed", in.readings,
                                        in.writer.readings_committed));
    if (round == 1) {
      std::string marks;
      for (const auto& [minute, kib] : in.rss_marks)
        marks += fmt::format("{}{} min: {} KiB", marks.empty() ? "" : ", ", minute, kib);
      fmt::print("  RSS at each 10 minutes of recorded time: {}; peak RSS {} KiB\n",
                 marks.empty() ? "(run shorter than 10 min)" : marks, peak_rss_kib());
    }
  }
  fmt::print(
      "\nmedians over {} rounds:\n"
      "  ingest                    {:>12.0f} readings/s\n"
      "  blob-insert ceiling       {:>12.0f} readings/s  ingest reaches {:.0f} % of it\n"
      "  raw write ceiling         {:>12.0f} readings/s  ingest reaches {:.0f} % of it\n"
      "  pipeline without storage  {:>12.0f} readings/s\n"
      "  (blob-insert ceiling of the same readings as schema-1 17-byte records: {:.0f} "
      "readings/s)\n"
      "  stored                    {:.2f} bytes/reading in the chunk BLOBs, {:.2f} in the "
      "file: {:.0f} MB per hour of a 10 kHz channel\n"
      "  one core (process CPU time, producer and writer threads) ingests {:.0f} readings/s: "
      "{:.0f} channels at 10 kHz, {:.1f} at 100 kHz\n",
      o.rounds, median(ingest_rate), median(blob_rate), 100.0 * median(ratio_blob),
      median(raw_rate), 100.0 * median(ratio_raw), median(pipeline_rate), median(blob17_rate),
      bytes_per_reading, file_bytes_per_reading, file_bytes_per_reading * 36e6 / 1e6,
      median(per_core), median(per_core) / 1e4, median(per_core) / 1e5);
  if (where.pinned())
    fmt::print(
        "  pinned (event loop on CPU {}, encoder and writer on CPU {}): ingest {:.0f} "
        "readings/s, {:.0f} % of the blob-insert ceiling\n",
        where.loop_cpu, where.storage_cpu, median(pinned_rate), 100.0 * median(ratio_pinned));
}

// The generated readings' values: exactly as a real instrument's driver stores them, or not.
enum class BenchValues {
  // The length as `daq bench ingest`'s gauge prints it ("%+011.6f" mm: 1 nm, six decimals of a
  // millimetre) and the line-gauge driver stores it: the printed decimal in metres as one
  // correctly rounded division (parse_plain_decimal_scaled: the integer nanometres / 10^9); the
  // air as a PTU300 prints it ("P= 1013.25 hPa T=  20.00 'C RH=  50.0 %RH": the hPa decimal in
  // Pa, two decimals of degC, one of %RH). What a store holds: raw readings, at
  // the instrument's resolution, each the correctly rounded double of its decimal in SI.
  quantised,
  // 0.1 + 1e-6 sin(...) + 1e-9 k computed in doubles: 16 - 17 significant digits a value, as
  // no instrument stores them (a compensated length would be; the store holds none).
  unquantised,
};

// `value` printed with `decimals` decimals in a unit 10^exponent_to_si of SI, as a driver
// stores it: the printed decimal in SI, correctly rounded (the count over the exact power of
// ten, cal::drivers::codec::scaled_count; docs/codecs.md, "Readings in SI").
double as_printed(double value, int decimals, int exponent_to_si) {
  const double scale = std::pow(10.0, decimals);  // exact for decimals <= 22
  return cal::drivers::codec::scaled_count(std::llround(value * scale),
                                           {1, exponent_to_si - decimals});
}

// A run of `seconds` of a 10 kHz length stream (device 0) and 1 Hz air (device 1), stored in
// batches of 16384 readings as the batch writer stores them. Not timed: this is the input.
std::int64_t generate_run(cal::storage::Store& store, int seconds,
                          BenchValues values = BenchValues::unquantised) {
  const bool quantised = values == BenchValues::quantised;
  const auto run = store.begin_run(
      {.campaign = "daq bench export",
       .kind = "bench",
       .axis = "X",
       .settings_json = quantised ? R"({"generated": "daq bench export", "values": "quantised"})"
                                  : R"({"generated": "daq bench export"})"});
  store.add_instrument({.run_id = run, .device = 0, .driver = "gauge", .transport = "generated"});
  store.add_instrument({.run_id = run, .device = 1, .driver = "ptu300", .transport = "generated"});
  std::vector<cal::storage::RawReading> batch;
  batch.reserve(16384 + 3);
  const std::int64_t n = static_cast<std::int64_t>(seconds) * 10'000;
  for (std::int64_t i = 0; i < n; ++i) {
    const std::int64_t t = i * 100'000;
    const double length_m =
        0.1 + 1e-6 * std::sin(1e-4 * static_cast<double>(i)) + 1e-9 * static_cast<double>(i % 977);
    batch.push_back({.time_ns = t,
                     .quantity = 1,
                     .value = quantised ? as_printed(length_m * 1e3, 6, -3) : length_m});
    if (i % 10'000 == 0) {
      const double s = static_cast<double>(i / 10'000);
      const double air[3] = {20.0 + 1e-3 * s, 101325.0 - 0.1 * s, 45.0 + 1e-2 * s};
      batch.push_back({.time_ns = t,
                       .device = 1,
                       .quantity = 2,
                       .value = quantised ? as_printed(air[0], 2, 0) : air[0]});
      batch.push_back({.time_ns = t,
                       .device = 1,
                       .quantity = 3,
                       .value = quantised ? as_printed(air[1] / 100.0, 2, 2) : air[1]});
      batch.push_back({.time_ns = t,
                       .device = 1,
                       .quantity = 4,
                       .value = quantised ? as_printed(air[2], 1, 0) : air[2]});
    }
    if (batch.size() >= 16384) {
      store.append_readings(run, batch);
      batch.clear();
    }
  }
  store.append_readings(run, batch);
  store.finish_run(run, cal::storage::RunStatus::complete);
  return run;
}

}  // namespace
namespace bench {
// Runs this daq binary with `args`, its output (stdout and stderr) to `output`: its wall time,
// CPU and peak RSS (wait4) and how it exited.
ChildResult spawn_child(const std::vector<std::string>& args, const std::string& output) {
  return spawn_program("/proc/self/exe", args, output);
}

ChildResult spawn_program(const std::string& program, const std::vector<std::string>& args,
                          const std::string& output) {
  std::vector<char*> argv;
  std::string self = program;
  argv.push_back(self.data());
  std::vector<std::string> copy = args;
  for (auto& a : copy) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, output.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  const auto t0 = Clock::now();
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, program.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw cal::InputError(fmt::format("bench: cannot start daq: {}", std::strerror(rc)));
  int status = 0;
  rusage usage{};
  if (::wait4(pid, &status, 0, &usage) != pid)
    throw cal::InputError(fmt::format("bench: lost daq {}", fmt::join(args, " ")));
  const auto tv = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec);
  };
  return {.seconds = seconds_since(t0),
          .cpu_s = tv(usage.ru_utime) + tv(usage.ru_stime),
          .peak_rss_kib = usage.ru_maxrss,
          .exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1};
}

ChildResult run_child(const std::vector<std::string>& args) {
  return run_program("/proc/self/exe", args);
}

ChildResult run_program(const std::string& program, const std::vector<std::string>& args) {
  auto r = spawn_program(program, args, "/dev/null");
  if (r.exit_code != 0)
    throw cal::InputError(
        fmt::format("bench: daq {} failed (exit {})", fmt::join(args, " "), r.exit_code));
  return r;
}
}  // namespace bench
namespace {

// The ceiling of an export, measured in this process beside it: what any export must do at the
// least, read the run's readings from the store (every chunk decoded, nothing formatted) and
// write as many bytes as the export wrote (its own first 64 KiB, repeated, to a file in the same
// directory). CPU seconds (this thread) and wall seconds of each.
struct ExportCeiling {
  double read_s = 0.0, read_cpu_s = 0.0, write_s = 0.0, write_cpu_s = 0.0;
};

ExportCeiling export_ceiling(const fs::path& db, std::int64_t run, const fs::path& exported,
                             const fs::path& scratch) {
  ExportCeiling c;
  {
    auto t0 = Clock::now();
    double cpu0 = cpu_seconds(RUSAGE_THREAD);
    cal::storage::Store store(db, {.read_only = true});
    auto stream = store.stream_readings(run);
    std::vector<cal::storage::RawReading> batch;
    // next() decodes each chunk in the storage library: nothing here for a compiler to drop.
    while (stream.next(batch)) {
    }
    c.read_s = seconds_since(t0);
    c.read_cpu_s = cpu_seconds(RUSAGE_THREAD) - cpu0;
  }
  const auto bytes = fs::file_size(exported);
  std::vector<char> block(1 << 16);
  {
    std::FILE* in = std::fopen(exported.c_str(), "rb");
    if (!in) throw cal::InputError(fmt::format("bench: cannot read {}", exported.string()));
    block.resize(std::fread(block.data(), 1, block.size(), in));
    std::fclose(in);
  }
  if (block.empty()) return c;
  const auto t0 = Clock::now();
  const double cpu0 = cpu_seconds(RUSAGE_THREAD);
  std::FILE* out = std::fopen(scratch.c_str(), "wb");
  if (!out) throw cal::InputError(fmt::format("bench: cannot write {}", scratch.string()));
  for (std::uintmax_t left = bytes; left > 0;) {
    const auto n = std::min<std::uintmax_t>(left, block.size());
    std::fwrite(block.data(), 1, n, out);
    left -= n;
  }
  std::fclose(out);
  c.write_s = seconds_since(t0);
  c.write_cpu_s = cpu_seconds(RUSAGE_THREAD) - cpu0;
  return c;
}

struct ExportBenchOptions {
  int minutes = 60;
  int steps = 4;
  std::string dir;
  std::string keep;             // the generated database, kept under this name
  std::string values = "both";  // quantised | unquantised | both (a run of each, in turn)
  std::string peer;             // another daq binary whose exports are measured alternately
  int repeat = 1;               // rounds of each export and its ceiling
};

// Whether two files hold the same bytes.
bool same_bytes(const fs::path& a, const fs::path& b) {
  if (fs::file_size(a) != fs::file_size(b)) return false;
  std::ifstream x(a, std::ios::binary), y(b, std::ios::binary);
  std::vector<char> bx(1 << 16), by(1 << 16);
  while (x && y) {
    x.read(bx.data(), static_cast<std::streamsize>(bx.size()));
    y.read(by.data(), static_cast<std::streamsize>(by.size()));
    if (x.gcount() != y.gcount() || !std::equal(bx.begin(), bx.begin() + x.gcount(), by.begin()))
      return false;
  }
  return true;
}

// One export's CPU time and its ceiling's in each round (--repeat), of one run and format by one
// binary.
struct ExportRounds {
  std::string what;  // "10.0 min q csv  this"
  std::vector<double> export_cpu_s, ceiling_cpu_s;
};

// "min 0.52 s, median 0.60 s" of CPU times.
std::string min_and_median(const std::vector<double>& v) {
  return fmt::format("min {:.2f} s, median {:.2f} s", *std::min_element(v.begin(), v.end()),
                     median(v));
}

// The summary of --repeat: for each export, the least and the median CPU of it and of its
// ceiling, and the % from each (the least ceiling against the least export: the rounds the
// machine's noise touched least; the medians: the usual round).
void print_repeated(const std::vector<ExportRounds>& all, int repeat) {
  fmt::print(
      "\nrepeated {} times (each round: the export, then its ceiling; with --peer-daq the other "
      "binary's export and its ceiling in the same round, which of the two goes first swapped "
      "every round); CPU:\n",
      repeat);
  for (const auto& e : all) {
    const double min_export = *std::min_element(e.export_cpu_s.begin(), e.export_cpu_s.end());
    const double min_ceiling = *std::min_element(e.ceiling_cpu_s.begin(), e.ceiling_cpu_s.end());
    std::vector<std::string> per_round;
    for (std::size_t i = 0; i < e.export_cpu_s.size(); ++i)
      per_round.push_back(fmt::format("{:.0f}", 100.0 * e.ceiling_cpu_s[i] / e.export_cpu_s[i]));
    fmt::print(
        "  {}: export {}; ceiling {}: {:.0f} % by the mins, {:.0f} % by the medians (per round: "
        "{} %)\n",
        e.what, min_and_median(e.export_cpu_s), min_and_median(e.ceiling_cpu_s),
        100.0 * min_ceiling / min_export, 100.0 * median(e.ceiling_cpu_s) / median(e.export_cpu_s),
        fmt::join(per_round, ", "));
  }
}

void bench_export(const ExportBenchOptions& o) {
  if (o.minutes < 1 || o.steps < 1)
    throw cal::InputError("bench export: --minutes and --steps must be at least 1");
  if (o.repeat < 1) throw cal::InputError("bench export: --repeat must be at least 1");
  const fs::path dir = o.dir.empty() ? fs::temp_directory_path() : fs::path(o.dir);
  const auto tag = std::to_string(::getpid());
  const fs::path db =
      o.keep.empty() ? dir / ("caldaq-bench-export-" + tag + ".sqlite") : fs::path(o.keep);
  const fs::path html = dir / ("caldaq-bench-report-" + tag + ".html");
  const fs::path exported = dir / ("caldaq-bench-export-" + tag + ".out");
  const fs::path exported_peer = dir / ("caldaq-bench-export-" + tag + ".peer");
  const fs::path scratch = dir / ("caldaq-bench-ceiling-" + tag + ".out");
  const Cleanup cleanup(o.keep.empty()
                            ? std::vector<fs::path>{db, html, exported, exported_peer, scratch}
                            : std::vector<fs::path>{html, exported, exported_peer, scratch});
  if (!o.keep.empty() && fs::exists(db))
    throw cal::InputError(fmt::format(
        "bench export: --keep-db {}: the file exists; name a new one (nothing was written)",
        db.string()));
  remove_db(db);
  std::vector<BenchValues> kinds;
  if (o.values != "unquantised") kinds.push_back(BenchValues::quantised);
  if (o.values != "quantised") kinds.push_back(BenchValues::unquantised);
  fmt::print(
      "values: {}\n",
      o.values == "unquantised"
          ? "unquantised (0.1 + 1e-6 sin + 1e-9 k in doubles: 16 - 17 significant digits, which "
            "no instrument stores)"
          : "quantised (q): the 10 kHz length as daq bench ingest's line gauge prints it (mm with "
            "six decimals, 1 nm) and its driver stores it (the decimal in metres, its own double: "
            "raw readings are stored at the instrument's resolution, docs/storage.md); the air "
            "as a PTU300 prints it (0.01 hPa, 0.01 degC, 0.1 %RH)" +
                std::string(o.values == "both"
                                ? "; then unquantised (u): 0.1 + 1e-6 sin + 1e-9 k in doubles, "
                                  "16 - 17 significant digits, the bench's values before"
                                : ""));
  fmt::print("{:>9} {:>10} {:>7}  {:>31}  {:>31}  {:>16}\n", "minutes", "readings", "MB",
             "export csv: wall, CPU, RSS, %", "export json: wall, CPU, RSS, %", "report (html)");
  std::vector<std::string> ceilings;
  std::vector<ExportRounds> rounds;  // (--repeat)
  const std::string self = "/proc/self/exe";
  bool identical = true;
  for (int k = 1; k <= o.steps; ++k)
    for (const auto values : kinds) {
      const int seconds = o.minutes * 60 * k / o.steps;
      const char* const tag_values = values == BenchValues::quantised ? "q" : "u";
      std::int64_t run = 0, count = 0;
      const auto size_before = fs::exists(db) ? fs::file_size(db) : 0;
      {
        cal::storage::Store store(db, {.full_sync = false});
        run = generate_run(store, seconds, values);
        count = store.reading_count(run);
      }
      const double stored_mb = static_cast<double>(fs::file_size(db) - size_before) / 1e6;
      const auto id = std::to_string(run);
      // An export to a file, then its ceiling for the same bytes (both on the same load): the
      // table's text, and the CPU times into `into`.
      const auto measure = [&](const std::string& program, const char* who, const char* format,
                               const fs::path& out, int round, ExportRounds& into) {
        const auto r = run_program(
            program, {"export", id, "--db", db.string(), "--format", format, "-o", out.string()});
        const auto c = export_ceiling(db, run, out, scratch);
        const double mb = static_cast<double>(fs::file_size(out)) / 1e6;
        const double ceiling_cpu_s = c.read_cpu_s + c.write_cpu_s;
        into.export_cpu_s.push_back(r.cpu_s);
        into.ceiling_cpu_s.push_back(ceiling_cpu_s);
        ceilings.push_back(fmt::format(
            "  {:5.1f} min {} {:4} {}{}: {:6.0f} MB written; store read {:.2f} s (CPU {:.2f} s), "
            "writing the same bytes {:.2f} s (CPU {:.2f} s): export at {:.0f} % of that ceiling by "
            "CPU, {:.0f} % by wall time",
            seconds / 60.0, tag_values, format, who,
            o.repeat > 1 ? fmt::format(" round {}", round) : std::string(), mb, c.read_s,
            c.read_cpu_s, c.write_s, c.write_cpu_s, 100.0 * ceiling_cpu_s / r.cpu_s,
            100.0 * (c.read_s + c.write_s) / r.seconds));
        return fmt::format("{:6.2f} s {:6.2f} s {:4.0f} MB {:3.0f} %", r.seconds, r.cpu_s,
                           static_cast<double>(r.peak_rss_kib) / 1024,
                           100.0 * ceiling_cpu_s / r.cpu_s);
      };
      // Each format --repeat times, this binary's export and (--peer-daq) the peer's of the same
      // run in each round, in turn first; their bytes compared. The table shows the first round.
      std::pair<std::string, std::string> text[2];
      const char* const formats[2] = {"csv", "json"};
      ExportRounds mine[2], peers[2];
      for (int f = 0; f < 2; ++f) {
        const auto what =
            fmt::format("{:5.1f} min {} {:4}", seconds / 60.0, tag_values, formats[f]);
        mine[f].what = what + " this";
        peers[f].what = what + " peer";
      }
      for (int round = 1; round <= o.repeat; ++round)
        for (int f = 0; f < 2; ++f) {
          const bool peer_first = !o.peer.empty() && round % 2 == 0;
          std::string this_text, peer_text;
          if (peer_first)
            peer_text = measure(o.peer, "peer", formats[f], exported_peer, round, peers[f]);
          this_text = measure(self, "this", formats[f], exported, round, mine[f]);
          if (!o.peer.empty() && !peer_first)
            peer_text = measure(o.peer, "peer", formats[f], exported_peer, round, peers[f]);
          if (!o.peer.empty()) {
            const bool same = same_bytes(exported, exported_peer);
            peer_text += same ? "" : " DIFFERENT BYTES";
            identical = identical && same;
          }
          if (round == 1) text[f] = {this_text, peer_text};
        }
      for (int f = 0; f < 2; ++f) {
        rounds.push_back(mine[f]);
        if (!o.peer.empty()) rounds.push_back(peers[f]);
      }
      const auto report =
          run_program(self, {"report", id, "--db", db.string(), "-o", html.string()});
      fmt::print("{:>7.1f} {} {:>10} {:>7.1f}  {:>31}  {:>31}  {:6.2f} s {:4.0f} MB\n",
                 seconds / 60.0, tag_values, count, stored_mb, text[0].first, text[1].first,
                 report.seconds, static_cast<double>(report.peak_rss_kib) / 1024);
      if (!o.peer.empty())
        fmt::print("{:>9} {:>10} {:>7}  {:>31}  {:>31}\n", "peer", "", "", text[0].second,
                   text[1].second);
    }
  if (!o.peer.empty())
    fmt::print("peer: {}; its exports {} this binary's, byte for byte\n", o.peer,
               identical ? "are the same as" : "DIFFER from");
  fmt::print(
      "(wall time, CPU time and peak RSS of each daq process; %: the export's CPU time against "
      "its ceiling's, measured beside it: reading the run from the store and writing the same "
      "number of bytes)\n{}\n",
      fmt::join(ceilings, "\n"));
  if (o.repeat > 1) print_repeated(rounds, o.repeat);
}

struct SyncBenchOptions {
  std::string to;
  int minutes = 10;
  int runs = 1;  // runs of --minutes each in the generated store
  int rounds = 3;
  std::string dir;
  std::string site = "daq bench";
};

// daq sync of generated runs against PostgreSQL's own COPY of the same chunk rows, in alternate
// rounds on the same server and load (issue 35's "sync throughput against COPY").
void bench_sync(const SyncBenchOptions& o) {
  namespace pg = cal::storage::pg;
  if (!pg::is_postgresql_url(o.to))
    throw cal::InputError(
        fmt::format("bench sync: --to: '{}' is not a PostgreSQL URI "
                    "(postgresql://...; a scratch database: the bench's runs are "
                    "sent there and deleted again)",
                    o.to));
  if (o.minutes < 1 || o.rounds < 1 || o.runs < 1)
    throw cal::InputError("bench sync: --minutes, --runs and --rounds must be at least 1");
  const fs::path dir = o.dir.empty() ? fs::temp_directory_path() : fs::path(o.dir);
  const fs::path db = dir / fmt::format("caldaq-bench-sync-{}.sqlite", ::getpid());
  const Cleanup cleanup({db});
  remove_db(db);
  std::int64_t readings = 0;
  std::vector<std::string> uuids;
  std::vector<std::int64_t> runs;
  {
    cal::storage::Store store(db, {.full_sync = false});
    for (int k = 0; k < o.runs; ++k) {
      runs.push_back(generate_run(store, o.minutes * 60));
      readings += store.reading_count(runs.back());
      uuids.push_back(store.run(runs.back())->uuid);
    }
  }
  fmt::print(
      "{} run{} of {} min of a 10 kHz length stream with 1 Hz air: {} readings, {:.1f} MB "
      "store\n",
      o.runs, o.runs == 1 ? "" : "s", o.minutes, readings,
      static_cast<double>(fs::file_size(db)) / 1e6);
  pg::delete_central_runs(o.to, uuids);  // runs left by a cut bench
  std::vector<double> sync_s, ceiling_s;
  fmt::print("{:>5} {:>10} {:>8}  {:>24}  {:>34}  {:>5}\n", "round", "readings", "MB",
             "daq sync: wall, readings/s", "COPY ceiling: read + copy, readings/s", "%");
  for (int k = 1; k <= o.rounds; ++k) {
    const auto s =
        run_child({"sync", "--db", db.string(), "--to", o.to, "--site", o.site, "--quiet"});
    pg::delete_central_runs(o.to, uuids);
    const cal::storage::Store store(db, {.read_only = true});
    const auto c = pg::copy_ceiling(store, o.to, runs);
    const double ceiling = c.read_s + c.copy_s;
    sync_s.push_back(s.seconds);
    ceiling_s.push_back(ceiling);
    fmt::print(
        "{:>5} {:>10} {:>8.1f}  {:>8.2f} s {:>11.0f}/s  {:>6.2f} + {:>6.2f} s {:>11.0f}/s  "
        "{:>4.0f}\n",
        k, readings, static_cast<double>(c.bytes) / 1e6, s.seconds,
        static_cast<double>(readings) / s.seconds, c.read_s, c.copy_s,
        static_cast<double>(readings) / ceiling, 100.0 * ceiling / s.seconds);
  }
  const double ms = median(sync_s), mc = median(ceiling_s);
  fmt::print(
      "median: daq sync {:.0f} readings/s, COPY ceiling {:.0f} readings/s: sync at {:.0f} % of "
      "the ceiling\n(wall times; daq sync is a child process that opens, checks and sends the runs "
      "with their instruments and results; the ceiling reads the same chunks from the store and "
      "COPYs their rows in binary into a scratch table shaped like caldaq.reading_chunks, "
      "primary key included)\n",
      static_cast<double>(readings) / ms, static_cast<double>(readings) / mc, 100.0 * mc / ms);
}

}  // namespace

void add_bench_commands(CLI::App& app) {
  auto* bench = add_group(
      app, "bench",
      "Measure this machine: ingest, replay, export and sync beside their peers and ceilings");
  const auto [in, o] = add_command<BenchOptions>(
      *bench, "ingest", bench_ingest,
      "Replay a generated 10 kHz capture through the real instruments, compensation and store; "
      "measure the SQLite blob-insert and raw-write ceilings for the same bytes in the same run");
  in->add_option("--seconds", o->seconds, "Recorded seconds of the 10 kHz stream")
      ->capture_default_str();
  in->add_option("--rounds", o->rounds, "Rounds (ingest then ceilings); medians are reported")
      ->capture_default_str();
  in->add_option("--dir", o->dir, "Directory for the capture and databases (default: $TMPDIR)");
  in->add_option("--batch", o->batch_readings, "Readings per committed batch")
      ->capture_default_str();
  in->add_option("--loop-cpu", o->loop_cpu,
                 "With --storage-cpu: each round also ingests with the event loop on this CPU")
      ->check(whole_in(0, 1 << 20));
  in->add_option("--storage-cpu", o->storage_cpu,
                 "With --loop-cpu: ... and the batch encoder and SQLite writer threads on this one")
      ->check(whole_in(0, 1 << 20));

  const auto [ex, e] = add_command<ExportBenchOptions>(
      *bench, "export", bench_export,
      "Store generated runs of a 10 kHz stream (up to --minutes long) and measure the peak RSS "
      "and time of daq export (CSV, JSON) and daq report on each");
  ex->add_option("--minutes", e->minutes, "Length of the longest run")->capture_default_str();
  ex->add_option("--steps", e->steps, "Runs of 1/steps ... steps/steps of that length")
      ->capture_default_str();
  ex->add_option("--dir", e->dir, "Directory for the database (default: $TMPDIR)");
  ex->add_option("--keep-db", e->keep,
                 "Store the generated runs in this new file and keep it (to export or inspect)");
  ex->add_option("--values", e->values,
                 "The generated readings: quantised (as a 1 nm gauge's driver stores them, "
                 "run first), unquantised (16 - 17 significant digits) or both")
      ->check(CLI::IsMember({"quantised", "unquantised", "both"}))
      ->capture_default_str();
  ex->add_option("--peer-daq", e->peer,
                 "Also measure this daq binary's exports of the same runs, each right after this "
                 "one's with its own ceiling, and compare their bytes (a build to compare with)")
      ->check(CLI::ExistingFile);
  ex->add_option("--repeat", e->repeat,
                 "Rounds of each export and its ceiling (with --peer-daq, the peer's in the same "
                 "round); more than 1 adds the least and the median CPU of each and the % from "
                 "them")
      ->check(whole_in(1, 1000))
      ->capture_default_str();

  add_bench_replay_command(*bench);

  const auto [sy, y] = add_command<SyncBenchOptions>(
      *bench, "sync", bench_sync,
      "Send a generated run of a 10 kHz stream to a PostgreSQL server with daq sync and measure "
      "it beside the server's own COPY of the same chunk rows (a scratch database: the bench's "
      "run is deleted from it again)");
  sy->add_option("--to", y->to, "The server (postgresql://...)")->required();
  sy->add_option("--minutes", y->minutes, "Length of each generated run")->capture_default_str();
  sy->add_option("--runs", y->runs,
                 "Generated runs in the store, each sent by the same daq sync (a store of many "
                 "runs: each run's row, instruments and results in a transaction of its own)")
      ->capture_default_str();
  sy->add_option("--rounds", y->rounds, "Rounds (sync, then its ceiling); medians are reported")
      ->capture_default_str();
  sy->add_option("--dir", y->dir, "Directory for the generated database (default: $TMPDIR)");
  sy->add_option("--site", y->site,
                 "The site the generated run is sent as (central schema 7: one the login may "
                 "write; the run has no machine and its configuration names none)")
      ->capture_default_str();
}

}  // namespace daq
