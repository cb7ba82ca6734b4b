// The TEMPer instrument on recorded HID reports (HID cannot be emulated here without kernel
// support): a capture written report by report, replayed through the real instrument code.
#include <gtest/gtest.h>

#include <boost/asio/io_context.hpp>

#include "../support/temper_report.hpp"
#include "cal/replay/capture.hpp"
#include "cal/replay/session.hpp"
#include "temper/instrument.hpp"

namespace {

namespace d = cal::drivers;

using cal::test::temper_report;

TEST(TemperReplay, RecordedReportsGiveTimedReadingsAndTheMissingProbeIsCounted) {
  const auto path = std::filesystem::temp_directory_path() / "caldaq_temper_replay.cdq";
  {
    cal::replay::CaptureWriter w(path, R"({"test":"temper"})");
    const auto rx = [&](std::int64_t t_ns, const std::string& r) {
      w.record(t_ns, 0, cal::replay::RecordKind::received, cal::drivers::codec::as_bytes(r));
    };
    w.event(0, 0, "opened");
    rx(10'000'000, temper_report({0x82, 0x02}));  // init answer: 2 sensors
    rx(1'000'000'000,
       temper_report({0x80, 0x80, 0x09, 0x2E}));  // inner 0x092E = 2350 -> 23.50 degC
    rx(1'000'500'000, temper_report({0x80, 0x01, 0x4E, 0x20}));  // probe: 200.00 degC = missing
    rx(2'000'000'000,
       temper_report({0x80, 0x80, 0x09, 0x60}));  // inner 0x0960 = 2400 -> 24.00 degC
    w.close();
  }
  boost::asio::io_context io;
  cal::replay::ReplayBus bus(io, path);
  auto t = d::make_temper(io, bus.transport(0, "hid 413d:2107"),
                          {.name = "TEMPer", .clock = bus.clock(), .replay = true},
                          {.family = d::codec::TemperFamily::gold});
  std::vector<d::Reading> readings;
  int codec_errors = 0;
  t->start({.reading = [&](const d::Reading& r) { readings.push_back(r); },
            .codec_error = [&](const d::codec::CodecError&) { ++codec_errors; }});
  bool done = false;
  bus.start([&](const cal::replay::ReplayEnd&) { done = true; });
  while (!done) io.run_one();
  io.poll();
  ASSERT_EQ(readings.size(), 2u);
  EXPECT_EQ(readings[0].quantity, d::Quantity::material_temperature_degc);
  EXPECT_EQ(readings[0].time_ns, 1'000'000'000);
  EXPECT_DOUBLE_EQ(readings[0].value, 23.50);
  EXPECT_EQ(readings[1].time_ns, 2'000'000'000);
  EXPECT_DOUBLE_EQ(readings[1].value, 24.00);
  EXPECT_EQ(codec_errors, 1);
  EXPECT_EQ(t->codec_stats().out_of_range, 1u);
  t->stop();
  std::filesystem::remove(path);
}

}  // namespace
