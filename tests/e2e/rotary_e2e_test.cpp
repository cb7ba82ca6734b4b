// End to end (issue 36 c): a rotary axis's angular positioning per ISO 230-2 acquired by the
// one linear runner. The SIMULATED shop turns its C axis through the plan 0 .. 360 deg every
// 45 deg (3 deg overrun, 5 runs each way) with known injected errors; its SIMULATED angular
// reference (a rotary indexer's readout, arcsec lines modulo a turn on a pseudo-terminal) is
// read through the real gauge driver; the runner recognises the stops from that stream alone
// (no laser), stores them and evaluates them in arcsec. On simulated time (VirtualTime), so the
// same readings on a loaded machine.
#include <gtest/gtest.h>

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "../support/temp_db.hpp"
#include "cal/analysis/error.hpp"
#include "cal/storage/store.hpp"
#include "sim_volumetric.hpp"

namespace {

namespace fs = std::filesystem;

// The injected truth, written out here from the shop's numbers (not through its own formula):
// the axis stops half the backlash short of its target (below it approached from below), and
// at the angle it is driven to carries the encoder's scale error and the worm's cyclic error;
// the reference reads zero_arcsec at the axis's 0 deg.
double truth_arcsec(const daq::ShopTruth::Rotary& r, double target_deg, bool up) {
  const double driven_deg = target_deg + (up ? -0.5 : 0.5) * r.backlash_arcsec / 3600.0;
  return r.zero_arcsec + r.scale_arcsec_per_turn * driven_deg / 360.0 +
         r.cyclic_arcsec * std::sin(2 * std::numbers::pi * driven_deg / r.cyclic_period_deg) +
         (up ? -0.5 : 0.5) * r.backlash_arcsec;
}

// Tolerances, from what limits the measurement: the axis's 0.3" of position noise averaged over
// a stop's window (1.5 s at 50 Hz: 0.04" a stop, 0.02" a mean of 5 runs), the readout's 0.001"
// digits, and the servo's settling tail in the window (Kv 30; the trigger takes a window once
// its spread is within 1 millidegree = 3.6"): the stop reads up to 0.2" short of where the axis
// comes to rest, on either side, so a reversal up to 0.4" larger. Each target's mean up and
// down within 0.3" of the truth, each reversal and B within 0.45" of the injected backlash.
// Measured: the worst mean 0.20" off, B 6.32" (daq sim --test rotary, the same truth).
TEST(RotaryAcquisition, StopsFromTheAngularReferenceRecoverTheInjectedErrors) {
  const auto db = cal::test::temp_path("caldaq-rotary", "acquire");
  daq::SimulatedAcquisition a{.truth = {}, .database = db, .laser_poll_s = 0.02};
  a.truth.rotary = {.scale_arcsec_per_turn = 10.0,
                    .cyclic_arcsec = 4.0,
                    .cyclic_period_deg = 120.0,
                    .backlash_arcsec = 6.0,
                    .noise_arcsec = 0.3,
                    .zero_arcsec = -3.0};
  const auto test = daq::simulated_rotary_test(5);
  const auto out = daq::acquire_simulated(a, test);
  ASSERT_TRUE(out.complete) << out.reason;
  EXPECT_TRUE(out.missed.empty());
  EXPECT_EQ(out.component, "E_CC");
  ASSERT_TRUE(out.profile);
  const auto& j = *out.profile;
  EXPECT_EQ(j["schema"], "caldaq.rotary.v1");
  EXPECT_EQ(j["unit"], "arcsec");
  const auto& r = a.truth.rotary;
  const auto& targets = j["targets"];
  ASSERT_EQ(targets.size(), 9u);
  double worst = 0;
  for (const auto& t : targets) {
    const double q = t["position_deg"];
    const double up = truth_arcsec(r, q, true), down = truth_arcsec(r, q, false);
    worst = std::max({worst, std::abs(t["mean_up"].get<double>() - up),
                      std::abs(t["mean_down"].get<double>() - down)});
    EXPECT_NEAR(t["mean_up"].get<double>(), up, 0.3) << q << " deg";
    EXPECT_NEAR(t["mean_down"].get<double>(), down, 0.3) << q << " deg";
    EXPECT_NEAR(std::abs(t["reversal"].get<double>()), r.backlash_arcsec, 0.45) << q << " deg";
  }
  const double b = j["axis"]["B"]["value"];
  EXPECT_NEAR(std::abs(b), r.backlash_arcsec, 0.45);
  // The 360 deg target read as 0 deg by the reference: its deviation is the turn's 10" from
  // the zero's -3", not -1296000".
  EXPECT_NEAR(targets.back()["mean"].get<double>(), r.zero_arcsec + r.scale_arcsec_per_turn, 0.25);
  // Stored: 9 targets x 5 runs x 2 directions, each stop's deviation in arcsec (the 45 deg
  // target's is a few arcsec, not its angle of 162000"), its raw value the
  // reference's angle in rad; the run is a rotary one, measured by the angular reference.
  cal::storage::Store store(db, {.read_only = true});
  const auto stops = store.targets(out.run_id);
  ASSERT_EQ(stops.size(), 90u);
  for (const auto& s : stops) {
    const double truth = truth_arcsec(r, s.nominal_mm, s.direction == '+');
    EXPECT_NEAR(s.deviation_um, truth, 0.5)  // the deviation, not the angle
        << s.nominal_mm << " deg run " << s.run_number << s.direction;
    EXPECT_NEAR(s.raw_m * 180.0 / std::numbers::pi, s.nominal_mm, 0.01);
  }
  const auto run = store.run(out.run_id);
  ASSERT_TRUE(run);
  EXPECT_EQ(run->kind, "rotary");
  EXPECT_EQ(run->axis, "C");
  std::printf(
      "rotary acquisition: worst |mean - injected| %.3f\", B %.3f\" (injected %.1f\"), "
      "360 deg %.3f\" (injected %.3f\"), %zu readings\n",
      worst, b, r.backlash_arcsec, targets.back()["mean"].get<double>(),
      truth_arcsec(r, 360.0, true) / 2 + truth_arcsec(r, 360.0, false) / 2, out.readings);
  cal::test::remove_db(db);
}

// A rotary test is refused without its angular reference, naming the role.
TEST(RotaryAcquisition, RefusedWithoutAnAngularReference) {
  boost::asio::io_context io;
  daq::LinearRunSetup setup;
  setup.config.linear = daq::simulated_rotary_test(2);
  setup.database = cal::test::temp_path("caldaq-rotary", "refused");
  try {
    daq::LinearRun run(io, std::move(setup));
    FAIL() << "a rotary run without its reference was accepted";
  } catch (const cal::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("role = \"angle\""), std::string::npos) << e.what();
  }
}

}  // namespace
