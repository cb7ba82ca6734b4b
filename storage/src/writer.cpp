#include "cal/storage/writer.hpp"

#include <fmt/format.h>
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <condition_variable>
#include <deque>
#include <mutex>
#include <optional>
#include <thread>
#include <vector>

#include "cal/analysis/error.hpp"

namespace cal::storage {
namespace {

// The CPU set of `cpus`, each checked against the CPUs the calling thread may run on.
cpu_set_t cpu_set_of(std::span<const int> cpus) {
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  if (sched_getaffinity(0, sizeof allowed, &allowed) != 0)
    throw InputError("storage CPUs: cannot read this thread's CPU affinity");
  cpu_set_t set;
  CPU_ZERO(&set);
  for (const int cpu : cpus) {
    if (cpu < 0 || cpu >= CPU_SETSIZE || !CPU_ISSET(cpu, &allowed))
      throw InputError(
          fmt::format("CPU {}: not one this process may run on (taskset -p shows which)", cpu));
    CPU_SET(cpu, &set);
  }
  return set;
}

}  // namespace

void check_cpus(std::span<const int> cpus) { cpu_set_of(cpus); }

struct BatchWriter::Impl {
  std::filesystem::path path;
  std::int64_t run_id;
  WriterOptions options;
  std::function<void(const std::string&)> on_error;

  std::vector<RawReading> current;  // producer side only
  std::uint64_t pushed = 0;         // producer side only
  std::chrono::steady_clock::time_point current_started{};
  std::chrono::steady_clock::time_point now() const {
    return options.clock ? options.clock() : std::chrono::steady_clock::now();
  }

  mutable std::mutex mutex;
  std::condition_variable changed;
  std::deque<std::vector<RawReading>> queue;
  // Committed batches' vectors, emptied, for the producer to fill again: no allocation (and no
  // fresh pages to fault in) per batch.
  std::vector<std::vector<RawReading>> spare;
  // Encoded batches waiting for the writer: the encoder thread groups and encodes batch k + 1
  // while the writer thread commits batch k (its fsync leaves the CPU idle), so storing costs
  // about what SQLite alone costs for the bytes.
  std::deque<PreparedBatch> prepared;
  std::vector<PreparedBatch> spare_prepared;
  static constexpr std::size_t max_prepared = 2;
  bool closing = false;
  bool encoding = false;      // the encoder holds a batch it has not handed on yet
  bool encoder_done = false;  // closing and everything encoded
  bool busy = false;          // the writer holds a batch it has not committed yet
  std::string error;
  WriterStats stats;
  std::thread encoder, thread;
  // Where the two threads run; none: the OS decides.
  std::optional<cpu_set_t> writer_cpus, encoder_cpus;

  // Called first in each storage thread. The set was checked in the constructor, so this
  // cannot fail for a reason the caller could act on; the thread then runs unpinned.
  static void place_this_thread(const std::optional<cpu_set_t>& cpus) {
    if (cpus) pthread_setaffinity_np(pthread_self(), sizeof *cpus, &*cpus);
  }

  void encode_loop() {
    place_this_thread(encoder_cpus);
    for (;;) {
      std::vector<RawReading> batch;
      PreparedBatch out;
      {
        std::unique_lock lock(mutex);
        changed.wait(lock, [&] { return closing || !queue.empty() || !error.empty(); });
        if (!error.empty()) return;
        if (queue.empty()) {
          encoder_done = true;
          lock.unlock();
          changed.notify_all();
          return;
        }
        batch = std::move(queue.front());
        queue.pop_front();
        encoding = true;
        if (!spare_prepared.empty()) {
          out = std::move(spare_prepared.back());
          spare_prepared.pop_back();
        }
      }
      changed.notify_all();  // a producer waiting for room may go on
      const auto start = std::chrono::steady_clock::now();
      try {
        out.prepare(batch);
      } catch (const std::exception& e) {
        return fail(std::string("encode a batch of readings: ") + e.what());
      }
      const auto took = std::chrono::steady_clock::now() - start;
      std::unique_lock lock(mutex);
      stats.encode_time += took;
      changed.wait(lock, [&] { return prepared.size() < max_prepared || !error.empty(); });
      encoding = false;
      if (!error.empty()) return;
      prepared.push_back(std::move(out));
      if (spare.size() < 2) {
        batch.clear();
        spare.push_back(std::move(batch));
      }
      lock.unlock();
      changed.notify_all();
    }
  }

