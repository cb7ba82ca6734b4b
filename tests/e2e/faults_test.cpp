// Faults end cleanly (issue 15): a store or a capture that fails mid-run (a full disk,
// injected here by the stores' and the capture writer's own size caps, which fail exactly as
// a full disk does) ends the run as aborted with the reason naming the file, keeps what was
// written, and nothing is thrown out of an instrument's handler or a destructor. The same on
// a real full filesystem (a small tmpfs) is tests/cli/full_disk_test.sh, where mounting is
// allowed. Runs against the SIMULATED shop's twins through the real drivers.
#include <gtest/gtest.h>
#include <unistd.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <filesystem>
#include <random>

#include "../support/temp_db.hpp"
#include "cal/replay/capture.hpp"
#include "cal/replay/session.hpp"
#include "cal/storage/store.hpp"
#include "circle_run.hpp"
#include "ids3010/instrument.hpp"
#include "line_gauge/instrument.hpp"
#include "linear_run.hpp"
#include "ptu300/instrument.hpp"
#include "sim_shop.hpp"

namespace {

namespace fs = std::filesystem;
namespace d = cal::drivers;
namespace t = cal::drivers::transport;
using namespace std::chrono_literals;

fs::path temp_path(const char* name, const char* ext) {
  return cal::test::temp_path("caldaq-faults", name, ext);
}
using cal::test::remove_db;

// Pages of an empty store: the schema. A cap a few pages above it fills within seconds.
std::int64_t empty_store_pages() {
  const auto p = temp_path("empty", ".sqlite");
  { cal::storage::Store s(p); }
  const auto pages = static_cast<std::int64_t>(fs::file_size(p) / 4096);
  remove_db(p);
  return pages;
}

// A linear run of the simulated shop, its instruments recording through `recorder` if given.
struct Shop {
  // Simulated time that jumps from event to event (loop_time.hpp): loop seconds are simulated
  // seconds.
  static constexpr double speed = 1.0;
  boost::asio::io_context io;
  d::VirtualTime& time = d::VirtualTime::install(io);
  daq::SimulatedShop shop{io, daq::ShopTruth{}, speed};

  daq::LinearRunSetup setup(const fs::path& db, d::WireRecorder* recorder = nullptr) {
    cal::daq::Config c;
    c.machine_name = "faults";
    c.environment.stale_after_s = 60.0;
    c.linear = cal::daq::LinearTestConfig{.first_mm = 0, .last_mm = 200, .count = 5, .runs = 3};
    daq::LinearRunSetup s;
    s.config = c;
    s.database = db;
    shop.connect_linear(s, {.material = false, .recorder = recorder});
    return s;
  }
  // Runs the loop until the run ends by itself (it must: the fault ends it) or 600 s of
  // simulated time pass (20 s of wall time at the 30x this test ran at before).
  template <class Run>
  void run_until_finished(Run& run) {
    time.run_for(600s, [&] { return run.finished(); });
  }
};

TEST(Faults, AFullDatabaseAbortsTheRunNamingTheFileAndKeepsWhatWasWritten) {
  const auto db = temp_path("fulldb", ".sqlite");
  Shop s;
  auto setup = s.setup(db);
  setup.store_options.max_pages = empty_store_pages() + 16;  // 64 KiB for the readings
  daq::LinearRun run(s.io, std::move(setup));
  run.start();
  s.run_until_finished(run);
  ASSERT_TRUE(run.finished()) << "the run went on although its store was full";
  const auto& out = run.outcome();
  EXPECT_FALSE(out.complete);
  EXPECT_EQ(out.reason.rfind("storage failed: " + db.string() + ": ", 0), 0u) << out.reason;
  EXPECT_NE(out.reason.find("full"), std::string::npos)
      << out.reason;  // "database or disk is full"
  // Everything committed before the store filled is there, and the run says why it ended.
  cal::storage::Store store(db);
  const auto r = store.run(out.run_id);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, cal::storage::RunStatus::aborted);
  EXPECT_EQ(r->note, out.reason);
  EXPECT_GT(store.reading_count(out.run_id), 100);
  EXPECT_LE(store.reading_count(out.run_id), static_cast<std::int64_t>(out.readings));
  remove_db(db);
}

