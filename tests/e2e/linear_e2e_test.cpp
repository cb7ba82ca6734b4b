// End to end: the simulated shop with known injected errors, acquired through the real
// transports, codecs and instruments, compensated, triggered, sequenced, stored and
// evaluated; the stored result must agree with the simulated truth. And a real `daq demo`
// process killed with SIGKILL mid-run must leave a readable database with the run incomplete.
#include <fcntl.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <boost/asio/io_context.hpp>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <random>
#include <thread>

#include "../support/temp_db.hpp"
#include "cal/drivers/loop_time.hpp"
#include "cal/storage/store.hpp"
#include "circle_output.hpp"
#include "circle_run.hpp"
#include "ids3010/instrument.hpp"
#include "iso230_2_output.hpp"
#include "line_gauge/instrument.hpp"
#include "linear_run.hpp"
#include "ptu300/instrument.hpp"
#include "roles.hpp"
#include "sim_shop.hpp"
#include "verdict.hpp"

namespace {

namespace fs = std::filesystem;
namespace d = cal::drivers;
namespace t = cal::drivers::transport;
using namespace std::chrono_literals;

fs::path temp_db(const char* name) { return cal::test::temp_path("caldaq-e2e", name); }
using cal::test::remove_db;

// The linear test of the acquisitions below: 5 targets over 200 mm, 3 runs, 3 mm overruns.
cal::daq::Config linear_config() {
  cal::daq::Config c;
  c.machine_name = "e2e";
  c.environment.stale_after_s = 60.0;  // simulated seconds at 40x: see cmd_demo.cpp
  c.trigger = {.tolerance_um = 1.0, .dwell_s = 1.5, .window_mm = 0.5};
  c.linear = cal::daq::LinearTestConfig{.first_mm = 0,
                                        .last_mm = 200,
                                        .count = 5,
                                        .runs = 3,
                                        .overrun_mm = 3,
                                        .feed_mm_per_min = 6000,
                                        .dwell_s = 3};
  return c;
}

// A linear run of the simulated shop on simulated time that jumps from event to event
// (loop_time.hpp): loop seconds are simulated seconds, and the run takes as long as the CPU
// needs.
struct LinearShop {
  boost::asio::io_context io;
  d::VirtualTime& time = d::VirtualTime::install(io);
  daq::SimulatedShop shop{io, daq::ShopTruth{}, 1.0};
  const cal::daq::Config config = linear_config();
  daq::StartupReadings read{1};

  daq::LinearRunSetup setup(const fs::path& db) {
    daq::LinearRunSetup s;
    s.config = config;
    s.database = db;
    shop.connect_linear(s);  // the laser at 100 Hz of simulated time
    s.on_reading = [this](const d::Reading& r) { read.add(r); };
    return s;
  }
  // Every instrument has read once: the machine may move.
  bool started() {
    return shop.wait_until([&] { return read.all(); });
  }
};

TEST(LinearEndToEnd, MeasuredResultsAgreeWithTheSimulatedTruth) {
  const auto db = temp_db("linear");
  LinearShop s;
  auto setup = s.setup(db);
  daq::LinearRun run(s.io, std::move(setup));
  run.start();
  ASSERT_TRUE(s.started());
  s.shop.run_linear(run.plan(), s.config.linear->feed_mm_per_min, s.config.linear->dwell_s);
  s.shop.run_program([&] { return run.finished(); }, 30.0);
  ASSERT_TRUE(run.finished());
  const auto& out = run.outcome();
  ASSERT_TRUE(out.complete) << out.reason;

  // The truth: the same evaluation of the noise-free deviations at the same stops. The
  // tolerance, 0.15 um, covers: the standard error of a mean of 3 stop means (each the mean
  // of ~15 readings of 0.15 um noise: 0.04 um per stop, 0.02 um per mean), the rest of the
  // servo settling in the averaged half (< 0.01 um), and the environment sensors' rounding
  // (0.01 degC, 0.01 hPa, 0.1 %RH: < 0.01 ppm, < 0.002 um at 200 mm). Without the air and
  // material compensation the error at 200 mm would be about 290 ppm = 58 um.
  const auto truth =
      cal::iso230_2::evaluate(s.shop.true_measurements(run.plan()), out.evaluation->standard.id);
  for (const char* key : {"B_mean", "E_up", "E_down", "E_bi", "M"})
    EXPECT_NEAR(out.evaluation->at(key).value_um, truth.at(key).value_um, 0.15) << key;
  for (std::size_t i = 0; i < truth.targets.size(); ++i) {
    EXPECT_NEAR(out.evaluation->targets[i].mean_up_um, truth.targets[i].mean_up_um, 0.15) << i;
    EXPECT_NEAR(out.evaluation->targets[i].mean_down_um, truth.targets[i].mean_down_um, 0.15) << i;
  }

  // Stored: the run complete, every stop, the result, and the raw readings.
  cal::storage::Store store(db);
  const auto r = store.run(out.run_id);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, cal::storage::RunStatus::complete);
  EXPECT_EQ(store.targets(out.run_id).size(), 5u * 3u * 2u);
  ASSERT_EQ(store.results(out.run_id).size(), 1u);
  EXPECT_EQ(store.results(out.run_id)[0].standard, "ISO 230-2:2014");
  EXPECT_EQ(store.reading_count(out.run_id), static_cast<std::int64_t>(out.readings));
  EXPECT_EQ(store.instruments(out.run_id).size(), 3u);
  EXPECT_TRUE(store.missed_stops(out.run_id).empty());
  EXPECT_TRUE(r->origin_unix_ns.has_value());

