#pragma once
// Batched writes off the event loop: the loop appends readings to the current batch (cheap,
// no I/O); full batches go through a bounded queue to an encoder thread (grouping into chunks,
// encoding) and on to a writer thread that owns the Store's connection and commits each batch
// in one transaction, while the next one is encoded. When the queue is full the loop
// waits (back-pressure) rather than dropping: no reading is ever silently lost, and the time
// spent waiting is measured and reported as overload.
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "cal/storage/store.hpp"

namespace cal::storage {

struct WriterOptions {
  std::size_t batch_readings = 16384;        // a batch is committed when this full, or
  std::chrono::milliseconds batch_age{200};  // when its oldest reading is this old
  std::size_t max_queued_batches = 8;        // then the producer waits
  StoreOptions store;                        // for the writer's own connection
  // The clock a batch's age is measured on (empty: the steady clock). A session on simulated
  // time passes its loop's clock, so that its batches (what each commit holds) are the same
  // on a fast or a loaded machine instead of depending on how fast the CPU runs it.
  std::function<std::chrono::steady_clock::time_point()> clock;
  // CPUs (Linux numbers) the writer thread (SQLite, the commits and their fsyncs) and the
  // encoder thread run on; empty: wherever the OS schedules them (a thread left unplaced runs
  // where the thread that made the writer may run). Where ingest competes for few cores,
  // placing the storage threads on a CPU apart from the event loop's, the one that takes the
  // disk's interrupts, keeps the scheduler from placing the writer behind the loop: on the
  // 2-core benchmark machine ingest went from about 60 % to about 75 % of the SQLite ceiling
  // (docs/benchmarks.md). The constructor throws cal::InputError for a CPU the calling thread
  // may not run on (make the writer before pinning the calling thread elsewhere).
  std::vector<int> writer_cpus, encoder_cpus;
};

struct WriterStats {
  std::uint64_t readings_in = 0;
  std::uint64_t readings_committed = 0;
  std::uint64_t batches_committed = 0;
  std::size_t max_queue_depth = 0;
  std::uint64_t overload_waits = 0;           // times the producer found the queue full
  std::chrono::nanoseconds overload_time{0};  // total time it waited
  // Time the encoder thread spent grouping and encoding batches, and the writer thread storing
  // them (checksums, SQLite, the commits' fsyncs); the two overlap. A store time near the wall
  // time of a run: the commits are what limits it.
  std::chrono::nanoseconds encode_time{0};
  std::chrono::nanoseconds store_time{0};
};

// Throws cal::InputError, naming the CPU, unless the calling thread may run on every one of
// `cpus` (what BatchWriter checks of WriterOptions::writer_cpus and encoder_cpus).
void check_cpus(std::span<const int> cpus);

class BatchWriter {
 public:
  // Opens its own connection to the store at `path` on the writer thread. Errors (e.g. a full
  // disk) are reported through on_error once, from the writer thread; later pushes then throw
  // StoreError so the run stops instead of pretending to record.
  BatchWriter(std::filesystem::path path, std::int64_t run_id, WriterOptions options = {},
              std::function<void(const std::string&)> on_error = {});
  ~BatchWriter();  // flushes and joins
  BatchWriter(const BatchWriter&) = delete;
  BatchWriter& operator=(const BatchWriter&) = delete;

  void push(const RawReading& r);
  // The same for several readings in order (one call per chunk of a high-rate stream); the
  // batches are cut at the very same readings as by pushing them one by one.
  void push(std::span<const RawReading> readings);
  // Hands the current batch over (even if small) when it is batch_age old by the options'
  // clock, e.g. from a periodic timer on the loop.
  void flush_if_old();
  // Hands over the current batch and waits until everything pushed so far is committed.
  void flush();
  // Call from the producer's thread (the event loop).
  WriterStats stats() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cal::storage
