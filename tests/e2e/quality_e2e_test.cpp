// End to end: the quality gates of a run's stops (issue 26). A polled probe whose answers come
// late still gives each stop the value measured there; an outlier stop marks the run suspect.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <tuple>

#include "cal/storage/store.hpp"
#include "run_quality.hpp"
#include "sim_volumetric.hpp"

namespace {

namespace fs = std::filesystem;
namespace kin = cal::kinematics;

fs::path temp_db(const char* name) {
  return fs::temp_directory_path() /
         (std::string("caldaq-quality-") + name + "-" + std::to_string(::getpid()) + "-" +
          std::to_string(std::random_device{}()) + ".sqlite");
}
void remove_db(const fs::path& p) {
  for (const char* s : {"", "-wal", "-shm"}) fs::remove(p.string() + s);
}

using StopKey = std::tuple<int, char, int>;  // run, direction, target

std::map<StopKey, double> stored_stops(const fs::path& db, std::int64_t run) {
  cal::storage::Store store(db, {.read_only = true});
  std::map<StopKey, double> out;
  for (const auto& t : store.targets(run))
    out[{t.run_number, t.direction, t.target_index}] = t.deviation_um;
  return out;
}

daq::LinearRunOutcome acquire(const fs::path& db, double probe_delay_s) {
  daq::SimulatedAcquisition a{.truth = daq::volumetric_truth(kin::Topology::xfyz),
                              .database = db,
                              .laser_poll_s = 0.02,
                              .store_options = {.full_sync = false}};
  a.truth.probe_answer_delay_s = probe_delay_s;
  return daq::acquire_simulated(a, daq::volumetric_test("E_YX"));
}

// The indicator's answers come 4 s after their requests: longer than the 3.5 s from one stop's
// capture window to the next's (4 s standing, 1 s moving), so what arrives during a stop's
// window was measured at the stop before. Stamped with their requests' times, each stop still
// gets the value measured while the machine stood there: the same as with answers on time
// (the mean of the same samples). Stamped on arrival (before issue
// 26), the stops took the previous target's values, microns off.
TEST(LateProbe, EachStopGetsTheValueMeasuredWhileTheMachineStoodThere) {
  const auto db = temp_db("late");
  const auto on_time = acquire(db, 0.0);
  const auto late = acquire(db, 4.0);
  ASSERT_TRUE(on_time.complete) << on_time.reason;
  ASSERT_TRUE(late.complete) << late.reason;
  // Neither is suspect: the check finds no outlier in a clean run (stored with it).
  EXPECT_EQ(on_time.quality.state, "ok") << on_time.quality.summary;
  EXPECT_EQ(late.quality.state, "ok") << late.quality.summary;
  const auto expected = stored_stops(db, on_time.run_id);
  const auto got = stored_stops(db, late.run_id);
  ASSERT_EQ(expected.size(), 12u);  // 6 targets, up and down
  ASSERT_EQ(got.size(), expected.size());
  double spread = 0;  // how different the targets are: what a wrong match would show
  for (const auto& [key, value] : expected) {
    ASSERT_TRUE(got.count(key));
    EXPECT_NEAR(got.at(key), value, 1e-9)
        << "run " << std::get<0>(key) << std::get<1>(key) << " target " << std::get<2>(key);
    spread = std::max(spread, std::abs(value - expected.begin()->second));
  }
  EXPECT_GT(spread, 0.5);  // the test would see a neighbour's value

  // The latency is measured and stated with the result.
  cal::storage::Store store(db, {.read_only = true});
  const auto results = store.results(late.run_id);
  ASSERT_FALSE(results.empty());
  const auto prov = nlohmann::json::parse(results.back().provenance_json);
  ASSERT_TRUE(prov.contains("probe_answer_latency")) << prov.dump();
  EXPECT_NEAR(prov["probe_answer_latency"]["median_ms"].get<double>(), 4000.0, 1.0);
  EXPECT_GT(prov["probe_answer_latency"]["answers"].get<int>(), 100);
  remove_db(db);
}

struct Cli {
  int status = 0;
  std::string output;
};
Cli daq_cli(const std::string& args, const fs::path& out) {
  const int rc = std::system(
      (std::string(CALDAQ_DAQ_BINARY) + " " + args + " >'" + out.string() + "' 2>&1").c_str());
  std::ifstream in(out);
  std::stringstream text;
  text << in.rdbuf();
  return {rc, text.str()};
}

// A stored run with one stop 0.5 um off among stops repeatable to 0.003 um (the walkthrough's
// wrong stop): suspect, with that stop named; `daq model build` refuses it naming the run, and
// builds with --accept-suspect RUN, recording it in the model's provenance. The clean run
// before it is not suspect.
TEST(SuspectRun, AnOutlierStopIsRefusedByModelBuildUnlessAccepted) {
  const auto db = temp_db("outlier");
  const auto clean = acquire(db, 0.0);
  ASSERT_TRUE(clean.complete) << clean.reason;
  EXPECT_EQ(clean.quality.state, "ok") << clean.quality.summary;
  std::int64_t bad = 0;
  {
    cal::storage::Store store(db);
    auto record = *store.run(clean.run_id);
    bad = store.begin_run(record);
    auto stops = store.targets(clean.run_id);
    for (auto& t : stops) {
      t.run_id = bad;
      if (t.target_index == 3 && t.direction == '-') t.deviation_um += 0.5;
    }
    store.add_targets(stops);
    store.finish_run(bad, cal::storage::RunStatus::complete);
    // Stored without a quality (as an import or an older run): assessed when read.
    const auto q = daq::run_quality(store, bad);
    EXPECT_EQ(q.state, "suspect") << q.summary;
    ASSERT_EQ(q.suspects.size(), 2u) << q.summary;  // up and down at 300 mm disagree
    EXPECT_EQ(q.suspects[0].target_index, 3);
    EXPECT_NE(q.summary.find("at 300 mm"), std::string::npos) << q.summary;
    EXPECT_EQ(daq::run_quality(store, clean.run_id).state, "ok");
  }
  const auto model = fs::path(db.string() + ".model.json");
  const auto out = fs::path(db.string() + ".out");
  const std::string build = "model build --machine 'SIMULATED volumetric' --allow-missing --db '" +
                            db.string() + "' -o '" + model.string() + "'";
  const auto refused = daq_cli(build, out);
  EXPECT_NE(refused.status, 0) << refused.output;
  EXPECT_NE(refused.output.find("run " + std::to_string(bad) + ":"), std::string::npos)
      << refused.output;
  EXPECT_NE(refused.output.find("--accept-suspect"), std::string::npos) << refused.output;
  EXPECT_FALSE(fs::exists(model));
  const auto accepted = daq_cli(build + " --accept-suspect " + std::to_string(bad), out);
  ASSERT_EQ(accepted.status, 0) << accepted.output;
  EXPECT_NE(accepted.output.find("SUSPECT run " + std::to_string(bad)), std::string::npos)
      << accepted.output;
  std::ifstream in(model);
  const auto doc = nlohmann::json::parse(in);
  EXPECT_EQ(doc["provenance"]["accepted_suspect_runs"], nlohmann::json::array({bad}))
      << doc["provenance"].dump();
  fs::remove(model);
  fs::remove(out);
  remove_db(db);
}

}  // namespace