  // Verdicts against limits set from the simulated truth (not from the measured values): E
  // 0.3 um above the true E (inside: the measurement is within 0.15 um of it), M 0.3 um below
  // the true M (outside).
  const nlohmann::json tol{{"E_um", truth.at("E_bi").value_um + 0.3},
                           {"M_um", truth.at("M").value_um - 0.3},
                           {"source", "tolerances.X"}};
  const auto v = daq::linear_verdict(tol, daq::to_json(*out.evaluation));
  ASSERT_TRUE(v.configured);
  EXPECT_FALSE(v.pass);
  ASSERT_EQ(v.checks.size(), 2u);
  EXPECT_EQ(v.checks[0].key, "E_bi");
  EXPECT_TRUE(v.checks[0].pass);
  EXPECT_EQ(v.checks[1].key, "M");
  EXPECT_FALSE(v.checks[1].pass);
  EXPECT_EQ(daq::summary(daq::linear_verdict(nullptr, daq::to_json(*out.evaluation))),
            "no tolerance configured");
  remove_db(db);
}

// A stop the machine never makes (the simulated program skips run 2 up at target 3): the
// run reaches the end of its plan but is stored incomplete, the stop listed as missed, and
// the evaluation says that target has one run fewer up.
TEST(LinearEndToEnd, ADroppedStopIsStoredIncompleteWithTheStopListed) {
  const auto db = temp_db("dropped");
  LinearShop s;
  auto setup = s.setup(db);
  std::vector<std::string> events;
  setup.on_event = [&events](const std::string& e) { events.push_back(e); };
  daq::LinearRun run(s.io, std::move(setup));
  run.start();
  ASSERT_TRUE(s.started());
  // The machine's program without the stop of run 2 up at target 3 (100 mm): it moves on.
  auto program = run.plan();
  const auto skipped = std::find_if(program.moves.begin(), program.moves.end(), [](const auto& m) {
    return m.kind == cal::iso230_2::MoveKind::measure && m.run == 2 &&
           m.direction == cal::iso230_2::Direction::up && m.target_index == 3;
  });
  ASSERT_NE(skipped, program.moves.end());
  program.moves.erase(skipped);
  s.shop.run_linear(program, s.config.linear->feed_mm_per_min, s.config.linear->dwell_s);
  s.shop.run_program([&] { return run.finished(); }, 30.0);
  ASSERT_TRUE(run.finished());
  const auto& out = run.outcome();
  ASSERT_TRUE(out.complete) << out.reason;  // the end of the plan was reached and evaluated
  EXPECT_EQ(out.status, cal::storage::RunStatus::incomplete);
  ASSERT_EQ(out.missed.size(), 1u);
  EXPECT_EQ(out.missed[0].run_number, 2);
  EXPECT_EQ(out.missed[0].direction, '+');
  EXPECT_EQ(out.missed[0].target_index, 2);  // 0-based: the third target
  EXPECT_DOUBLE_EQ(out.missed[0].nominal_mm, run.plan().targets_mm[2]);
  for (const auto& e : events) EXPECT_EQ(e.find("all stops captured"), std::string::npos) << e;
  EXPECT_NE(std::find(events.begin(), events.end(), "end of the plan: 1 of 30 stops missed"),
            events.end());

  cal::storage::Store store(db);
  const auto r = store.run(out.run_id);
  EXPECT_EQ(r->status, cal::storage::RunStatus::incomplete);
  EXPECT_EQ(r->note, "1 of 30 planned stops missed");
  const auto missed = store.missed_stops(out.run_id);
  ASSERT_EQ(missed.size(), 1u);
  EXPECT_EQ(missed[0].target_index, 2);
  EXPECT_EQ(store.targets(out.run_id).size(), 29u);
  // The evaluation's runs per direction: 3 everywhere but 2 at that target up.
  EXPECT_EQ(daq::runs_text(*out.evaluation),
            fmt::format("2 to 3 runs per direction (3 at every other target and direction; 2 at "
                        "{:.3f} mm up)",
                        run.plan().targets_mm[2]));
  ASSERT_EQ(store.results(out.run_id).size(), 1u);
  remove_db(db);
}

