// End to end: the 21 geometric errors of a SIMULATED machine measured through the one linear
// runner (kinds: positioning, straightness, angular, roll) with the real drivers against the
// twins, stored, the model built from the stored runs and compared with the injected truth;
// then the verification loop: compensate with the built model, measure again.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <map>
#include <random>

#include "../support/temp_db.hpp"
#include "cal/analysis/volumetric_comp.hpp"
#include "cal/storage/store.hpp"
#include "kinds/kind.hpp"
#include "model/model_build.hpp"
#include "sim_volumetric.hpp"
#include "stored_model.hpp"

namespace {

namespace fs = std::filesystem;
namespace kin = cal::kinematics;
namespace mdl = cal::daq::model;

fs::path temp_db(const char* name) { return cal::test::temp_path("caldaq-vol", name); }
using cal::test::remove_db;

// The campaign's tests as acquired here: the machine stands 2.5 s at each stop instead of 4 s
// (the trigger's 1.5 s dwell after the servo has settled, about 0.3 s at Kv 30 from a 3 mm
// following error, leaves 0.7 s for the gauges polled at 10 Hz; the run refuses a stop whose
// probe reading comes later). The truth has no noise, so the stops' values do not depend on
// how long they are averaged: the tolerances below hold as with 4 s. Simulated time per
// campaign 1,370 s -> 1,050 s.
std::vector<cal::daq::LinearTestConfig> campaign() {
  auto tests = daq::volumetric_tests();
  for (auto& l : tests) l.dwell_s = 2.5;
  return tests;
}

// The laser at 50 Hz of simulated time instead of 100 Hz: half the TCP round trips through
// the kernel (most of the test's CPU). A 3 mm overrun excursion at 6000 mm/min (about 0.1 s)
// still gets 5 readings, and at a stop the 1.5 s window 75 readings of a still machine.
// SQLite at synchronous=NORMAL (WAL): no fdatasync per commit (about 450 per campaign, on the
// loop's thread), which only a power loss would need; nothing here reads the disk's state
// after one.
daq::SimulatedAcquisition acquisition(kin::Topology t, const fs::path& db) {
  return {.truth = daq::volumetric_truth(t),
          .database = db,
          .laser_poll_s = 0.02,
          .store_options = {.full_sync = false}};
}

// One test acquired; measured once more when its run refused a stop because the probe's answer
// came after the machine had left (docs/iso230-2.md, "Which samples make a stop's value"), as an
// operator would. On simulated time that happens only when this process is starved: the clock
// forgets bytes still in flight after VirtualTime::kSettle of wall time and jumps to the
// probe's next deadline (seen once in a clean-clone scripts/test, ctest -j3 on 2 cores, when
// kSettle was 200 ms: "answers came up to 3000 ms after their requests (median 0 ms)"; now
// 2 s); the old rule took the value measured there. The refused run stays stored as aborted (the
// build takes the newer).
daq::LinearRunOutcome acquire_measuring_again(const daq::SimulatedAcquisition& a,
                                              const cal::daq::LinearTestConfig& test) {
  auto out = daq::acquire_simulated(a, test);
  if (!out.complete && out.reason.find("after their requests") != std::string::npos) {
    std::printf("measured again: %s: %s\n", out.component.c_str(), out.reason.c_str());
    out = daq::acquire_simulated(a, test);
  }
  return out;
}

// Every test of the campaign acquired and stored; the model built from the store.
mdl::BuildReport measure_and_build(const daq::SimulatedAcquisition& a, kin::Topology t) {
  for (const auto& test : campaign()) {
    const auto out = acquire_measuring_again(a, test);
    EXPECT_TRUE(out.complete) << kin::to_string(t) << " " << out.component << ": " << out.reason;
  }
  cal::storage::Store store(a.database, {.read_only = true});
  const auto stored = daq::stored_profiles(store, a.machine);
  EXPECT_EQ(stored.profiles.size(), 18u);
  EXPECT_EQ(stored.topology, t);  // recorded with each run ([machine] topology)
  return mdl::build(stored.profiles, {.machine = a.machine, .topology = t});
}

// The largest |f(p)| over the targets' grid of the simulated travel (6 x 6 x 6 points: where
// the measured tables have their points).
double max_over_grid_um(const std::function<kin::Vec3(const kin::Vec3&)>& f) {
  double worst = 0;
  for (int i = 0; i <= 5; ++i)
    for (int j = 0; j <= 5; ++j)
      for (int k = 0; k <= 5; ++k) {
        const kin::Vec3 p{500.0 * i / 5, 400.0 * j / 5, 300.0 * k / 5};
        const auto e = f(p);
        worst = std::max(worst, std::hypot(e[0], e[1], e[2]));
      }
  return worst;
}

// The model's own volumetric correction (cal::volcomp::correction_um, what the ISG volumetric
// compensation file holds), applied by the simulated control, positions held within the tables.
std::function<kin::Vec3(const kin::Vec3&)> control_compensation(const mdl::Model& m) {
  return [m](const kin::Vec3& p) {
    kin::Vec3 q = p;
    for (std::size_t k = 0; k < 3; ++k)
      q[k] = std::clamp(q[k], (*m.travel_mm)[k][0], (*m.travel_mm)[k][1]);
    return cal::volcomp::correction_um(m.machine, q, m.carriers);
  };
}

// The 21 errors recovered, for four chains (a gantry, a cross table, the Makino-like YFXZ and a
// horizontal centre). Tolerances, from what limits the measurement (the truth has no noise):
// the indicator's 10 nm digits and the laser's picometre ones, the air compensation of the
// differential beams (the air sensors' rounding: < 0.01 ppm of 100 mm), the servo's settling
// in a 1 s window (< 1 nm), and the first-order Abbe correction against the simulated HTM
// (angles <= 20 urad, arms <= 700 mm: < 0.01 um). Translations within 0.03 um, angles within
// 0.02 urad, squareness within 0.1 urad (a slope of 6 points over 300 mm: 10 nm / 300 mm).
class Recovered : public ::testing::TestWithParam<kin::Topology> {};

TEST_P(Recovered, AllTwentyOneErrorsFromTheStoredRuns) {
  const auto t = GetParam();
  const auto db = temp_db("recover");
  const auto a = acquisition(t, db);
  const auto r = measure_and_build(a, t);
  EXPECT_TRUE(r.missing.empty()) << fmt::format("{}", fmt::join(r.missing, ","));
  const auto& truth = *a.truth.geometry;
  const auto& built = r.model.machine;
  for (kin::Component c : kin::all_components()) {
    const auto i = static_cast<std::size_t>(c);
    const double L = daq::kSimTravelMm[i / 6];
    const double tol = i % 6 >= 3 ? 0.02 : 0.03;
    for (int s = 0; s <= 5; ++s) {
      const double q = L * s / 5;  // the targets
      EXPECT_NEAR(kin::component(built, c)(q), kin::component(truth, c)(q), tol)
          << kin::to_string(t) << " " << kin::to_string(c) << " at " << q << " mm";
    }
  }
  EXPECT_NEAR(built.squareness.c0y_urad, truth.squareness.c0y_urad, 0.1) << kin::to_string(t);
  EXPECT_NEAR(built.squareness.b0z_urad, truth.squareness.b0z_urad, 0.1) << kin::to_string(t);
  EXPECT_NEAR(built.squareness.a0z_urad, truth.squareness.a0z_urad, 0.1) << kin::to_string(t);
  remove_db(db);
}

INSTANTIATE_TEST_SUITE_P(Chains, Recovered,
                         ::testing::Values(kin::Topology::fxyz, kin::Topology::xyfz,
                                           kin::Topology::yfxz, kin::Topology::zfxy),
                         [](const auto& p) { return std::string(kin::to_string(p.param)); });

// The range of a stored run's profile (the mean of each target's stops), um.
double profile_range_um(const fs::path& db, std::int64_t run) {
  cal::storage::Store store(db, {.read_only = true});
  std::map<int, std::pair<double, int>> by;
  for (const auto& t : store.targets(run))
    by[t.target_index].first += t.deviation_um, ++by[t.target_index].second;
  double lo = INFINITY, hi = -INFINITY;
  for (const auto& [i, v] : by)
    lo = std::min(lo, v.first / v.second), hi = std::max(hi, v.first / v.second);
  return hi - lo;
}

// The verification loop (docs/volumetric-walkthrough.md, "The verification loop"): inject,
// measure all 21 through the acquisition, build the model (for the probe as the tool), let the
// simulated control apply the model's own volumetric correction, and measure again what the
// tool does: every positioning and straightness run of the campaign, at the stationary
// positions of the first campaign and at the far corner of the travel (not measured before).
//
// The bound. With the correction c(p) = -e1(p) of the first-order model built from the
// measurements, the tool lands at p + c + e(p + c) = [e(p) - e1(p)] + [e(p + c) - e(p)]:
// - e - e1: the measured model against the truth (the recovery tolerances above, 0.03 um
//   per translation and 0.02 urad per angle over arms up to 0.8 m, summed over a point's
//   contributions: <= 0.1 um) plus HTM - first order (angles <= 25 urad, arms <= 0.8 m: 1e-3 um);
// - e(p + c) - e(p) <= |c| |de/dp| ~ 25 um x 5e-5 ~ 1e-3 um: the second-order term.
// So the residual is bounded by 0.1 um, the measurement's own error, against about 20 um
// before; the measured profiles' ranges (each a difference of two points) by 0.2 um.
TEST(VolumetricLoop, CompensatedWithTheBuiltModelTheResidualIsSecondOrder) {
  const auto t = kin::Topology::yfxz;
  const auto db1 = temp_db("loop1"), db2 = temp_db("loop2");
  const auto first = acquisition(t, db1);
  const kin::Vec3 probe{0.0, 0.0, -100.0};  // the campaign's probe: the tool compensated for
  auto built = measure_and_build(first, t).model;
  built.machine.tool_offset_mm = probe;
  auto truth = *first.truth.geometry;
  truth.tool_offset_mm = probe;

  const auto comp = control_compensation(built);
  const double before = max_over_grid_um(
      [&](const kin::Vec3& p) { return kin::volumetric_error_um(truth, p, kin::Method::htm); });
  // The truth's residual at the grid: the simulated machine driven to p + c(p).
  const double residual = max_over_grid_um(
      [&](const kin::Vec3& p) { return cal::volcomp::residual_um(truth, p, comp(p)); });
  // The second-order term alone: the same with the truth's own correction (no measurement).
  const double second_order = max_over_grid_um([&](const kin::Vec3& p) {
    return cal::volcomp::residual_um(truth, p, cal::volcomp::correction_um(truth, p));
  });

  // Measured again with the control compensating: what the tool does along every line.
  daq::SimulatedAcquisition again = first;
  again.database = db2;
  again.compensation = comp;
  double worst_before = 0, worst_after = 0;
  for (const auto& test : campaign()) {
    if (test.measure.kind != "positioning" && test.measure.kind != "straightness") continue;
    for (const auto& stationary :
         {test.measure.stationary_mm, std::array<double, 3>{500, 400, 300}}) {
      auto l = test;
      l.measure.stationary_mm = stationary;
      const auto out = acquire_measuring_again(again, l);
      ASSERT_TRUE(out.complete) << out.component << ": " << out.reason;
      const double r = profile_range_um(db2, out.run_id);
      if (r > 0.1) {
        cal::storage::Store st(db2, {.read_only = true});
        for (const auto& tt : st.targets(out.run_id))
          std::printf("  %s %c %g: %.4f\n", out.component.c_str(), tt.direction, tt.nominal_mm,
                      tt.deviation_um);
      }
      worst_after = std::max(worst_after, r);
      EXPECT_LT(r, 0.2) << out.component << " at " << stationary[0] << ", " << stationary[1] << ", "
                        << stationary[2];
    }
  }
  {
    cal::storage::Store store(db1, {.read_only = true});
    for (const auto& r : store.runs())
      if (r.kind == "linear" || r.kind == "straightness")
        worst_before = std::max(worst_before, profile_range_um(db1, r.id));
  }
  std::printf(
      "loop %s: max |e| over the grid before %.3f um, after (truth) %.4f um, second-order term "
      "alone %.5f um; measured profiles' largest range before %.3f um, after %.4f um\n",
      std::string(kin::to_string(t)).c_str(), before, residual, second_order, worst_before,
      worst_after);
  EXPECT_GT(before, 10.0);
  EXPECT_LT(second_order, 0.005);
  EXPECT_LT(residual, 0.1);
  EXPECT_GT(worst_before, 5.0);
  remove_db(db1);
  remove_db(db2);
}

}  // namespace
