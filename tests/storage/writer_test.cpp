// The batch writer: nothing is lost whatever the batching, order is kept, and a failing disk
// stops the producer with the error while every committed batch stays readable.
#include "cal/storage/writer.hpp"

#include <gtest/gtest.h>
#include <sched.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "cal/analysis/error.hpp"

namespace {

namespace fs = std::filesystem;
using namespace cal::storage;

struct TempFile {
  fs::path path = fs::temp_directory_path() / ("caldaq-writer-" + std::to_string(::getpid()) + "-" +
                                               std::to_string(std::random_device{}()) + ".sqlite");
  ~TempFile() {
    for (const char* suffix : {"", "-wal", "-shm"}) fs::remove(path.string() + suffix);
  }
};

RawReading reading(std::int64_t i) {
  return {
      .time_ns = i * 100'000, .device = 1, .quantity = 0, .value = static_cast<double>(i) * 1e-9};
}

TEST(BatchWriter, KeepsEveryReadingInOrderAcrossBatches) {
  TempFile file;
  std::int64_t run = 0;
  { run = Store(file.path).begin_run({.kind = "linear"}); }
  constexpr std::int64_t n = 100'003;  // not a multiple of the batch: the tail must be flushed
  {
    BatchWriter writer(file.path, run, {.batch_readings = 1000, .max_queued_batches = 2});
    for (std::int64_t i = 0; i < n; ++i) writer.push(reading(i));
    writer.flush();
    const auto s = writer.stats();
    EXPECT_EQ(s.readings_in, static_cast<std::uint64_t>(n));
    EXPECT_EQ(s.readings_committed, static_cast<std::uint64_t>(n));
    EXPECT_EQ(s.batches_committed, 101u);  // 100 full + the tail of 3
    EXPECT_LE(s.max_queue_depth, 2u);
  }
  Store store(file.path);
  const auto back = store.readings(run);
  ASSERT_EQ(static_cast<std::int64_t>(back.size()), n);
  for (std::int64_t i = 0; i < n; i += 997)
    EXPECT_EQ(back[static_cast<std::size_t>(i)].value, reading(i).value);
}

// The CPUs each thread of this process may run on, as the kernel lists them
// (/proc/self/task/<tid>/status, "Cpus_allowed_list:"), one entry per thread.
std::vector<std::string> threads_cpu_lists() {
  std::vector<std::string> lists;
  for (const auto& task : fs::directory_iterator("/proc/self/task")) {
    std::ifstream status(task.path() / "status");
    for (std::string line; std::getline(status, line);)
      if (line.starts_with("Cpus_allowed_list:")) lists.push_back(line.substr(line.find(':') + 1));
  }
  for (auto& l : lists) l.erase(0, l.find_first_not_of(" \t"));
  return lists;
}

TEST(BatchWriter, StorageThreadsRunOnTheGivenCpusAndStoreTheSame) {
  cpu_set_t allowed;
  ASSERT_EQ(sched_getaffinity(0, sizeof allowed, &allowed), 0);
  int last = -1;
  for (int cpu = 0; cpu < CPU_SETSIZE; ++cpu)
    if (CPU_ISSET(cpu, &allowed)) last = cpu;
  ASSERT_GE(last, 0);
  const auto before = threads_cpu_lists();
  const auto pinned_before = std::count(before.begin(), before.end(), std::to_string(last));
  TempFile file;
  std::int64_t run = 0;
  { run = Store(file.path).begin_run({.kind = "linear"}); }
  {
    BatchWriter writer(file.path, run,
                       {.batch_readings = 1000, .writer_cpus = {last}, .encoder_cpus = {last}});
    for (std::int64_t i = 0; i < 5000; ++i) writer.push(reading(i));
    writer.flush();  // both threads have run (and placed themselves) by now
    const auto during = threads_cpu_lists();
    // The encoder and the writer, and nothing else of this process, were moved to `last` (on a
    // one-CPU machine every thread lists it anyway).
    if (CPU_COUNT(&allowed) > 1) {
      EXPECT_EQ(std::count(during.begin(), during.end(), std::to_string(last)), pinned_before + 2);
    }
    EXPECT_EQ(writer.stats().readings_committed, 5000u);
  }
  EXPECT_EQ(Store(file.path).readings(run).size(), 5000u);
}

TEST(BatchWriter, ACpuThisThreadMayNotUseIsRefusedWithTheCpuNamed) {
  TempFile file;
  std::int64_t run = 0;
  { run = Store(file.path).begin_run({.kind = "linear"}); }
  for (const int cpu : {-1, CPU_SETSIZE, CPU_SETSIZE - 1}) {
    try {
      BatchWriter writer(file.path, run, {.writer_cpus = {cpu}});
      ADD_FAILURE() << "CPU " << cpu << " accepted";
    } catch (const cal::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("CPU " + std::to_string(cpu)), std::string::npos)
          << e.what();
    }
  }
}

TEST(BatchWriter, PushingSpansCutsTheSameBatchesAsPushingOneByOne) {
  // Spans of random sizes (empty, smaller than, across and larger than a batch): every batch
  // but the tail must still be full (100 of 1000 readings and the tail of 3, as one by one
  // above), so the chunks stored are the same, and every reading comes back in order.
  TempFile file;
  std::int64_t run = 0;
  { run = Store(file.path).begin_run({.kind = "linear"}); }
  constexpr std::int64_t n = 100'003;
  std::vector<RawReading> all;
  for (std::int64_t i = 0; i < n; ++i) all.push_back(reading(i));
  {
    BatchWriter writer(file.path, run, {.batch_readings = 1000, .max_queued_batches = 2});
    std::mt19937 rng(7);
    std::uniform_int_distribution<std::size_t> size(0, 2500);
    for (std::size_t at = 0; at < all.size();) {
      const std::size_t k = std::min(size(rng), all.size() - at);
      writer.push(std::span<const RawReading>(all).subspan(at, k));
      at += k;
    }
    writer.flush();
    const auto s = writer.stats();
    EXPECT_EQ(s.readings_in, static_cast<std::uint64_t>(n));
    EXPECT_EQ(s.readings_committed, static_cast<std::uint64_t>(n));
    EXPECT_EQ(s.batches_committed, 101u);
  }
  Store store(file.path);
  const auto back = store.readings(run);
  ASSERT_EQ(static_cast<std::int64_t>(back.size()), n);
  for (std::int64_t i = 0; i < n; ++i) {
    ASSERT_EQ(back[static_cast<std::size_t>(i)].time_ns, all[static_cast<std::size_t>(i)].time_ns);
    ASSERT_EQ(back[static_cast<std::size_t>(i)].value, all[static_cast<std::size_t>(i)].value);
  }
}

// A batch's age is read on the options' clock (a simulated session's time): it is handed over
// when that clock says 200 ms have passed since its first reading, however much wall time did.
TEST(BatchWriter, ABatchAgesOnTheGivenClock) {
  TempFile file;
  std::int64_t run = 0;
  { run = Store(file.path).begin_run({.kind = "linear"}); }
  std::chrono::steady_clock::time_point now{};  // a clock that moves only when told
  BatchWriter writer(file.path, run, {.batch_age = std::chrono::milliseconds(200), .clock = [&now] {
                                        return now;
                                      }});
  for (std::int64_t i = 0; i < 10; ++i) writer.push(reading(i));
  now += std::chrono::milliseconds(199);
  writer.flush_if_old();
  EXPECT_EQ(writer.stats().batches_committed, 0u);  // 199 ms old: kept
  now += std::chrono::milliseconds(1);
  writer.flush_if_old();
  writer.push(reading(10));  // opens the next batch at t = 200 ms
  writer.flush();            // waits for what was handed over, and hands over the second
  const auto s = writer.stats();
  EXPECT_EQ(s.batches_committed, 2u);  // the 10 aged ones, then the one read after
  EXPECT_EQ(s.readings_committed, 11u);
}

TEST(BatchWriter, AFullDiskStopsTheProducerAndKeepsCommittedBatches) {
  TempFile file;
  std::int64_t run = 0;
  { run = Store(file.path).begin_run({.kind = "linear"}); }
  std::string reported;
  std::uint64_t committed = 0;
  {
    BatchWriter writer(
        file.path, run,
        {.batch_readings = 1000, .max_queued_batches = 1, .store = {.max_pages = 64}},
        [&](const std::string& e) { reported = e; });
    EXPECT_THROW(
        {
          for (std::int64_t i = 0; i < 10'000'000; ++i) writer.push(reading(i));
          writer.flush();
        },
        StoreError);
    committed = writer.stats().readings_committed;
  }
  EXPECT_NE(reported.find("full"), std::string::npos) << reported;
  EXPECT_GT(committed, 0u);
  Store store(file.path);
  EXPECT_EQ(store.reading_count(run), static_cast<std::int64_t>(committed));
}

}  // namespace