// The circle of the ballbar tests: R 100 mm at 1000 mm/min, the bar sampled at 1 kHz, on the
// simulated shop's bar (a line gauge on its serial port), stored in `db`.
constexpr cal::daq::BallbarProgram kShopCircle{
    .radius_mm = 100, .feed_mm_per_min = 1000, .sample_rate_hz = 1000};

daq::CircleRunSetup shop_circle_setup(boost::asio::io_context& io, daq::SimulatedShop& shop,
                                      const fs::path& db) {
  return {.program = kShopCircle,
          .database = db,
          .ballbar = d::make_gauge(
              io, t::make_serial(io, {.device = shop.ballbar_device(), .baud = 115200}),
              {.clock = shop.clock_ns()}, {.min_si = -0.1, .max_si = 0.1})};
}

TEST(CircleEndToEnd, BallbarDiagnosticsAgreeWithTheInjectedErrors) {
  // The shop's injected errors: squareness +20 um/m, Y lagging X by 1/29.7 - 1/30 s =
  // 0.3367 ms, backlash X 4 um, scale +8 um/m on X, pitch error 1 um / 40 mm on X, noise
  // 0.15 um on X. About 2 x 42,000 samples: the noise alone moves a coefficient by
  // ~0.15 / sqrt(42000) = 0.001 um; the tolerances cover the model's known departures:
  // the servo's unequal amplitude attenuation in the scale term (+0.3 um/m), the step of the
  // backlash shared with the reversal-spike term (~2 %), and the feed-in timing (a few ms of
  // angle offset).
  const auto db = temp_db("circle");
  // Simulated time that jumps from event to event (loop_time.hpp): loop seconds are simulated
  // seconds, and the run takes as long as the CPU needs.
  boost::asio::io_context io;
  d::VirtualTime::install(io);
  daq::SimulatedShop shop(io, daq::ShopTruth{}, 1.0);
  const auto program = kShopCircle;
  daq::CircleRun run(io, shop_circle_setup(io, shop, db));
  run.start();
  shop.run_circle(program);
  shop.run_program([&] { return run.finished(); }, 30.0);
  ASSERT_TRUE(run.finished());
  ASSERT_TRUE(run.outcome().complete) << run.outcome().reason;
  std::map<std::string, double> v;
  for (const auto& dg : run.outcome().result->diagnostics) v[dg.key] = dg.value;
  EXPECT_NEAR(v["squareness"], 20.0, 0.2);
  EXPECT_NEAR(v["servo_mismatch"], (1 / 29.7 - 1 / 30.0) * 1e3, 0.02);
  EXPECT_NEAR(v["backlash_X"], 4.0, 0.2);
  EXPECT_NEAR(v["scale_mismatch"], 8.3, 0.5);
  EXPECT_NEAR(v["cyclic_X"], 1.0, 0.1);
  cal::storage::Store store(db);
  ASSERT_EQ(store.results(run.outcome().run_id).size(), 1u);
  EXPECT_EQ(store.results(run.outcome().run_id)[0].standard, "ISO 230-4:2005");
  // Per-diagnostic limits from the injected errors: squareness 20 um/m against 20.3 (inside;
  // measured within 0.2 of the truth), backlash X 4 um against 3.7 (outside).
  const nlohmann::json tol{{"diagnostics", {{"squareness", 20.3}, {"backlash_X", 3.7}}}};
  const auto verdict = daq::circle_verdict(
      tol, daq::circle_json(*run.outcome().result, 100, "XY", program.feed_mm_per_min));
  ASSERT_EQ(verdict.checks.size(), 2u);
  EXPECT_TRUE(daq::find_check(verdict, "squareness")->pass);
  EXPECT_FALSE(daq::find_check(verdict, "backlash_X")->pass);
  EXPECT_EQ(daq::summary(verdict), "FAIL");
  remove_db(db);
}

