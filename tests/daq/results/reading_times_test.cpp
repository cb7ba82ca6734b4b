// The rows of an export with their spread times (daq/src/results/reading_times.hpp): readings
// that came one to a stored time keep it; a stream's readings sharing one stored time are spread
// back from it by the stream's period; the rows of a time go out stream by stream, whatever
// order they came in, each with the tag it was added with.
#include "reading_times.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

#include "cal/storage/store.hpp"

namespace {
namespace fs = std::filesystem;
namespace st = cal::storage;

st::RawReading at(std::int64_t time_ns, int device, int quantity) {
  return {.time_ns = time_ns,
          .device = static_cast<std::uint16_t>(device),
          .quantity = static_cast<std::uint8_t>(quantity),
          .value = static_cast<double>(time_ns)};
}

TEST(ExportRows, SingleReadingsKeepTheirTimeAndGroupsAreSpreadStreamByStream) {
  const fs::path db =
      fs::temp_directory_path() / ("caldaq-export-rows-" + std::to_string(::getpid()) + ".sqlite");
  fs::remove(db);
  st::Store store(db);
  const auto run = store.begin_run({.kind = "bench", .axis = "X"});
  // Stream A (device 0) one reading per stored time; stream B (device 1) three readings to a
  // transport read at 1000 and 2000 ns, then one at 3000 ns. B's period from its stored series:
  // (3000 - 1000) / (7 - 1) = 1000 / 3 ns.
  const std::vector<st::RawReading> stored{at(0, 0, 1),    at(1000, 0, 1), at(1000, 1, 2),
                                           at(1000, 1, 2), at(1000, 1, 2), at(2000, 1, 2),
                                           at(2000, 1, 2), at(2000, 1, 2), at(3000, 0, 1),
                                           at(3000, 1, 2), at(4000, 0, 1)};
  store.append_readings(run, stored);
  store.finish_run(run, st::RunStatus::complete);
  daq::ExportClock clock(store, *store.run(run), nlohmann::json::object());
  daq::ExportRows rows(clock);
  // In: at 3000 ns B comes before A (the rows must still go out A, then B); tags 0, 1, 2...
  std::vector<st::RawReading> in = stored;
  std::swap(in[8], in[9]);
  std::vector<daq::ExportRow> out;
  for (std::size_t i = 0; i < in.size(); ++i)
    rows.add_each(
        in[i], [&](const daq::ExportRow& x) { out.push_back(x); }, i);
  rows.finish_each([&](const daq::ExportRow& x) { out.push_back(x); });
  // By hand: B's group at 1000 ns has nothing before it: 1000 - 2p, 1000 - p, 1000; at 2000 ns
  // 2000 - 2p = 1333.3 is after the group before (1000): 2000 - 2p, 2000 - p, 2000.
  const double p = 1000.0 / 3.0;
  struct Want {
    int device;
    double session_ns;
    std::uint64_t tag;
  };
  const std::vector<Want> want{{0, 0, 0},        {0, 1000, 1}, {1, 1000 - 2 * p, 2},
                               {1, 1000 - p, 3}, {1, 1000, 4}, {1, 2000 - 2 * p, 5},
                               {1, 2000 - p, 6}, {1, 2000, 7}, {0, 3000, 9},
                               {1, 3000, 8},     {0, 4000, 10}};
  ASSERT_EQ(out.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(out[i].r.device, want[i].device) << i;
    EXPECT_NEAR(out[i].session_ns, want[i].session_ns, 1e-6) << i;
    EXPECT_EQ(out[i].tag, want[i].tag) << i;
    EXPECT_EQ(out[i].r.value, static_cast<double>(out[i].r.time_ns)) << i;  // the reading's own
  }
  // add_batch (the exports' way, which hands a reading alone at its time straight on): the same
  // rows and times by hand, however the store cuts the readings into batches (every cut).
  for (unsigned cuts = 0; cuts < (1U << (in.size() - 1)); ++cuts) {
    daq::ExportClock batch_clock(store, *store.run(run), nlohmann::json::object());
    daq::ExportRows batch_rows(batch_clock);
    std::vector<daq::ExportRow> got;
    const auto keep = [&](const daq::ExportRow& x) { got.push_back(x); };
    std::size_t from = 0;
    for (std::size_t i = 1; i <= in.size(); ++i)
      if (i == in.size() || ((cuts >> (i - 1)) & 1U) != 0) {
        batch_rows.add_batch(std::span(in).subspan(from, i - from), keep);
        from = i;
      }
    batch_rows.finish_each(keep);
    ASSERT_EQ(got.size(), want.size()) << cuts;
    for (std::size_t i = 0; i < want.size(); ++i) {
      ASSERT_EQ(got[i].r.device, want[i].device) << cuts << " " << i;
      ASSERT_NEAR(got[i].session_ns, want[i].session_ns, 1e-6) << cuts << " " << i;
      ASSERT_EQ(got[i].r.value, static_cast<double>(got[i].r.time_ns)) << cuts << " " << i;
    }
  }
  fs::remove(db);
}

}  // namespace
