// What a device says instead of a value is never a reading, and the run is told why (issue
// 26): a PTU300 field printed as stars (a failed measurement, a check such as PDMAX exceeded),
// an IDS3010 ECU value answered with a non-zero error number. Recorded bytes replayed through
// the real instruments.
#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>
#include <filesystem>
#include <string>
#include <vector>

#include "cal/replay/capture.hpp"
#include "cal/replay/session.hpp"
#include "ids3010/codec.hpp"
#include "ids3010/instrument.hpp"
#include "ptu300/instrument.hpp"

namespace {

namespace d = cal::drivers;

struct Heard {
  std::vector<d::Reading> readings;
  std::vector<d::DeviceMessage> messages;
};

// Replays the capture `write` records (device 0) through the instrument `make` returns.
template <class Write, class Make>
Heard replayed(const std::string& name, Write&& write, Make&& make) {
  const auto path = std::filesystem::temp_directory_path() / ("caldaq_" + name + ".cdq");
  {
    cal::replay::CaptureWriter w(path, R"({"test":"device errors"})");
    w.event(0, 0, "opened");
    write(w);
    w.close();
  }
  boost::asio::io_context io;
  cal::replay::ReplayBus bus(io, path);
  auto instrument = make(io, bus);
  Heard heard;
  instrument->start({.reading = [&](const d::Reading& r) { heard.readings.push_back(r); },
                     .message = [&](const d::DeviceMessage& m) { heard.messages.push_back(m); }});
  bool done = false;
  bus.start([&](const cal::replay::ReplayEnd&) { done = true; });
  while (!done) io.run_one();
  io.poll();
  instrument->stop();
  std::filesystem::remove(path);
  return heard;
}

void record(cal::replay::CaptureWriter& w, double t_s, cal::replay::RecordKind kind,
            const std::string& bytes) {
  w.record(static_cast<std::int64_t>(t_s * 1e9), 0, kind, d::codec::as_bytes(bytes));
}

TEST(Ptu300Replay, StarsAreNoReadingAndAreSaidOnceWithTheirReason) {
  const auto heard = replayed(
      "ptu300_stars",
      [](cal::replay::CaptureWriter& w) {
        const auto rx = [&](double t_s, const std::string& line) {
          record(w, t_s, cal::replay::RecordKind::received, line);
        };
        rx(1, "P= 1013.2 hPa T= 22.2 'C RH= 38.3 %RH\r\n");
        rx(2, "P= 1013.3 hPa T= ****.* 'C RH= 38.4 %RH\r\n");  // T failed
        rx(3, "P= 1013.3 hPa T= ****.* 'C RH= 38.4 %RH\r\n");  // still: said once
        // The user's guide's PDMAX example (M210796EN-G p. 111): P1 and P2 differ beyond the
        // limit, P is printed as stars and the ERR field reads 1000.
        rx(4, "1034.2 1035.4 ****** hPa 1000\r\n");
        rx(5, "P= 1013.4 hPa T= 22.3 'C RH= 38.5 %RH\r\n");
      },
      [](boost::asio::io_context& io, cal::replay::ReplayBus& bus) {
        return d::make_ptu300(io, bus.transport(0, "serial /dev/ttyUSB0 4800 7E1"),
                              {.name = "PTU300", .clock = bus.clock(), .replay = true});
      });
  const auto& readings = heard.readings;
  const auto& messages = heard.messages;
  std::vector<std::int64_t> temperature_s, pressure_s;
  for (const auto& r : readings) {
    EXPECT_EQ(r.status, d::ReadingStatus::ok);
    if (r.quantity == d::Quantity::air_temperature_degc) {
      temperature_s.push_back(r.time_ns / 1'000'000'000);
      EXPECT_GT(r.value, 22.0);  // never the 0 a starred field holds
    }
    if (r.quantity == d::Quantity::air_pressure_pa) pressure_s.push_back(r.time_ns / 1'000'000'000);
  }
  EXPECT_EQ(temperature_s, (std::vector<std::int64_t>{1, 5}));
  EXPECT_EQ(pressure_s, (std::vector<std::int64_t>{1, 2, 3, 5}));

  ASSERT_EQ(messages.size(), 3u);
  EXPECT_EQ(messages[0].severity, d::DeviceMessage::Severity::warning);
  EXPECT_EQ(messages[0].text.rfind("T: printed as stars, no value", 0), 0u) << messages[0].text;
  EXPECT_NE(messages[0].text.find("ERRS"), std::string::npos) << messages[0].text;
  EXPECT_EQ(messages[1].severity, d::DeviceMessage::Severity::warning);
  EXPECT_EQ(messages[1].text.rfind("the hPa field: printed as stars", 0), 0u) << messages[1].text;
  EXPECT_EQ(messages[2].severity, d::DeviceMessage::Severity::info);
  EXPECT_EQ(messages[2].text, "T: measured again");
}

// The ECU getters' result[0] is the device's error number (attocube's wrappers: errNo): with a
// non-zero number the value beside it is not a measurement. Before, it became an air reading.
TEST(Ids3010Replay, AnEcuValueWithAnErrorNumberIsNoReading) {
  const auto heard = replayed(
      "ids_ecu_error",
      [](cal::replay::CaptureWriter& w) {
        d::codec::IdsCodec requests;  // the request lines as the instrument writes them
        const auto exchange = [&](double t_s, d::codec::IdsMethod m, const std::string& result,
                                  std::span<const d::codec::IdsParam> params = {}) {
          record(w, t_s, cal::replay::RecordKind::sent, requests.encode(m, params));
          record(w, t_s + 0.01, cal::replay::RecordKind::received,
                 R"({"jsonrpc":"2.0","result":)" + result + R"(,"id":)" +
                     std::to_string(requests.last_id()) + "}\n");
        };
        using M = d::codec::IdsMethod;
        exchange(1, M::ecu_get_temperature, "[0,21.5]");
        exchange(2, M::ecu_get_temperature, "[5,21.6]");  // error 5: 21.6 is no value
        const d::codec::IdsParam explain[] = {std::int64_t{1}, std::int64_t{5}};
        exchange(2.1, M::error_number_to_string, R"([0,"ECU sensor not connected"])", explain);
        exchange(3, M::ecu_get_temperature, "[0,21.7]");
      },
      [](boost::asio::io_context& io, cal::replay::ReplayBus& bus) {
        return d::make_ids3010(io, bus.transport(0, "tcp 192.168.1.1:9090"),
                               {.name = "IDS3010", .clock = bus.clock(), .replay = true});
      });
  std::vector<double> air_degc;
  for (const auto& r : heard.readings)
    if (r.quantity == d::Quantity::air_temperature_degc) air_degc.push_back(r.value);
  EXPECT_EQ(air_degc, (std::vector<double>{21.5, 21.7}));
  ASSERT_EQ(heard.messages.size(), 1u);
  EXPECT_EQ(heard.messages[0].severity, d::DeviceMessage::Severity::error);
  EXPECT_EQ(heard.messages[0].code, 5);
  EXPECT_NE(heard.messages[0].text.find("ECU sensor not connected"), std::string::npos)
      << heard.messages[0].text;
}

}  // namespace
