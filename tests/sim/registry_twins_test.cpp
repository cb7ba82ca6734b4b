// Every registered device, built through the registry alone (as a run builds it), against the
// twin the registry gives for the same options: the instrument opens, streams, and its
// readings are of the quantities the driver declares. A new device gets this test for free.
#include <gtest/gtest.h>

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <cmath>
#include <set>

#include "cal/drivers/registry.hpp"
#include "cal/drivers/sim/twin.hpp"

namespace {

namespace d = cal::drivers;
namespace sim = cal::drivers::sim;
using namespace std::chrono_literals;

sim::World parked_world() {
  sim::MachineConfig c;
  c.start_mm = {100, 20, 10};
  return sim::World(c, sim::AirConfig{});
}

struct TwinRun {
  std::vector<d::Reading> readings;
  std::uint64_t codec_errors = 0;
};

// The device's instrument, built through the registry, against the registry's twin for the same
// options, until it has read `enough` readings (or 5 s passed).
TwinRun run_against_twin(const d::DeviceDriver& drv, const d::Options& options,
                         const d::InstrumentContext& context, std::size_t enough) {
  boost::asio::io_context io;
  sim::World world = parked_world();
  double now_s = 1.0;
  auto twin = drv.make_twin(
      io, world, [&] { return now_s; }, options);
  if (!twin) {
    ADD_FAILURE() << drv.name() << " has no twin";
    return {};
  }
  auto transport = twin->connect(io);
  if (!transport) transport = d::transport::make_transport(io, twin->transport(), -1);
  auto instrument =
      drv.make_instrument(io, std::move(transport),
                          {.device = 7, .name = "twin", .poll_period = 5ms}, options, context);
  TwinRun run;
  instrument->start({.reading = [&](const d::Reading& r) { run.readings.push_back(r); }});
  // The twin's clock moves on (an IDS3010 reports "measurement starting" for 0.2 s).
  const auto deadline = std::chrono::steady_clock::now() + 5s;
  while (run.readings.size() < enough && std::chrono::steady_clock::now() < deadline) {
    io.run_for(5ms);
    io.restart();
    now_s += 0.01;
  }
  instrument->stop();
  run.codec_errors = instrument->codec_stats().errors();
  return run;
}

TEST(RegistryTwins, EveryDevicesInstrumentReadsItsTwin) {
  for (const auto* drv : d::device_drivers()) {
    SCOPED_TRACE(std::string(drv->name()));
    const d::Options options(drv->options());
    const d::InstrumentContext context{.role = "", .test_axis = 0};
    // A device that sends only on change (an MTConnect adapter) says each value once while the
    // machine is parked.
    const std::size_t enough = drv->sends_on_change() ? 1 : 3;
    const TwinRun run = run_against_twin(*drv, options, context, enough);
    ASSERT_GE(run.readings.size(), enough);
    EXPECT_EQ(run.codec_errors, 0u);
    const auto declared = drv->quantities(options, context);
    for (const auto& r : run.readings) {
      EXPECT_EQ(r.device, 7);
      EXPECT_NE(std::find(declared.begin(), declared.end(), r.quantity), declared.end())
          << "undeclared quantity " << d::to_string(r.quantity);
    }
  }
}

TEST(RegistryTwins, EveryGaugePresetReadsItsFamilysLinesFromTheTwin) {
  // The twin prints each family's documented line (Mitutoyo's "01A+" and CR only, Sylvac's CR
  // only, Mahr's unit word) and answers the family's request; the instrument configured by the
  // preset alone reads the bar's length: tool (100, 20, 10), table ball at 0, zero at 100 mm.
  const auto& gauge = d::driver("gauge");
  const double expected_m = (std::sqrt(100.0 * 100 + 20 * 20 + 10 * 10) - 100.0) * 1e-3;
  for (const auto& preset : {"mitutoyo_digimatic", "sylvac", "mahr_millimar"}) {
    SCOPED_TRACE(preset);
    const std::vector<std::pair<std::string, std::string>> set{{"preset", preset}};
    const auto options = d::options_from_text(gauge, set);
    const TwinRun run = run_against_twin(gauge, options, {.role = "", .test_axis = 0}, 3);
    ASSERT_GE(run.readings.size(), 3u);
    EXPECT_EQ(run.codec_errors, 0u);
    for (const auto& r : run.readings) EXPECT_NEAR(r.value, expected_m, 1e-8);
  }
}

}  // namespace