TEST(Faults, ACaptureOnAFullDiskAbortsTheRunAndStaysReadable) {
  const auto db = temp_path("fullcap", ".sqlite");
  const auto cdq = temp_path("fullcap", ".cdq");
  Shop s;
  cal::replay::CaptureWriter writer(cdq, "{}", {.block_bytes = 4096, .max_file_bytes = 24 * 1024});
  daq::LinearRun* running = nullptr;
  cal::replay::CaptureRecorder recorder(writer, [&](const std::string& e) {
    boost::asio::post(s.io, [&running, e] {
      if (running) running->stop("capture failed: " + e);
    });
  });
  daq::LinearRun run(s.io, s.setup(db, &recorder));
  running = &run;
  run.start();
  s.run_until_finished(run);
  running = nullptr;
  ASSERT_TRUE(run.finished()) << "the run went on although its capture could not be written";
  const auto& out = run.outcome();
  EXPECT_FALSE(out.complete);
  EXPECT_EQ(out.reason.rfind("capture failed: " + cdq.string() + ": write failed at byte ", 0), 0u)
      << out.reason;
  EXPECT_NE(out.reason.find("No space left on device"), std::string::npos) << out.reason;
  ASSERT_TRUE(recorder.failure());
  // The instruments' stop() recorded "closed" into the failed recorder: nothing was thrown.
  recorder.close();  // and closing it again neither throws nor writes an end block
  // The capture holds every block written before the failure; it says it was not closed.
  cal::replay::CaptureReader reader(cdq);
  std::uint64_t records = 0;
  while (reader.next()) ++records;
  EXPECT_GT(records, 10u);
  ASSERT_TRUE(reader.damage());
  EXPECT_NE(reader.damage()->what.find("no end block"), std::string::npos) << reader.damage()->what;
  EXPECT_LE(fs::file_size(cdq), 24u * 1024u);
  // The store is complete up to the abort and says why.
  cal::storage::Store store(db);
  EXPECT_EQ(store.run(out.run_id)->status, cal::storage::RunStatus::aborted);
  EXPECT_EQ(store.run(out.run_id)->note, out.reason);
  EXPECT_EQ(store.reading_count(out.run_id), static_cast<std::int64_t>(out.readings));
  remove_db(db);
  fs::remove(cdq);
}

TEST(Faults, NoExceptionEscapesTheRunsDestructors) {
  // A display callback that throws (a web page gone, a full terminal) while the destructor
  // aborts the run: before, ~LinearRun -> abort -> ... let it through, i.e. std::terminate.
  const auto db = temp_path("dtor", ".sqlite");
  {
    Shop s;
    auto setup = s.setup(db);
    bool started = false;
    setup.on_event = [&started](const std::string&) {
      if (started) throw std::runtime_error("the display is gone");
    };
    setup.on_live = [&started](const daq::LiveState&) {
      if (started) throw std::runtime_error("the page is gone");
    };
    daq::LinearRun run(s.io, std::move(setup));
    run.start();
    s.time.run_for(6s);  // 200 ms of wall time at 30x
    started = true;
  }  // ~LinearRun aborts the running run here
  {
    boost::asio::io_context io;
    daq::SimulatedShop shop(io, daq::ShopTruth{}, 30.0);
    bool started = false;
    daq::CircleRunSetup setup{
        .program = {.radius_mm = 100},
        .database = db,
        .ballbar =
            d::make_gauge(io, t::make_serial(io, {.device = shop.ballbar_device(), .baud = 115200}),
                          {.clock = shop.clock_ns()}, {.min_si = -0.1, .max_si = 0.1})};
    setup.on_live = [&started](const daq::CircleLive&) {
      if (started) throw std::runtime_error("the page is gone");
    };
    daq::CircleRun run(io, std::move(setup));
    run.start();
    io.run_for(200ms);
    started = true;
  }  // ~CircleRun aborts the running run here
  // Both runs are stored as aborted: the destructors did their work despite the callbacks.
  cal::storage::Store store(db);
  const auto runs = store.runs();
  ASSERT_EQ(runs.size(), 2u);
  for (const auto& r : runs) EXPECT_EQ(r.status, cal::storage::RunStatus::aborted) << r.id;
  remove_db(db);
}

TEST(Faults, AFailedRecorderNeverThrowsIntoAnInstrument) {
  const auto cdq = temp_path("recorder", ".cdq");
  cal::replay::CaptureWriter writer(cdq, "{}", {.block_bytes = 64, .max_file_bytes = 200});
  int failures = 0;
  std::string message;
  cal::replay::CaptureRecorder recorder(writer, [&](const std::string& e) {
    ++failures;
    message = e;
  });
  const std::string line = "P= 1013.2 hPa T= 21.3 'C RH= 42.0 %RH\r\n";
  const auto bytes = std::as_bytes(std::span(line.data(), line.size()));
  for (int i = 0; i < 50; ++i) {
    EXPECT_NO_THROW(recorder.received(1, i, bytes));
    EXPECT_NO_THROW(recorder.event(1, i, "closed"));
  }
  EXPECT_NO_THROW(recorder.flush());
  EXPECT_NO_THROW(recorder.close());
  EXPECT_EQ(failures, 1);  // reported once, not once per record
  EXPECT_EQ(message.rfind(cdq.string() + ": write failed at byte ", 0), 0u) << message;
  EXPECT_NE(message.find("No space left on device"), std::string::npos) << message;
  fs::remove(cdq);
}

}  // namespace
