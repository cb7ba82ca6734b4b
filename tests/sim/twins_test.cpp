// The real transports against the simulated twins: the bytes on the wire are those of the
// protocols, and the values are the simulated truth converted by hand.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>
#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "../support/asio_loop.hpp"
#include "cal/drivers/transport/transport.hpp"
#include "ids3010/twin.hpp"
#include "line_gauge/twin.hpp"
#include "ptu300/codec.hpp"
#include "ptu300/twin.hpp"

namespace {

namespace sim = cal::drivers::sim;
namespace t = cal::drivers::transport;
using namespace std::chrono_literals;

using cal::test::bytes;

using cal::test::run_until;

// A machine parked at x = 100 mm (no errors), still air at 20 degC, 101325 Pa, 50 %RH.
struct Bench {
  boost::asio::io_context io;
  double now_s = 0.0;
  sim::Clock clock = [this] { return now_s; };
  sim::World world{[] {
                     sim::MachineConfig c;
                     c.start_mm = {100, 0, 0};
                     return c;
                   }(),
                   sim::AirConfig{}};
  std::string received;
  std::optional<t::Error> error;

  void open(t::Transport& tr) {
    tr.open(
        [this](std::span<const std::byte> b) {
          received.append(reinterpret_cast<const char*>(b.data()), b.size());
        },
        [this](const t::Error& e) { error = e; });
  }
  // A serial port on a PTU300 twin, opened at 4800 7E1 as the device's settings ask.
  std::unique_ptr<t::Transport> open_ptu300(const sim::Ptu300Twin& twin) {
    auto port =
        t::make_serial(io, t::parse_serial_settings("4800 7E1", {.device = twin.device_path()}));
    open(*port);
    return port;
  }
  std::string next_line() {
    run_until(io, [&] { return received.find('\n') != std::string::npos; });
    const auto eol = received.find('\n');
    if (eol == std::string::npos) return "(nothing)";
    std::string line = received.substr(0, eol + 1);
    received.erase(0, eol + 1);
    return line;
  }
};

nlohmann::json call(Bench& b, t::Transport& tr, std::string_view method, int id) {
  tr.write(
      bytes(fmt::format(R"({{"jsonrpc": "2.0", "method": "{}", "params": [], "id": {}, "api": 2}})"
                        "\n",
                        method, id)));
  return nlohmann::json::parse(b.next_line());
}

TEST(IdsTwin, AnswersJsonRpcWithTheOpticalPathInPicometres) {
  Bench b;
  sim::IdsTwin twin(b.io, b.world, b.clock, {.datum_mm = {0, 0, 0}});
  auto tcp = t::make_tcp(b.io, {.host = "127.0.0.1", .port = twin.port()});
  b.open(*tcp);
  run_until(b.io, [&] { return tcp->is_open(); });

  // Not measuring yet: the twin's error code 1, and the id is echoed.
  auto r = call(b, *tcp, "com.attocube.ids.displacement.getAxesDisplacement", 7);
  EXPECT_EQ(r["id"], 7);
  EXPECT_EQ(r["result"][0], sim::IdsTwin::error_not_measuring);

  EXPECT_EQ(call(b, *tcp, "com.attocube.ids.system.startMeasurement", 8)["result"][0], 0);
  EXPECT_EQ(call(b, *tcp, "com.attocube.ids.system.getCurrentMode", 9)["result"][1],
            "measurement starting");
  b.now_s = 1.0;  // past the 0.2 s start-up
  EXPECT_EQ(call(b, *tcp, "com.attocube.ids.system.getCurrentMode", 10)["result"][1],
            "measurement running");
  // Edlen/Ciddor n = 1.000271374 at 20 degC, 101325 Pa, 50 %RH: 100 mm reads
  // 100.0271374 mm = 100027137400 pm (within 1e-8 relative: 1000 pm).
  r = call(b, *tcp, "com.attocube.ids.displacement.getAxesDisplacement", 11);
  EXPECT_EQ(r["result"][0], 0);
  EXPECT_NEAR(r["result"][1].get<double>(), 100027137400.0, 1000.0);
  EXPECT_EQ(r["result"][2], 0);  // axis 2 measures nothing

  // The ECU reports once its interface is enabled (attocube's ecu.py), as the device.
  EXPECT_EQ(call(b, *tcp, "com.attocube.ecu.getPressureInHPa", 15)["result"][0],
            sim::IdsTwin::error_ecu_disabled);
  EXPECT_EQ(call(b, *tcp, "com.attocube.ecu.enable", 16)["result"][0], 0);
  r = call(b, *tcp, "com.attocube.ecu.getPressureInHPa", 12);
  EXPECT_NEAR(r["result"][1].get<double>(), 1013.25, 1e-9);

  twin.set_beam_lost(0, true);
  EXPECT_EQ(call(b, *tcp, "com.attocube.ids.displacement.getAxesDisplacement", 13)["result"][0],
            sim::IdsTwin::error_beam_lost);

  r = call(b, *tcp, "com.attocube.ids.no.suchMethod", 14);
  EXPECT_EQ(r["error"]["code"], -32601);
  EXPECT_EQ(r["id"], 14);
  EXPECT_EQ(twin.requests_served(), 10u);  // with the two ECU-enable requests

  twin.drop_connections();
  run_until(b.io, [&] { return b.error.has_value(); });
  ASSERT_TRUE(b.error);
  EXPECT_EQ(b.error->kind, t::ErrorKind::closed_by_peer);
}

TEST(IdsTwin, SpeaksTheConfiguredApiGenerationOnly) {
  // Firmware 1.9.1 renamed com.attocube.ids.* to com.attocube.sen.* (attocube-systems/IDS-APIs);
  // a twin of either generation does not know the other's names, as the device does not.
  Bench b;
  sim::IdsTwin twin(b.io, b.world, b.clock, {.api = cal::drivers::codec::IdsApi::sen});
  auto tcp = t::make_tcp(b.io, {.host = "127.0.0.1", .port = twin.port()});
  b.open(*tcp);
  run_until(b.io, [&] { return tcp->is_open(); });
  EXPECT_EQ(call(b, *tcp, "com.attocube.sen.system.getCurrentMode", 1)["result"][1], "system idle");
  EXPECT_EQ(call(b, *tcp, "com.attocube.ids.system.getCurrentMode", 2)["error"]["code"], -32601);
  EXPECT_EQ(call(b, *tcp, "com.attocube.system.getFirmwareVersion", 3)["result"][1],
            "1.9.1 (simulated)");
  const auto text = call(b, *tcp, "com.attocube.system.errorNumberToString", 4);
  EXPECT_EQ(text["result"][0], 0);  // (no params: the twin's text for an unknown number)
}

TEST(IdsTwin, AnswersUnterminatedRequestsAndEndsItsAnswersWithCrLf) {
  // attocube's ACS.py (IDS-APIs) and the EPICS driver nmarks99/attocubeIDS write each request
  // with no terminator; ACS.py reads answers up to CR LF. Two requests in one write, one split
  // inside a string, one ended by LF (MATLAB's writeline): each answered once, with CR LF.
  Bench b;
  sim::IdsTwin twin(b.io, b.world, b.clock);
  auto tcp = t::make_tcp(b.io, {.host = "127.0.0.1", .port = twin.port()});
  b.open(*tcp);
  run_until(b.io, [&] { return tcp->is_open(); });
  const auto request = [](int id) {
    return fmt::format(
        R"({{"jsonrpc": "2.0", "method": "com.attocube.ids.system.getCurrentMode", "params": [], "id": {}, "api": 2}})",
        id);
  };
  tcp->write(bytes(request(1) + request(2)));
  const std::string third = request(3);
  tcp->write(bytes(third.substr(0, 40)));  // inside the method's string
  for (const int id : {1, 2}) {
    const std::string line = b.next_line();
    ASSERT_TRUE(line.ends_with("}\r\n")) << line;
    EXPECT_EQ(nlohmann::json::parse(line)["id"], id);
    EXPECT_EQ(nlohmann::json::parse(line)["result"][1], "system idle");
  }
  EXPECT_EQ(b.next_line(), "(nothing)");  // half a request is not answered
  tcp->write(bytes(third.substr(40)));
  EXPECT_EQ(nlohmann::json::parse(b.next_line())["id"], 3);
  tcp->write(bytes(request(4) + "\n"));
  EXPECT_EQ(nlohmann::json::parse(b.next_line())["id"], 4);
  tcp->write(bytes("not json\n"));  // a line that is no object: JSON-RPC's parse error
  EXPECT_EQ(nlohmann::json::parse(b.next_line())["error"]["code"], -32700);
  EXPECT_EQ(twin.requests_served(), 5u);
  EXPECT_TRUE(b.received.empty());
}

TEST(Ptu300Twin, AnswersSendAt4800SevenEvenOne) {
  Bench b;
  sim::Ptu300Twin twin(b.io, b.world, b.clock);
  auto port = b.open_ptu300(twin);
  port->write(bytes("SEND\r"));
  EXPECT_EQ(b.next_line(), "P= 1013.25 hPa T=  20.00 'C RH=  50.0 %RH\r\n");
  port->write(bytes("INTV 2 S\r"));
  EXPECT_EQ(b.next_line(), "Output intrv. : 2 s\r\n");
  // RUN mode: one line per 2 s of simulated time.
  port->write(bytes("R\r"));
  EXPECT_EQ(b.next_line().substr(0, 3), "P= ");
  const auto before = twin.lines_sent();
  b.now_s = 1.0;
  b.io.run_for(30ms);
  EXPECT_EQ(twin.lines_sent(), before);
  b.now_s = 2.0;
  run_until(b.io, [&] { return twin.lines_sent() > before; });
  EXPECT_EQ(twin.lines_sent(), before + 1);
  port->write(bytes("S\r"));
  EXPECT_EQ(b.next_line().substr(0, 3), "P= ");
  twin.unplug();
  run_until(b.io, [&] { return b.error.has_value(); });
  ASSERT_TRUE(b.error);
}

TEST(Ptu300Twin, TakesCommandsEndedByLfOrCrLfAndAnswersTheInformationalCommands) {
  // The PTU300 user's guide (M210796EN) ends commands with <cr>; a terminal or a program may
  // send LF or CR LF: each command is answered once. ?, VERS, ERRS and UNIT answer as the
  // 300-series guides show them (no "Unknown command").
  Bench b;
  sim::Ptu300Twin twin(b.io, b.world, b.clock);
  auto port = b.open_ptu300(twin);
  port->write(bytes("SEND\n"));
  EXPECT_EQ(b.next_line(), "P= 1013.25 hPa T=  20.00 'C RH=  50.0 %RH\r\n");
  port->write(bytes("send\r\nVERS\n"));  // one answer each: the LF of CR LF is no command
  EXPECT_EQ(b.next_line().substr(0, 3), "P= ");
  EXPECT_EQ(b.next_line(), "PTU300 / 5.10 (simulated)\r\n");
  port->write(bytes("ERRS\r"));
  EXPECT_EQ(b.next_line(), "No errors\r\n");
  port->write(bytes("?\r"));
  EXPECT_EQ(b.next_line(), "PTU300 / 5.10 (simulated)\r\n");
  std::string settings;
  for (std::string line; (line = b.next_line()) != "(nothing)";) settings += line;
  EXPECT_NE(settings.find("Baud P D S     : 4800 E 7 1\r\n"), std::string::npos) << settings;
  EXPECT_NE(settings.find("Output units   : metric\r\n"), std::string::npos) << settings;
  EXPECT_EQ(settings.find("Unknown"), std::string::npos) << settings;
  // UNIT N: the temperature in 'F, as a unit left non-metric prints it; the real codec reads
  // it back to degC.
  port->write(bytes("UNIT N\r"));
  EXPECT_EQ(b.next_line(), "Output units   : non metric\r\n");
  port->write(bytes("SEND\r"));
  const std::string fahrenheit = b.next_line();
  EXPECT_EQ(fahrenheit, "P= 1013.25 hPa T=  68.00 'F RH=  50.0 %RH\r\n");
  cal::drivers::codec::Ptu300Codec codec;
  std::vector<cal::drivers::codec::Ptu300Frame> frames;
  std::vector<cal::drivers::codec::CodecError> errors;
  codec.feed(fahrenheit, frames, errors);
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_TRUE(errors.empty());
  EXPECT_NEAR(*frames[0].temperature_degc, 20.0, 1e-9);
  port->write(bytes("UNIT\r"));
  EXPECT_EQ(b.next_line(), "Output units   : non metric\r\n");
  port->write(bytes("XYZZY\n"));
  EXPECT_EQ(b.next_line(), "Unknown command\r\n");
}

TEST(GaugeTwin, StreamsTheBarLengthAtItsSampleRate) {
  // Tool at (100, 0, 0), table ball at (0, 0, 0), gauge zeroed at 99.99 mm: reads +0.01 mm.
  Bench b;
  sim::GaugeTwin twin(b.io, b.world, b.clock,
                      {.pivot_mm = {0, 0, 0}, .zero_length_mm = 99.99, .sample_rate_hz = 1000});
  auto port = t::make_serial(b.io, {.device = twin.device_path(), .baud = 115200});
  b.open(*port);
  EXPECT_EQ(b.next_line(), "+000.01000\r\n");
  // Samples k / 1000 s for k = 0..250 are due at t = 0.25 s: 251 lines in all.
  b.now_s = 0.25;
  run_until(b.io, [&] { return twin.lines_sent() >= 251 && b.received.size() >= 250 * 12; });
  EXPECT_EQ(twin.lines_sent(), 251u);
  EXPECT_EQ(b.received.size(), 250u * 12u);  // 250 more lines of 12 bytes
}

TEST(GaugeTwin, AnswersItsRequestInPolledMode) {
  Bench b;
  sim::GaugeTwin twin(
      b.io, b.world, b.clock,
      {.zero_length_mm = 100.5, .continuous = false, .request = "?", .decimals = 4});
  auto port = t::make_serial(b.io, {.device = twin.device_path()});
  b.open(*port);
  port->write(bytes("?\r"));
  EXPECT_EQ(b.next_line(), "-000.5000\r\n");
  EXPECT_EQ(twin.lines_sent(), 1u);
}

TEST(GaugeTwin, CarriesAnyScalarAsAThermometer) {
  // A thermometer on the structure: the machine temperature, 20 degC at t = 0.
  Bench b;
  sim::GaugeTwin twin(b.io, b.world, b.clock,
                      {.continuous = false, .decimals = 3, .value = [](const sim::World& w) {
                         return w.state().machine_temperature_degc;
                       }});
  auto port = t::make_serial(b.io, {.device = twin.device_path()});
  b.open(*port);
  port->write(bytes("?\r"));
  EXPECT_EQ(b.next_line(), "+020.000\r\n");
}

}  // namespace
