// How many JSON-RPC requests per second the IDS3010 driver reaches: the real instrument
// (ids3010/instrument.cpp, one request in flight, polled as fast as it can: poll period 0)
// against the SIMULATED twin on a loopback TCP port, both on one event loop in this process.
// Each displacement request gives one reading (one axis read), so readings/s = requests/s.
// What it measures is the software path (JSON encode and parse, the loop, loopback TCP); a
// real IDS3010 adds its network and firmware latency. Numbers: docs/drivers.md (IDS3010 rate).
#include <benchmark/benchmark.h>

#include <boost/asio/io_context.hpp>

#include "cal/drivers/sim/world.hpp"
#include "cal/drivers/transport/transport.hpp"
#include "ids3010/instrument.hpp"
#include "ids3010/twin.hpp"

namespace {

namespace d = cal::drivers;
namespace sim = cal::drivers::sim;
using namespace std::chrono_literals;

void BM_Ids3010JsonRpcRequests(benchmark::State& state) {
  boost::asio::io_context io;
  sim::MachineConfig machine;
  machine.start_mm = {100, 0, 0};
  sim::World world(machine, sim::AirConfig{});
  sim::IdsTwin twin(io, world, sim::steady_clock(), {.api = d::codec::IdsApi::sen});
  auto ids = d::make_ids3010(
      io, d::transport::make_tcp(io, {.host = "127.0.0.1", .port = twin.port()}),
      {.name = "laser", .poll_period = 0us}, {.read_environment = state.range(0) != 0});
  std::int64_t readings = 0;
  ids->start({.reading = [&](const d::Reading& r) {
    readings += r.quantity == d::Quantity::displacement_m;
  }});
  // Until the measurement runs (the twin's 0.2 s "measurement starting").
  const auto limit = std::chrono::steady_clock::now() + 5s;
  while (readings == 0 && std::chrono::steady_clock::now() < limit) io.run_for(10ms);
  if (readings == 0) state.SkipWithError("the twin never measured");
  const std::int64_t before = readings;
  const auto served_before = twin.requests_served();
  for (auto _ : state) {
    const std::int64_t target = readings + 1000;
    while (readings < target) io.run_one();
  }
  state.SetItemsProcessed(readings - before);
  state.counters["requests_per_s"] = benchmark::Counter(
      static_cast<double>(twin.requests_served() - served_before), benchmark::Counter::kIsRate);
  state.counters["displacements_per_s"] =
      benchmark::Counter(static_cast<double>(readings - before), benchmark::Counter::kIsRate);
  ids->stop();
}
// Arg 0: displacement only; 1: with the ECU read every second (a request of its own).
BENCHMARK(BM_Ids3010JsonRpcRequests)->Arg(0)->Arg(1)->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
