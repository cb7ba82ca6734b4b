// The environmental compensation stage: interpolation in time, the compensation against a
// reference refractive index and a hand calculation, and the stale-sensor policies.
#include "cal/daq/env_stage.hpp"

#include <gtest/gtest.h>

namespace {

using cal::daq::AirQuantity;
using cal::daq::EnvStage;
constexpr std::int64_t s = 1'000'000'000;

cal::daq::EnvironmentConfig edlen(cal::daq::StalePolicy policy = cal::daq::StalePolicy::stop) {
  cal::daq::EnvironmentConfig c;
  c.equation = "edlen";
  c.stale_after_s = 10;
  c.on_stale = policy;
  c.expansion_ppm_per_k = 11.5;
  return c;
}

void standard_air(EnvStage& e, std::int64_t t) {
  e.add_air(t, AirQuantity::temperature_degc, 20.0);
  e.add_air(t, AirQuantity::pressure_pa, 101325.0);
  e.add_air(t, AirQuantity::humidity_pct, 50.0);
}

TEST(EnvStage, CompensatesWithTheReferenceIndexAndMaterialNormalisation) {
  // Edlen at 20 degC, 101325 Pa, 50 %RH, 633 nm: n = 1.000271374 (reference value of
  // tests/analysis/air_test.cpp). Material at 21 degC, 11.5 ppm/K. By hand:
  // L = 0.1 / 1.000271374 / (1 + 11.5e-6 x 1) = 0.0999717202876 m; factor -282.797 ppm.
  EnvStage e(edlen(), 1);
  standard_air(e, 0);
  e.add_material(0, 0, 21.0);
  const auto c = e.compensate(0, 0.1);
  EXPECT_NEAR(c.n, 1.000271374, 6e-10);
  // The reference n has 9 decimals (+-6e-10 as checked above): L within 0.1 m x 6e-10.
  EXPECT_NEAR(c.length_m, 0.0999717202876, 6e-11);
  EXPECT_NEAR(c.factor_ppm, -282.797, 1e-3);
  EXPECT_FALSE(c.fallback_air);
  EXPECT_FALSE(c.fallback_material);
  EXPECT_FALSE(c.held);
}

TEST(EnvStage, InterpolatesLinearlyInTimeAndFlagsAHeldValue) {
  EnvStage e(edlen(), 2);
  standard_air(e, 0);
  e.add_air(10 * s, AirQuantity::temperature_degc, 21.0);
  e.add_air(10 * s, AirQuantity::pressure_pa, 101325.0);
  e.add_air(10 * s, AirQuantity::humidity_pct, 50.0);
  e.add_material(0, 0, 20.0);
  e.add_material(10 * s, 0, 22.0);
  e.add_material(5 * s, 1, 19.0);  // the second sensor: one sample, mean with the first
  const auto mid = e.compensate(5 * s, 0.1);
  EXPECT_DOUBLE_EQ(mid.air_temperature_degc, 20.5);  // halfway between 20 and 21
  EXPECT_DOUBLE_EQ(mid.material_degc, (21.0 + 19.0) / 2);
  // Sensor 2's only sample is at 5 s: at 2.5 s that oldest value is used, not "held"; at
  // 7.5 s the reading is newer than sensor 2's newest sample: held.
  EXPECT_FALSE(e.compensate(2 * s + s / 2, 0.1).held);
  EXPECT_TRUE(e.compensate(7 * s + s / 2, 0.1).held);
  const auto late = e.compensate(12 * s, 0.1);
  EXPECT_TRUE(late.held);
  EXPECT_DOUBLE_EQ(late.air_temperature_degc, 21.0);
}

TEST(EnvStage, StaleSensorStopsTheRunUnderTheStopPolicy) {
  EnvStage e(edlen(cal::daq::StalePolicy::stop), 1);
  standard_air(e, 0);
  e.add_material(0, 0, 20.0);
  EXPECT_FALSE(e.check(5 * s).must_stop);
  e.add_air(9 * s, AirQuantity::temperature_degc, 20.1);
  e.add_air(9 * s, AirQuantity::humidity_pct, 50.0);
  e.add_material(9 * s, 0, 20.0);
  const auto h = e.check(11 * s);  // pressure's last sample is 11 s old
  EXPECT_TRUE(h.must_stop);
  ASSERT_EQ(h.messages.size(), 1u);
  EXPECT_EQ(h.messages[0], "air pressure is stale (last sample 11.0 s ago): stopping");
}

TEST(EnvStage, FallbackIsUsedRecordedAndAnnouncedOnce) {
  auto cfg = edlen(cal::daq::StalePolicy::fallback);
  cfg.fallback_material_degc = 20.0;
  EnvStage e(cfg, 1);
  standard_air(e, 0);
  // The thermometer never sent anything.
  const auto h = e.check(1 * s);
  EXPECT_FALSE(h.must_stop);
  ASSERT_EQ(h.messages.size(), 1u);
  EXPECT_EQ(h.messages[0], "material sensor 1 is stale (no sample yet): using the fallback 20");
  EXPECT_TRUE(e.check(2 * s).messages.empty());  // once per episode
  const auto c = e.compensate(1 * s, 0.1);
  EXPECT_TRUE(c.fallback_material);
  EXPECT_DOUBLE_EQ(c.material_degc, 20.0);
  e.add_material(3 * s, 0, 20.2);
  EXPECT_EQ(e.check(3 * s).messages, std::vector<std::string>{"material sensor 1 is back"});
  EXPECT_FALSE(e.compensate(3 * s, 0.1).fallback_material);
}

}  // namespace