TEST(CircleEndToEnd, ABallbarRunCommitsItsReadingsAsItGoesNotOnlyWhenABatchIsFull) {
  // A bar at 1 kHz fills a batch (16,384 readings) in 16 s; on a crash or a power loss what is
  // not committed is lost. The run offers its batch to the writer's age check every 100 ms
  // (simulated sessions: 5 s of simulated time), as the linear run does: 12 s into the program,
  // before any batch is full, most of the readings so far must be in the database, read by
  // another connection while the run goes on.
  const auto db = temp_db("circle-age");
  boost::asio::io_context io;
  auto& time = d::VirtualTime::install(io);
  daq::SimulatedShop shop(io, daq::ShopTruth{}, 1.0);
  const auto program = kShopCircle;
  daq::CircleRun run(io, shop_circle_setup(io, shop, db));
  run.start();
  const double t0 = time.now_s();
  shop.run_circle(program);
  shop.run_program([&] { return time.now_s() - t0 >= 12.0; }, 30.0);
  ASSERT_FALSE(run.finished());
  const auto read = run.outcome().readings;
  ASSERT_GT(read, 8'000u);   // the bar has been sending for most of the 12 s
  ASSERT_LT(read, 16'384u);  // no batch is full yet
  // Batches older than 5 s (simulated) are handed over within a tick: at least the readings
  // older than 5.1 s, at most all of them. The writer thread commits them in wall time: wait
  // for that (up to 10 s; without the run's age check nothing would come).
  const cal::storage::Store other(db, {.read_only = true});
  const auto least = static_cast<std::int64_t>(read) - 5'100;
  std::int64_t stored = 0;
  for (const auto until = std::chrono::steady_clock::now() + 10s;
       (stored = other.reading_count(run.outcome().run_id)) < least &&
       std::chrono::steady_clock::now() < until;)
    std::this_thread::sleep_for(10ms);
  EXPECT_GE(stored, least);
  EXPECT_LE(stored, static_cast<std::int64_t>(read));
  run.stop("test over");
  remove_db(db);
}

// One short linear run (2 runs over 3 targets) of the simulated shop on simulated time; what
// it stored: every reading and every captured stop's deviation.
struct StoredRun {
  std::vector<cal::storage::RawReading> readings;
  std::vector<double> deviations_um;
  std::uint64_t settle_timeouts = 0;
};
StoredRun short_simulated_run() {
  const auto db = temp_db("determinism");
  boost::asio::io_context io;
  auto& time = d::VirtualTime::install(io);
  daq::SimulatedShop shop(io, daq::ShopTruth{}, 1.0);
  cal::daq::Config c;
  c.machine_name = "e2e";
  c.trigger = {.tolerance_um = 1.0, .dwell_s = 1.5, .window_mm = 0.5};
  c.linear = cal::daq::LinearTestConfig{
      .first_mm = 0, .last_mm = 100, .count = 3, .runs = 2, .overrun_mm = 3, .dwell_s = 3};
  daq::LinearRunSetup setup;
  setup.config = c;
  setup.database = db;
  // No clock given: the instruments read the loop's (simulated) time.
  setup.laser = d::make_ids3010(
      io, t::make_tcp(io, {.host = "127.0.0.1", .port = shop.laser_port()}), {.poll_period = 10ms});
  setup.air = d::make_ptu300(
      io, t::make_serial(io, t::parse_serial_settings("4800 7E1", {.device = shop.air_device()})),
      {.poll_period = 1s});
  setup.material.push_back(d::make_gauge(
      io, t::make_serial(io, {.device = shop.material_device()}), {.poll_period = 1s},
      {.request = "?\r", .unit = d::codec::GaugeUnit::degc, .min_si = -40, .max_si = 150}));
  daq::StartupReadings read(1);
  setup.on_reading = [&read](const d::Reading& r) { read.add(r); };
  daq::LinearRun run(io, std::move(setup));
  run.start();
  EXPECT_TRUE(shop.wait_until([&] { return read.all(); }));
  shop.run_linear(run.plan(), c.linear->feed_mm_per_min, c.linear->dwell_s);
  shop.run_program([&] { return run.finished(); }, 30.0);
  EXPECT_TRUE(run.finished());
  EXPECT_TRUE(run.outcome().complete) << run.outcome().reason;
  StoredRun out;
  {
    cal::storage::Store store(db);
    out.readings = store.readings(run.outcome().run_id);
    for (const auto& target : store.targets(run.outcome().run_id))
      out.deviations_um.push_back(target.deviation_um);
  }
  out.settle_timeouts = time.stats().settle_timeouts;
  remove_db(db);
  return out;
}

// Simulated time makes a run a function of its inputs alone: run twice, the second time with
// both cores of a 2-core machine kept busy by two spinning threads, it stores the same readings
// bit for bit (times, devices, channels, quantities, statuses, values) and the same stops. With
// the shop paced by the wall clock, the readings' times and values would differ run to run.
TEST(LinearEndToEnd, TheSameSimulatedRunTwiceStoresTheSameReadingsBitForBitUnderLoad) {
  const StoredRun quiet = short_simulated_run();
  std::atomic<bool> stop{false};
  std::vector<std::thread> load;
  for (int i = 0; i < 2; ++i)
    load.emplace_back([&stop] {
      volatile std::uint64_t n = 0;
      while (!stop.load(std::memory_order_relaxed)) n = n + 1;
    });
  const StoredRun loaded = short_simulated_run();
  stop = true;
  for (auto& th : load) th.join();

  // About 45 s of simulated time: a 100 Hz laser, the air and material sensors at 1 Hz.
  ASSERT_GT(quiet.readings.size(), 4'000u);
  ASSERT_EQ(quiet.readings.size(), loaded.readings.size());
  for (std::size_t i = 0; i < quiet.readings.size(); ++i) {
    const auto &a = quiet.readings[i], &b = loaded.readings[i];
    ASSERT_EQ(a.time_ns, b.time_ns) << i;
    ASSERT_EQ(a.device, b.device) << i;
    ASSERT_EQ(a.channel, b.channel) << i;
    ASSERT_EQ(a.quantity, b.quantity) << i;
    ASSERT_EQ(a.status, b.status) << i;
    ASSERT_EQ(std::bit_cast<std::uint64_t>(a.value), std::bit_cast<std::uint64_t>(b.value)) << i;
  }
  ASSERT_EQ(quiet.deviations_um.size(), 12u);  // 2 runs x 3 targets x 2 directions
  ASSERT_EQ(quiet.deviations_um.size(), loaded.deviations_um.size());
  for (std::size_t i = 0; i < quiet.deviations_um.size(); ++i)
    EXPECT_EQ(std::bit_cast<std::uint64_t>(quiet.deviations_um[i]),
              std::bit_cast<std::uint64_t>(loaded.deviations_um[i]))
        << i;
  EXPECT_EQ(quiet.settle_timeouts, 0u);
  EXPECT_EQ(loaded.settle_timeouts, 0u);
}

TEST(LinearEndToEnd, KillDashNineMidRunLeavesAReadableIncompleteRun) {
  const auto db = temp_db("kill");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const int devnull = ::open("/dev/null", O_WRONLY);
    ::dup2(devnull, STDOUT_FILENO);
    const std::string capture = db.string() + ".cdq";
    // Paced by the wall clock (60x), so that it is still running when it is killed.
    ::execl(CALDAQ_DAQ_BINARY, "daq", "demo", "--quiet", "--speed", "60", "--db", db.c_str(),
            "--capture", capture.c_str(), nullptr);
    ::_exit(127);
  }
  // Wait until the run has stored some readings (committed batches), then kill.
  std::int64_t stored = 0;
  for (int i = 0; i < 200 && stored == 0; ++i) {
    std::this_thread::sleep_for(50ms);
    if (!fs::exists(db)) continue;
    try {
      cal::storage::Store peek(db);
      if (auto runs = peek.runs(); !runs.empty()) stored = peek.reading_count(runs[0].id);
    } catch (const cal::storage::StoreError&) {
    }
  }
  ASSERT_GT(stored, 0) << "the demo never stored a reading";
  ::kill(child, SIGKILL);
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFSIGNALED(status));

  cal::storage::Store store(db);
  const auto runs = store.runs();
  ASSERT_EQ(runs.size(), 1u);
  EXPECT_EQ(runs[0].status, cal::storage::RunStatus::incomplete);
  EXPECT_GE(store.reading_count(runs[0].id), stored);  // nothing committed was lost
  EXPECT_EQ(static_cast<std::int64_t>(store.readings(runs[0].id).size()),
            store.reading_count(runs[0].id));
  remove_db(db);
  fs::remove(db.string() + ".cdq");
}

TEST(LinearEndToEnd, ReplayingTheCaptureGivesIdenticalStoredResults) {
  const auto db = temp_db("replay");
  const auto capture = fs::path(db.string() + ".cdq");
  const std::string daq = CALDAQ_DAQ_BINARY;
  ASSERT_EQ(std::system((daq + " demo --quiet --db '" + db.string() + "' --capture '" +
                         capture.string() + "' > /dev/null")
                            .c_str()),
            0);
  ASSERT_EQ(std::system(
                (daq + " replay '" + capture.string() + "' --db '" + db.string() + "' > /dev/null")
                    .c_str()),
            0);
  cal::storage::Store store(db);
  const auto runs = store.runs();
  ASSERT_EQ(runs.size(), 3u);  // the demo's linear run and circle, then the replay
  EXPECT_EQ(runs[1].kind, "circle");
  EXPECT_EQ(runs[2].capture_path, fs::absolute(capture).string());
  // The same bytes through the same instruments and stages: the same readings (with their
  // timestamps), the same captured stops, the same result document.
  const auto a = store.readings(runs[0].id), b = store.readings(runs[2].id);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].time_ns, b[i].time_ns) << i;
    ASSERT_EQ(a[i].value, b[i].value) << i;
  }
  const auto ta = store.targets(runs[0].id), tb = store.targets(runs[2].id);
  ASSERT_EQ(ta.size(), tb.size());
  for (std::size_t i = 0; i < ta.size(); ++i) EXPECT_EQ(ta[i].deviation_um, tb[i].deviation_um);
  ASSERT_EQ(store.results(runs[0].id).size(), 1u);
  EXPECT_EQ(store.results(runs[0].id)[0].json, store.results(runs[2].id)[0].json);
  remove_db(db);
  fs::remove(capture);
}

}  // namespace
