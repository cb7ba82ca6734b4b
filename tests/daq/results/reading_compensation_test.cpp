// A stored run's laser readings compensated one by one (daq/src/results/reading_compensation):
// a sample its device flagged is no environment value.
#include "reading_compensation.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cal/drivers/instrument.hpp"
#include "cal/storage/store.hpp"

namespace {
namespace fs = std::filesystem;
namespace st = cal::storage;
using Q = cal::drivers::Quantity;
using S = cal::drivers::ReadingStatus;

st::RawReading reading(std::int64_t t_s, int device, Q q, double value, S status = S::ok) {
  return {.time_ns = t_s * 1'000'000'000,
          .device = static_cast<std::uint16_t>(device),
          .quantity = static_cast<std::uint8_t>(q),
          .status = static_cast<std::uint8_t>(status),
          .value = value};
}

TEST(ReadingCompensation, AnAirSampleItsDeviceFlaggedIsNoValue) {
  const fs::path db = fs::temp_directory_path() /
                      ("caldaq-reading-compensation-" + std::to_string(::getpid()) + ".sqlite");
  fs::remove(db);
  st::Store store(db);
  const auto run = store.begin_run({.kind = "linear",
                                    .axis = "X",
                                    .settings_json = R"({"environment": {"stale_after_s": 60}})"});
  store.add_instrument({.run_id = run, .device = 0, .driver = "laser", .transport = "test"});
  store.add_instrument({.run_id = run, .device = 1, .driver = "air", .transport = "test"});
  // Air at 20 degC, 101325 Pa, 50 %RH; the laser at 1 s; then the air station flags a
  // temperature of 80 degC out of range (a clipped or error value) at 2 s; the laser at 3 s.
  const std::vector<st::RawReading> in{
      reading(0, 1, Q::air_temperature_degc, 20.0),
      reading(0, 1, Q::air_pressure_pa, 101325.0),
      reading(0, 1, Q::air_humidity_pct, 50.0),
      reading(1, 0, Q::displacement_m, 0.1),
      reading(2, 1, Q::air_temperature_degc, 80.0, S::out_of_range),
      reading(3, 0, Q::displacement_m, 0.1)};
  store.append_readings(run, in);
  store.finish_run(run, st::RunStatus::complete);
  const auto record = *store.run(run);
  daq::ReadingCompensation comp(store, record, nlohmann::json::parse(record.settings_json));
  std::vector<cal::daq::Compensated> out;
  for (const auto& r : in)
    if (auto c = comp.add(r)) out.push_back(*c);
  ASSERT_EQ(out.size(), 2u);
  // The same air for both (20 degC held): the flagged 80 degC, had it been used, would change n
  // by about 55 ppm (1 ppm per K below 1 K).
  EXPECT_EQ(out[1].air_temperature_degc, 20.0);
  EXPECT_EQ(out[1].n, out[0].n);
  EXPECT_EQ(out[1].length_m, out[0].length_m);
  fs::remove(db);
}

}  // namespace
