// Records the checked-in capture tests/data/captures/twin_session.cdq: the real laser,
// PTU300, ballbar and position-feed instruments against the SIMULATED twins (session and
// truth in twin_session.hpp), for 4.5 s of simulated time (it jumps from event to event, see
// cal/drivers/loop_time.hpp: the recording takes as long as the CPU needs, and the same on a
// loaded machine), with the disturbances injected at fixed simulated times.
// Usage: record_captures OUTPUT.cdq
// Re-record only when the capture format or a protocol changes; the test checks every
// reading against the simulated truth, not against an earlier recording.
#include <boost/asio/io_context.hpp>
#include <chrono>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "cal/drivers/loop_time.hpp"
#include "cal/replay/session.hpp"
#include "twin_session.hpp"

namespace {

namespace sim = cal::drivers::sim;
namespace t = cal::drivers::transport;
namespace ts = twin_session;

std::string header(std::uint16_t ids_port, std::uint16_t shdr_port) {
  using nlohmann::json;
  const auto dev = [](int id, const char* name, const char* driver, std::string transport) {
    return json{{"device", id}, {"name", name}, {"driver", driver}, {"transport", transport}};
  };
  return json{
      {"software", "caldaq record_captures (tests/replay)"},
      {"simulated", true},
      {"session", "twin_session: see tests/replay/twin_session.hpp"},
      {"devices",
       json::array(
           {dev(ts::laser, "laser", "ids3010", "tcp 127.0.0.1:" + std::to_string(ids_port)),
            dev(ts::ptu300, "PTU300", "ptu300", "serial 4800 7E1"),
            dev(ts::ballbar, "ballbar", "gauge", "serial 115200 8N1"),
            dev(ts::position, "position", "shdr", "tcp 127.0.0.1:" + std::to_string(shdr_port))})}}
      .dump();
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: record_captures OUTPUT.cdq\n");
    return 2;
  }
  boost::asio::io_context io;
  auto& time = cal::drivers::VirtualTime::install(io);
  sim::World world(ts::machine(), ts::air());
  const auto program = ts::program();
  world.machine().load(program);
  const sim::Clock sim_clock = [&time] { return time.now_s(); };
  sim::IdsTwin ids(io, world, sim_clock);
  sim::Ptu300Twin ptu(io, world, sim_clock);
  sim::GaugeTwin bar(io, world, sim_clock,
                     {.pivot_mm = {ts::pivot_x_mm, 0, 0},
                      .zero_length_mm = ts::bar_zero_mm,
                      .sample_rate_hz = 100.0});
  sim::ShdrTwin shdr(io, world, sim_clock, {.period = std::chrono::milliseconds(20)});

  // Small blocks, so a damaged copy keeps most of its records readable (the test cuts one).
  cal::replay::CaptureWriter writer(argv[1], header(ids.port(), shdr.port()),
                                    {.block_bytes = 8 * 1024});
  cal::replay::CaptureRecorder recorder(writer);
  const cal::drivers::Clock clock = cal::drivers::loop_clock(io);  // the simulated time
  const auto transport = [&](std::uint16_t device) -> std::unique_ptr<t::Transport> {
    switch (device) {
      case ts::laser:
        return t::make_tcp(io, {.host = "127.0.0.1", .port = ids.port()});
      case ts::ptu300:
        return t::make_serial(io,
                              t::parse_serial_settings("4800 7E1", {.device = ptu.device_path()}));
      case ts::ballbar:
        return t::make_serial(io, {.device = bar.device_path(), .baud = 115200});
      default:
        return t::make_tcp(io, {.host = "127.0.0.1", .port = shdr.port()});
    }
  };
  auto instruments = ts::instruments(io, transport, {.clock = clock, .recorder = &recorder});
  std::size_t readings = 0;
  for (auto& i : instruments) i->start({.reading = [&](const auto&) { ++readings; }});

  const auto run_until = [&](double t_s) {
    time.run_until({}, static_cast<std::int64_t>(t_s * 1e9));
  };
  run_until(0.6);
  ids.set_beam_lost(0, true);
  run_until(0.8);
  ids.set_beam_lost(0, false);
  run_until(3.2);
  ids.drop_connections();
  run_until(ts::session_s);
  for (auto& i : instruments) i->stop();
  io.poll();
  writer.close();
  std::printf("%s: %zu readings, %llu bytes\n", argv[1], readings,
              static_cast<unsigned long long>(writer.bytes_written()));
  return 0;
}
