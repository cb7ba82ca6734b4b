#pragma once
// What the `daq bench` commands share (cmd_bench.cpp defines them): the ingest pipeline of
// `daq bench ingest` as the per-reading peer of other benches, and child runs of this binary
// measured by wait4.
#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "cal/storage/writer.hpp"

namespace CLI {
class App;
}

namespace daq::bench {

double median(std::vector<double> v);
void remove_db(const std::filesystem::path& p);

// Removes the benchmark's files when it ends, also by an error (they can be hundreds of MB).
struct Cleanup {
  std::vector<std::filesystem::path> files;
  explicit Cleanup(std::vector<std::filesystem::path> f) : files(std::move(f)) {}
  Cleanup(const Cleanup&) = delete;
  Cleanup& operator=(const Cleanup&) = delete;
  ~Cleanup() {
    std::error_code ec;
    for (const auto& f : files)
      for (const char* s : {"", "-wal", "-shm"}) std::filesystem::remove(f.string() + s, ec);
  }
};

// A capture of `seconds` of a 10 kHz gauge stream (ten lines per 1 ms record) and 1 Hz PTU300
// lines: the ingest bench's workload.
void write_capture(const std::filesystem::path& path, int seconds);

struct IngestResult {
  std::uint64_t readings = 0;
  std::uint64_t handovers = 0;  // calls that brought the gauge's readings (one per chunk)
  double wall_s = 0.0, cpu_s = 0.0;
  double checksum = 0.0;  // sum of the compensated lengths: the same in every round and version
  cal::storage::WriterStats writer;
  std::vector<std::pair<int, long>> rss_marks;  // (recorded minute, current RSS KiB)
};

// Where the threads of one ingest run (-1: the OS decides): the event loop on one CPU, the
// storage threads (the batch encoder and the SQLite writer) on another. (The encoder beside
// the loop instead was slower: 64 - 71 %, the loop's CPU then being the limit.)
struct Placement {
  int loop_cpu = -1, storage_cpu = -1;
  bool pinned() const { return loop_cpu >= 0; }
};

// The ingest pipeline on `capture` (write_capture's); `db` empty: the pipeline alone, readings
// go nowhere.
IngestResult ingest(const std::filesystem::path& capture, const std::filesystem::path& db,
                    std::size_t batch_readings, Placement where = {});

struct ChildResult {
  double seconds = 0.0;
  double cpu_s = 0.0;  // user and system
  long peak_rss_kib = 0;
  int exit_code = 0;  // -1: ended by a signal
};
// Runs this daq binary with `args`, its stdout and stderr to the file `output`.
ChildResult spawn_child(const std::vector<std::string>& args, const std::string& output);
// Runs `program` (a path) with `args` the same way. Its peak RSS from wait4 is at least this
// process's at the spawn (Linux keeps the larger of the old and the new image's across exec).
ChildResult spawn_program(const std::string& program, const std::vector<std::string>& args,
                          const std::string& output);
// spawn_child, its output to /dev/null; throws unless it exits with 0.
ChildResult run_child(const std::vector<std::string>& args);
// The same for another daq binary (`daq bench export --peer-daq`).
ChildResult run_program(const std::string& program, const std::vector<std::string>& args);

}  // namespace daq::bench

namespace daq {
// daq bench replay (cmd_bench_replay.cpp), added to the `bench` group by add_bench_commands.
void add_bench_replay_command(CLI::App& bench);
}  // namespace daq
