// End to end: the quality gates of a run's stops (issue 26). A polled probe whose answers come
// late still gives each stop the value measured there; an outlier stop marks the run suspect.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <tuple>

#include "../support/daq_cli.hpp"
#include "../support/temp_db.hpp"
#include "cal/drivers/instrument.hpp"
#include "cal/storage/store.hpp"
#include "run_quality.hpp"
#include "sim_volumetric.hpp"

namespace {

namespace fs = std::filesystem;
namespace kin = cal::kinematics;

fs::path temp_db(const char* name) { return cal::test::temp_path("caldaq-quality", name); }
using cal::test::remove_db;

using StopKey = std::tuple<int, char, int>;  // run, direction, target

std::map<StopKey, double> stored_stops(const fs::path& db, std::int64_t run) {
  cal::storage::Store store(db, {.read_only = true});
  std::map<StopKey, double> out;
  for (const auto& t : store.targets(run))
    out[{t.run_number, t.direction, t.target_index}] = t.deviation_um;
  return out;
}

daq::LinearRunOutcome acquire(const fs::path& db, double probe_delay_s,
                              bool measures_on_answer = false) {
  daq::SimulatedAcquisition a{.truth = daq::volumetric_truth(kin::Topology::xfyz),
                              .database = db,
                              .laser_poll_s = 0.02,
                              .store_options = {.full_sync = false}};
  a.truth.probe_answer_delay_s = probe_delay_s;
  a.truth.probe_measures_on_answer = measures_on_answer;
  return daq::acquire_simulated(a, daq::volumetric_test("E_YX"));
}

// The largest difference between two runs' stops (same keys), um; and how different the
// targets are (what a stop given a neighbour's value would show).
struct StopsCompared {
  double max_difference_um = 0.0, target_spread_um = 0.0;
};
StopsCompared compare_stops(const fs::path& db, std::int64_t expected_run, std::int64_t run) {
  const auto expected = stored_stops(db, expected_run);
  const auto got = stored_stops(db, run);
  EXPECT_EQ(expected.size(), 12u);  // 6 targets, up and down
  EXPECT_EQ(got.size(), expected.size());
  StopsCompared c;
  for (const auto& [key, value] : expected) {
    if (!got.count(key)) {
      ADD_FAILURE() << "run " << std::get<0>(key) << std::get<1>(key) << " target "
                    << std::get<2>(key) << " not stored";
      continue;
    }
    c.max_difference_um = std::max(c.max_difference_um, std::abs(got.at(key) - value));
    c.target_spread_um = std::max(c.target_spread_um, std::abs(value - expected.begin()->second));
  }
  return c;
}

// The machine stands 4 s at a target (volumetric_test: dwell 4 s, 1 s moving); the trigger
// captures after 1.5 s still, so the window is about 1.5 s and the machine stands at least
// 1.5 s after it (the run's bound: min(trigger dwell, dwell - trigger dwell)).
//
// The indicator's answers come 2 s after their requests, each value measured at its request.
// Stamped with its request and its answer's delay, a sample counts for a stop when both lie
// where the machine stood: the first second of each window. Each stop gets a mean of the
// samples measured there: the on-time run's values within the indicator's noise (0.02 um a
// sample, the means of 10 and 15 of them), where a neighbour's value is microns off. Stamped on
// arrival (before issue 26), the stops took values measured 2 s earlier, on the way.
TEST(LateProbe, EachStopGetsTheValueMeasuredWhileTheMachineStoodThere) {
  const auto db = temp_db("late");
  const auto on_time = acquire(db, 0.0);
  const auto late = acquire(db, 2.0);
  ASSERT_TRUE(on_time.complete) << on_time.reason;
  ASSERT_TRUE(late.complete) << late.reason;
  // Neither is suspect: the check finds no outlier in a clean run (stored with it).
  EXPECT_EQ(on_time.quality.state, "ok") << on_time.quality.summary;
  EXPECT_EQ(late.quality.state, "ok") << late.quality.summary;
  const auto c = compare_stops(db, on_time.run_id, late.run_id);
  EXPECT_LT(c.max_difference_um, 0.03);
  EXPECT_GT(c.target_spread_um, 0.5);  // the test would see a neighbour's value

  // The latency is measured and stated with the result.
  cal::storage::Store store(db, {.read_only = true});
  const auto results = store.results(late.run_id);
  ASSERT_FALSE(results.empty());
  const auto prov = nlohmann::json::parse(results.back().provenance_json);
  ASSERT_TRUE(prov.contains("probe_answer_latency")) << prov.dump();
  EXPECT_NEAR(prov["probe_answer_latency"]["median_ms"].get<double>(), 2000.0, 1.0);
  EXPECT_GT(prov["probe_answer_latency"]["answers"].get<int>(), 100);
  remove_db(db);
}

// Answers 4 s late: no sample's interval [request, answer] lies where the machine stood (the
// window and the 1.5 s after it), so no stop can be given a value that is surely its own: the
// run ends saying so, naming the latency, rather than store a value measured elsewhere.
TEST(LateProbe, AnswersLaterThanTheMachineStandsAreRefusedNamingTheLatency) {
  const auto db = temp_db("toolate");
  const auto late = acquire(db, 4.0);
  EXPECT_FALSE(late.complete);
  EXPECT_NE(late.reason.find("after their requests"), std::string::npos) << late.reason;
  EXPECT_NE(late.reason.find("4000 ms"), std::string::npos) << late.reason;
  remove_db(db);
}

// The walkthrough at 10x under load (issue 26): a starved twin process answered 0.3 s late
// with the value of when it answered, the machine at the next target; stamped with the request
// alone, the stop took it (0.43 um off). Here: answers 3 s late, each measured when answered.
// The last half second of each window's requests is answered after the machine has left: the
// old rule (the request's time alone) stored every stop, one 0.11 um off. No sample's
// [request, answer] lies where the machine stood, so the run is refused at its first stop,
// naming the latency: never a value measured elsewhere.
TEST(LateProbe, AValueMeasuredWhenItIsAnsweredIsNeverTakenForAStopTheMachineLeft) {
  const auto db = temp_db("onanswer");
  const auto late = acquire(db, 3.0, true);
  EXPECT_FALSE(late.complete);
  EXPECT_NE(late.reason.find("no straightness reading measured while the machine stood at "
                             "0.000 mm"),
            std::string::npos)
      << late.reason;
  EXPECT_NE(late.reason.find("up to 3000 ms after their requests"), std::string::npos)
      << late.reason;
  remove_db(db);
}

// Answers 1 s late, each measured when answered: every window sample is answered while the
// machine still stands (1.5 s after the capture at least), so every stop gets the mean of its
// own window's samples: the on-time run's values within the indicator's noise.
TEST(LateProbe, AValueAnsweredWhileTheMachineStillStandsIsTaken) {
  const auto db = temp_db("onanswer1");
  const auto on_time = acquire(db, 0.0);
  const auto late = acquire(db, 1.0, true);
  ASSERT_TRUE(on_time.complete) << on_time.reason;
  ASSERT_TRUE(late.complete) << late.reason;
  const auto c = compare_stops(db, on_time.run_id, late.run_id);
  EXPECT_LT(c.max_difference_um, 0.03);
  EXPECT_GT(c.target_spread_um, 0.5);
  remove_db(db);
}

using cal::test::daq_cli;

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
    record.uuid.clear();  // a new run: its own identity (the copy would share the UUID)
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

// A straightness run's indicator reads the straightedge only: the machine stands at the start
// of the line when the run begins, as it does when the indicator is set up there. Started at the
// origin, the simulated machine traversed 240 mm in Y to the line first, and the indicator read
// that move's following error (-2.7 mm at the volumetric shop's feed and Kv), a dip which made
// the report's readings plot print in mm and flattened the micrometre profile. Every reading now
// lies within the injected straightness and the servo's noise: a few micrometres.
TEST(IndicatorReadings, AStraightnessRunReadsOnlyItsStraightedge) {
  const auto db = temp_db("indicator");
  const auto run = acquire(db, 0.0);
  ASSERT_TRUE(run.complete) << run.reason;
  cal::storage::Store store(db, {.read_only = true});
  const std::uint8_t length[] = {static_cast<std::uint8_t>(cal::drivers::Quantity::length_m)};
  const auto readings = store.readings(run.run_id, length);
  ASSERT_GT(readings.size(), 100u);
  double lo = 0, hi = 0;
  for (const auto& r : readings) lo = std::min(lo, r.value), hi = std::max(hi, r.value);
  EXPECT_GT(lo, -20e-6) << "m, the first reading " << readings.front().value;
  EXPECT_LT(hi, 20e-6);
  remove_db(db);
}

}  // namespace
