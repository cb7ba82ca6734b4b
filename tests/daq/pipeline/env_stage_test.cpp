// The environmental compensation stage: interpolation in time, the compensation against a
// reference refractive index and a hand calculation, and the stale-sensor policies.
#include "cal/daq/env_stage.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "cal/analysis/error.hpp"

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

TEST(EnvStage, TheLengthAloneHasTheBitsOfTheWholeCompensation) {
  // compensated_length_m() serves 10 kHz streams from the held environment without building
  // the record; it must give compensate()'s length bit for bit, held or interpolated, on a
  // changing environment, and the same hand value as the whole record for standard air.
  EnvStage e(edlen(), 1);
  standard_air(e, 0);
  e.add_material(0, 0, 21.0);
  EXPECT_NEAR(e.compensated_length_m(0, 0.1), 0.0999717202876, 6e-11);  // the hand value above
  for (int k = 1; k <= 5; ++k) {  // air and material change every second
    e.add_air(k * s, AirQuantity::temperature_degc, 20.0 + 0.1 * k);
    e.add_air(k * s, AirQuantity::pressure_pa, 101325.0 - 30.0 * k);
    e.add_air(k * s, AirQuantity::humidity_pct, 50.0 + k);
    e.add_material(k * s, 0, 21.0 + 0.05 * k);
  }
  int held = 0;
  for (std::int64_t t = 0; t <= 8 * s; t += s / 7) {  // between samples, on them, after them
    for (int i = -100; i <= 100; ++i) {  // raw lengths from -1 m to 1 m, none a round number
      const double raw = 0.01 * i + 1.234567e-7 * i * i;
      const double whole = e.compensate(t, raw).length_m;
      const double alone = e.compensated_length_m(t, raw);
      ASSERT_EQ(std::memcmp(&whole, &alone, sizeof whole), 0) << t << " " << raw;
    }
    held += e.compensate(t, 0.1).held;
  }
  EXPECT_GT(held, 10);  // the held path (after 5 s) was taken as well as the interpolated one
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

TEST(EnvStage, Co2SensorIsInterpolatedIntoCiddor) {
  // Ciddor standard air (dry, 15 degC, 101325 Pa, 450 umol/mol) at 632.991 nm: n - 1 =
  // 2.76530324127e-4 (the dispersion formula, tests/analysis/air_test.cpp). For dry air at 15
  // degC and 101325 Pa the density ratio of Ciddor's equation is 1, so another CO2 content only
  // scales it by (1 + 0.534e-6 (xc - 450)) (Ciddor 1996, eq. 2). CO2 300 at 0 s and 900 at 10 s
  // interpolate to 600 at 5 s: n - 1 = 2.76530324127e-4 x 1.0000801 = 2.76552474206e-4.
  cal::daq::EnvironmentConfig cfg;
  cfg.equation = "ciddor";
  cfg.stale_after_s = 20;
  EnvStage e(cfg, cal::daq::EnvSensors{{true}, true});
  for (std::int64_t t : {0 * s, 10 * s}) {
    e.add_air(t, AirQuantity::temperature_degc, 15.0);
    e.add_air(t, AirQuantity::pressure_pa, 101325.0);
    e.add_air(t, AirQuantity::humidity_pct, 0.0);
    e.add_material(t, 0, 20.0);
  }
  e.add_air(0, AirQuantity::co2_umol_per_mol, 300.0);
  e.add_air(10 * s, AirQuantity::co2_umol_per_mol, 900.0);
  const auto c = e.compensate(5 * s, 0.2);
  EXPECT_DOUBLE_EQ(c.co2_umol_per_mol, 600.0);
  EXPECT_NEAR(c.n - 1, 2.76552474206e-4, 1e-11);
  EXPECT_NEAR(c.length_m, 0.2 / (1 + 2.76552474206e-4), 0.2 * 1e-11);  // material at 20 degC
  EXPECT_FALSE(c.fallback_air);
  // The CO2 sensor is checked like the others: silent from 10 s, stale at 31 s.
  e.add_air(30 * s, AirQuantity::temperature_degc, 15.0);
  e.add_air(30 * s, AirQuantity::pressure_pa, 101325.0);
  e.add_air(30 * s, AirQuantity::humidity_pct, 0.0);
  e.add_material(30 * s, 0, 20.0);
  const auto h = e.check(31 * s);
  ASSERT_EQ(h.messages.size(), 1u);
  EXPECT_EQ(h.messages[0], "air CO2 is stale (last sample 21.0 s ago): stopping");
}

TEST(EnvStage, WithoutACo2SensorTheConfiguredValueIsNoFallback) {
  // Same dry standard air, no CO2 sensor: the configured 450 umol/mol gives the dispersion
  // formula's value itself, and nothing is stale or flagged.
  cal::daq::EnvironmentConfig cfg;
  cfg.equation = "ciddor";
  EnvStage e(cfg, 1);
  e.add_air(0, AirQuantity::temperature_degc, 15.0);
  e.add_air(0, AirQuantity::pressure_pa, 101325.0);
  e.add_air(0, AirQuantity::humidity_pct, 0.0);
  e.add_material(0, 0, 20.0);
  EXPECT_TRUE(e.check(1 * s).messages.empty());
  const auto c = e.compensate(0, 0.2);
  EXPECT_NEAR(c.n - 1, 2.76530324127e-4, 1e-11);
  EXPECT_DOUBLE_EQ(c.co2_umol_per_mol, 450.0);
  EXPECT_FALSE(c.fallback_air);
}

TEST(EnvStage, DisabledMaterialSensorIsNeitherAveragedNorChecked) {
  // Three probes; the second is broken (reads 35 degC) and disabled: the material temperature
  // is the mean of 20.4 and 20.6 = 20.5 degC. With the Edlen reference n = 1.000271374 (20 degC,
  // 101325 Pa, 50 %RH) and 11.5 ppm/K: L = 0.1 / 1.000271374 / (1 + 11.5e-6 x 0.5)
  // = 0.0999722951217 m (to +-6e-11 m from the 9-decimal reference n).
  EnvStage e(edlen(), cal::daq::EnvSensors{{true, false, true}, false});
  standard_air(e, 0);
  e.add_material(0, 0, 20.4);
  e.add_material(0, 1, 35.0);
  e.add_material(0, 2, 20.6);
  const auto c = e.compensate(0, 0.1);
  EXPECT_DOUBLE_EQ(c.material_degc, 20.5);
  EXPECT_NEAR(c.length_m, 0.0999722951217, 6e-11);
  // At 5 s nothing is stale; the disabled probe is not reported even after it goes silent.
  standard_air(e, 9 * s);
  e.add_material(9 * s, 0, 20.4);
  e.add_material(9 * s, 2, 20.6);
  EXPECT_TRUE(e.check(12 * s).messages.empty());
  // Enabled again (silent since 0 s): stale, reported once; disabling it again is fine, but the
  // last enabled sensor cannot be disabled.
  e.set_material_enabled(1, true);
  EXPECT_EQ(
      e.check(12 * s).messages,
      std::vector<std::string>{"material sensor 2 is stale (last sample 12.0 s ago): stopping"});
  e.set_material_enabled(1, false);
  e.set_material_enabled(0, false);
  EXPECT_THROW(e.set_material_enabled(2, false), cal::InputError);
  EXPECT_THROW(e.set_material_enabled(3, true), cal::InputError);
}

TEST(EnvStage, StaleAirUsesItsFallbackValue) {
  // The pressure's last sample (90 kPa) is 20 s old: under the fallback policy the configured
  // 101325 Pa is used, which with 20 degC and 50 %RH gives the Edlen reference 1.000271374.
  auto cfg = edlen(cal::daq::StalePolicy::fallback);
  EnvStage e(cfg, 1);
  e.add_air(0, AirQuantity::pressure_pa, 90000.0);
  e.add_air(20 * s, AirQuantity::temperature_degc, 20.0);
  e.add_air(20 * s, AirQuantity::humidity_pct, 50.0);
  e.add_material(20 * s, 0, 20.0);
  const auto h = e.check(20 * s);
  EXPECT_FALSE(h.must_stop);
  EXPECT_EQ(h.messages, std::vector<std::string>{
                            "air pressure is stale (last sample 20.0 s ago): using the fallback "
                            "101325"});
  const auto c = e.compensate(20 * s, 0.1);
  EXPECT_TRUE(c.fallback_air);
  EXPECT_FALSE(c.fallback_material);
  EXPECT_DOUBLE_EQ(c.pressure_pa, 101325.0);
  EXPECT_NEAR(c.n, 1.000271374, 6e-10);
}

TEST(EnvStage, RefusesBadConfiguration) {
  auto cfg = edlen();
  cfg.stale_after_s = 0;
  EXPECT_THROW(EnvStage(cfg, 1), cal::InputError);
  cfg = edlen();
  cfg.expansion_ppm_per_k = std::nan("");
  EXPECT_THROW(EnvStage(cfg, 1), cal::InputError);
  cfg = edlen();
  cfg.equation = "guess";
  EXPECT_THROW(EnvStage(cfg, 1), cal::InputError);
  EXPECT_THROW(EnvStage(edlen(), -1), cal::InputError);
  EXPECT_THROW(EnvStage(edlen(), cal::daq::EnvSensors{{false, false}, false}), cal::InputError);
  EnvStage e(edlen(), 2);
  EXPECT_THROW(e.add_material(0, 2, 20.0), cal::InputError);  // sensors are 0 and 1
  // An impossible environment (a pressure of 0 from a faulty sensor) is not compensated.
  e.add_air(0, AirQuantity::temperature_degc, 20.0);
  e.add_air(0, AirQuantity::pressure_pa, 0.0);
  e.add_air(0, AirQuantity::humidity_pct, 50.0);
  EXPECT_THROW(e.compensate(0, 0.1), cal::InputError);
}

}  // namespace

