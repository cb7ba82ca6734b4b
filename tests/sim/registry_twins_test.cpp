// Every registered device, built through the registry alone (as a run builds it), against the
// twin the registry gives for the same options: the instrument opens, streams, and its
// readings are of the quantities the driver declares. A new device gets this test for free.
#include <gtest/gtest.h>

#include <algorithm>
#include <boost/asio/io_context.hpp>
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

TEST(RegistryTwins, EveryDevicesInstrumentReadsItsTwin) {
  for (const auto* drv : d::device_drivers()) {
    SCOPED_TRACE(std::string(drv->name()));
    boost::asio::io_context io;
    sim::World world = parked_world();
    double now_s = 1.0;
    const d::Options options(drv->options());
    const d::InstrumentContext context{.role = "", .test_axis = 0};
    auto twin = drv->make_twin(
        io, world, [&] { return now_s; }, options);
    ASSERT_NE(twin, nullptr);
    auto transport = twin->connect(io);
    if (!transport) transport = d::transport::make_transport(io, twin->transport(), -1);
    auto instrument =
        drv->make_instrument(io, std::move(transport),
                             {.device = 7, .name = "twin", .poll_period = 5ms}, options, context);
    std::vector<d::Reading> readings;
    instrument->start({.reading = [&](const d::Reading& r) { readings.push_back(r); }});
    // The twin's clock moves on (an IDS3010 reports "measurement starting" for 0.2 s).
    const auto deadline = std::chrono::steady_clock::now() + 5s;
    // A device that sends only on change (an MTConnect adapter) says each value once while the
    // machine is parked.
    const std::size_t enough = drv->sends_on_change() ? 1 : 3;
    while (readings.size() < enough && std::chrono::steady_clock::now() < deadline) {
      io.run_for(5ms);
      io.restart();
      now_s += 0.01;
    }
    instrument->stop();
    ASSERT_GE(readings.size(), enough);
    EXPECT_EQ(instrument->codec_stats().errors(), 0u);
    const auto declared = drv->quantities(options, context);
    for (const auto& r : readings) {
      EXPECT_EQ(r.device, 7);
      EXPECT_NE(std::find(declared.begin(), declared.end(), r.quantity), declared.end())
          << "undeclared quantity " << d::to_string(r.quantity);
    }
  }
}

}  // namespace