  void run() {
    place_this_thread(writer_cpus);
    std::optional<Store> store;
    try {
      store.emplace(path, options.store);
    } catch (const std::exception& e) {
      return fail(e.what());
    }
    for (;;) {
      PreparedBatch batch;
      {
        std::unique_lock lock(mutex);
        changed.wait(lock, [&] { return encoder_done || !prepared.empty() || !error.empty(); });
        if (!error.empty() || prepared.empty()) return;
        batch = std::move(prepared.front());
        prepared.pop_front();
        busy = true;
      }
      changed.notify_all();  // the encoder may hand on its next batch
      const auto start = std::chrono::steady_clock::now();
      try {
        store->append_prepared(run_id, batch);
      } catch (const std::exception& e) {
        return fail(e.what());
      }
      const auto took = std::chrono::steady_clock::now() - start;
      std::lock_guard lock(mutex);
      stats.store_time += took;
      busy = false;
      stats.readings_committed += batch.reading_count;
      ++stats.batches_committed;
      if (spare_prepared.size() < 2) spare_prepared.push_back(std::move(batch));
      changed.notify_all();
    }
  }

  void fail(const std::string& what) {
    {
      std::lock_guard lock(mutex);
      error = what;
      busy = false;
      queue.clear();
      prepared.clear();
    }
    changed.notify_all();
    if (on_error) on_error(what);
  }

  void check_error() const {
    std::lock_guard lock(mutex);
    if (!error.empty()) throw StoreError(error);
  }

  void hand_over() {
    if (current.empty()) return;
    std::unique_lock lock(mutex);
    if (queue.size() >= options.max_queued_batches) {
      ++stats.overload_waits;
      const auto start = std::chrono::steady_clock::now();
      changed.wait(lock,
                   [&] { return queue.size() < options.max_queued_batches || !error.empty(); });
      stats.overload_time += std::chrono::steady_clock::now() - start;
    }
    if (!error.empty()) throw StoreError(error);
    queue.push_back(std::move(current));
    stats.max_queue_depth = std::max(stats.max_queue_depth, queue.size());
    if (spare.empty()) {
      current = {};
    } else {
      current = std::move(spare.back());
      spare.pop_back();
    }
    lock.unlock();
    current.reserve(options.batch_readings);
    changed.notify_all();
  }
};

BatchWriter::BatchWriter(std::filesystem::path path, std::int64_t run_id, WriterOptions options,
                         std::function<void(const std::string&)> on_error)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = std::move(path);
  impl_->run_id = run_id;
  impl_->options = options;
  impl_->on_error = std::move(on_error);
  if (!options.writer_cpus.empty()) impl_->writer_cpus = cpu_set_of(options.writer_cpus);
  if (!options.encoder_cpus.empty()) impl_->encoder_cpus = cpu_set_of(options.encoder_cpus);
  impl_->current.reserve(options.batch_readings);
  impl_->encoder = std::thread([impl = impl_.get()] { impl->encode_loop(); });
  impl_->thread = std::thread([impl = impl_.get()] { impl->run(); });
}

BatchWriter::~BatchWriter() {
  try {
    impl_->hand_over();
  } catch (const std::exception&) {
    // already reported through on_error; nothing more can be stored
  }
  {
    std::lock_guard lock(impl_->mutex);
    impl_->closing = true;
  }
  impl_->changed.notify_all();
  impl_->encoder.join();
  impl_->thread.join();
}

void BatchWriter::push(const RawReading& r) {
  Impl& m = *impl_;
  if (m.current.empty()) {
    m.check_error();
    m.current_started = m.now();
  }
  m.current.push_back(r);
  ++m.pushed;  // producer-side only; stats() is called from the producer's thread
  if (m.current.size() >= m.options.batch_readings) m.hand_over();
}

void BatchWriter::push(std::span<const RawReading> readings) {
  Impl& m = *impl_;
  while (!readings.empty()) {
    if (m.current.empty()) {
      m.check_error();
      m.current_started = m.now();
    }
    // Up to the end of the current batch (at least one reading, as push(r) does).
    const std::size_t limit = m.options.batch_readings;
    const std::size_t room = m.current.size() < limit ? limit - m.current.size() : 1;
    const auto take = readings.first(std::min(readings.size(), room));
    m.current.insert(m.current.end(), take.begin(), take.end());
    m.pushed += take.size();
    readings = readings.subspan(take.size());
    if (m.current.size() >= m.options.batch_readings) m.hand_over();
  }
}

void BatchWriter::flush_if_old() {
  if (!impl_->current.empty() && impl_->now() - impl_->current_started >= impl_->options.batch_age)
    impl_->hand_over();
}

void BatchWriter::flush() {
  Impl& m = *impl_;
  m.hand_over();
  std::unique_lock lock(m.mutex);
  m.changed.wait(lock, [&] {
    return (m.queue.empty() && !m.encoding && m.prepared.empty() && !m.busy) || !m.error.empty();
  });
  if (!m.error.empty()) throw StoreError(m.error);
}

WriterStats BatchWriter::stats() const {
  std::lock_guard lock(impl_->mutex);
  WriterStats s = impl_->stats;
  s.readings_in = impl_->pushed;
  return s;
}

}  // namespace cal::storage