namespace cached {

struct Sample {
  std::int64_t t;
  int what;  // 0..2 air quantities, 3 material
  double v;
};

void feed(EnvStage& e, const Sample& x) {
  if (x.what == 3)
    e.add_material(x.t, 0, x.v);
  else
    e.add_air(x.t, static_cast<AirQuantity>(x.what), x.v);
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace cached

// The environment is computed once per held sample and the refractive index again only when
// the air changes (env_stage.hpp). The proof that this changes nothing: every compensation of a
// long stage (its cache warm, hit and missed in every way: held samples, interpolation between
// samples, samples arriving between readings, a stale sensor on its fallback and back) equals bit
// for bit the compensation of a fresh stage given the same samples, whose cache is empty, and its n
// is the equation's own for the air it reports.
TEST(EnvStage, CachedIndexGivesTheEquationsResultBitForBit) {
  auto cfg = edlen(cal::daq::StalePolicy::fallback);
  cfg.equation = "ciddor";
  std::vector<cached::Sample> samples;
  for (int k = 0; k < 12; ++k) {  // a 1 Hz station, with a 15 s silence of the air after 6 s
    const std::int64_t t = k < 6 ? k * s : (k + 15) * s;
    samples.push_back({t, 0, 20.0 + 0.013 * k});
    samples.push_back({t, 1, 101325.0 - 1.7 * k});
    samples.push_back({t, 2, 45.0 + 0.21 * k});
    samples.push_back({t, 3, 20.5 + 0.007 * k});
  }
  EnvStage warm(cfg, 1);
  std::size_t next = 0, compared = 0, held = 0, fallback = 0;
  for (std::int64_t t = 0; t < 28 * s; t += s / 37) {  // readings between and on the samples
    // Samples up to 1.5 s ahead of the reading (a laser with more latency than the station):
    // readings between two samples are interpolated, readings past the newest are held.
    for (; next < samples.size() && samples[next].t <= t + 3 * s / 2; ++next)
      cached::feed(warm, samples[next]);
    EnvStage fresh(cfg, 1);
    for (std::size_t i = 0; i < next; ++i) cached::feed(fresh, samples[i]);
    // Twice from the warm stage: a miss, then a hit on the same air.
    for (int twice = 0; twice < 2; ++twice) {
      const auto a = warm.compensate(t, 0.25), b = fresh.compensate(t, 0.25);
      ASSERT_TRUE(cached::same_bits(a.n, b.n)) << t;
      ASSERT_TRUE(cached::same_bits(a.length_m, b.length_m)) << t;
      ASSERT_TRUE(cached::same_bits(a.factor_ppm, b.factor_ppm)) << t;
      ASSERT_TRUE(cached::same_bits(a.air_temperature_degc, b.air_temperature_degc)) << t;
      ASSERT_TRUE(cached::same_bits(a.pressure_pa, b.pressure_pa)) << t;
      ASSERT_TRUE(cached::same_bits(a.humidity_pct, b.humidity_pct)) << t;
      ASSERT_TRUE(cached::same_bits(a.material_degc, b.material_degc)) << t;
      ASSERT_EQ(a.time_ns, t);
      ASSERT_EQ(a.held, b.held);
      ASSERT_EQ(a.fallback_air, b.fallback_air);
      ASSERT_EQ(a.fallback_material, b.fallback_material);
      cal::air::Conditions air;
      air.temperature_degc = a.air_temperature_degc;
      air.pressure_pa = a.pressure_pa;
      air.humidity = cal::air::Humidity::relative_pct(a.humidity_pct);
      air.co2_umol_per_mol = a.co2_umol_per_mol;
      air.wavelength_vacuum_nm = cfg.wavelength_nm;
      ASSERT_TRUE(
          cached::same_bits(a.n, cal::air::refractive_index(air, cal::air::Equation::ciddor).n));
      ++compared;
      held += a.held;
      fallback += a.fallback_air;
    }
  }
  // The sequence did go through every case.
  EXPECT_GT(compared, 2000u);
  EXPECT_GT(held, 100u);
  EXPECT_GT(fallback, 100u);
  EXPECT_GT(compared - held - fallback, 100u);  // interpolated
}

// After the run (daq recompensate) all samples are given first and the stops compensated
// afterwards: with keep_all_samples a stop early in an hour-long run gets the air of its own
// time. The live stage keeps 2 minutes, so there the same query would get the air of the end.
TEST(EnvStage, KeepingAllSamplesCompensatesAnEarlyStopOfALongRunWithItsOwnAir) {
  cal::daq::EnvSensors sensors{.material_enabled = {true}};
  EnvStage live(edlen(), sensors);
  sensors.keep_all_samples = true;
  EnvStage after(edlen(), sensors);
  for (std::int64_t k = 0; k <= 3600; ++k)  // 1 Hz for an hour, 20 -> 21 degC
    for (EnvStage* e : {&live, &after}) {
      e->add_air(k * s, AirQuantity::temperature_degc, 20.0 + static_cast<double>(k) / 3600.0);
      e->add_air(k * s, AirQuantity::pressure_pa, 101325.0);
      e->add_air(k * s, AirQuantity::humidity_pct, 50.0);
      e->add_material(k * s, 0, 20.0);
    }
  // At 5 min: 20 + 300/3600 degC exactly (a sample's time), and halfway to the next at 5.5 s.
  EXPECT_DOUBLE_EQ(after.compensate(300 * s, 0.1).air_temperature_degc, 20.0 + 300.0 / 3600.0);
  EXPECT_NEAR(after.compensate(300 * s + s / 2, 0.1).air_temperature_degc, 20.0 + 300.5 / 3600.0,
              1e-12);
  EXPECT_GT(live.compensate(300 * s, 0.1).air_temperature_degc, 20.9);  // the end's air
}
