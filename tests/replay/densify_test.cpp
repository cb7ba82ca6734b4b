// cal::replay::densify, the captures `daq bench replay` measures: the halsampler feed made from
// an SHDR feed covers the capture to its end, so the run it came from ends as it did (issue 32:
// the replay of a 1 kHz halsampler capture missed its last stop).
#include "cal/replay/densify.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "cal/daq/trigger.hpp"
#include "cal/replay/capture.hpp"
#include "halsampler/codec.hpp"

namespace {

using cal::replay::RecordKind;
constexpr std::int64_t ms = 1'000'000;

std::span<const std::byte> bytes(std::string_view s) {
  return {reinterpret_cast<const std::byte*>(s.data()), s.size()};
}

// The end of a linear run as `daq sim --acquire --capture` records it with the SHDR feed: the
// adapter sends the axis position while it moves (every 20 ms here) and nothing while it stands;
// the laser (device 1, its bytes irrelevant here) reads every 100 ms. The axis arrives at
// 50 mm at 1.0 s and the run ends on the laser reading that completes the 1.5 s dwell
// (at 2.5 s: the SHDR feed's trigger holds the last position up to the laser's time), so the
// capture's last record is that reading.
std::filesystem::path shdr_capture() {
  const auto path = std::filesystem::temp_directory_path() / "caldaq_densify_shdr.cdq";
  const nlohmann::json header = {
      {"format", "caldaq.capture-header.v1"},
      {"instruments",
       {{{"device", 0}, {"driver", "shdr"}, {"role", "position"}, {"transport", "tcp x:7878"}},
        {{"device", 1}, {"driver", "ids3010"}, {"role", "laser"}, {"transport", "tcp x:9090"}}}}};
  cal::replay::CaptureWriter w(path, header.dump());
  w.event(0, 0, "opened");
  w.event(0, 1, "opened");
  for (std::int64_t t = 0; t <= 2'500 * ms; t += 20 * ms) {
    if (t <= 1'000 * ms) {  // 0 -> 50 mm in 1 s, linearly
      const double x_mm = 50.0 * static_cast<double>(t) / (1'000.0 * ms);
      w.record(t, 0, RecordKind::received,
               bytes(fmt::format("2026-11-28T12:00:00.000Z|Xcom|{:.4f}\n", x_mm)));
    }
    if (t % (100 * ms) == 0) w.record(t, 1, RecordKind::received, bytes("laser"));
  }
  w.close();
  return path;
}

TEST(Densify, HalsamplerLinesEveryPeriodToTheCaptureEndAndTheLastStopIsFound) {
  const auto in = shdr_capture();
  const auto out = std::filesystem::temp_directory_path() / "caldaq_densify_hal.cdq";
  cal::replay::densify(in, out, "halsampler", 1000.0);

  cal::replay::CaptureReader reader(out);
  const auto header = nlohmann::json::parse(reader.header_json());
  EXPECT_EQ(header["instruments"][0]["driver"], "halsampler");  // the feed replaced
  EXPECT_EQ(header["instruments"][1]["driver"], "ids3010");     // the laser as it was

  // The lines through the real codec, and the stop through the trigger as a run configures it
  // for a periodic feed (feed_holds false: the feed proves the axis still up to its newest
  // sample only).
  cal::drivers::codec::HalsamplerCodec codec({.column = {0, -1, -1}});
  std::vector<cal::drivers::codec::PositionFrame> frames;
  cal::daq::PositionTrigger trigger({.tolerance_um = 1.0, .dwell_s = 1.5});
  trigger.expect(50.0);
  std::vector<std::int64_t> line_times;
  std::vector<double> line_mm;
  std::vector<cal::daq::Capture> captures;
  std::int64_t previous = 0, last_record = 0;
  double feed_mm = 0.0;
  while (const auto r = reader.next()) {
    EXPECT_GE(r->time_ns, previous) << "records out of time order";
    previous = last_record = r->time_ns;
    if (r->kind != RecordKind::received) continue;
    if (r->device == 1) {  // the laser reads where the feed says the axis is
      if (auto c = trigger.add_reading(r->time_ns, feed_mm)) captures.push_back(*c);
      continue;
    }
    frames.clear();
    codec.feed(r->bytes, frames);
    ASSERT_EQ(frames.size(), 1u) << r->text();
    feed_mm = *frames[0].position_m[0] * 1e3;
    line_times.push_back(r->time_ns);
    line_mm.push_back(feed_mm);
    if (auto c = trigger.add_position(r->time_ns, feed_mm)) captures.push_back(*c);
  }
  EXPECT_FALSE(reader.damage());
  EXPECT_EQ(codec.stats().errors(), 0u);
  EXPECT_EQ(codec.stats().frames, 2501u);

  // 0 to 2.5 s every 1 ms, the last at the capture's last instant (the laser's reading).
  EXPECT_EQ(line_times.size(), 2501u);  // before the fix 2,500: none at 2.5 s
  ASSERT_GT(line_times.size(), 1'000u);
  EXPECT_EQ(line_times.back(), 2'500 * ms);
  EXPECT_EQ(last_record, 2'500 * ms);
  for (std::size_t k = 1; k < line_times.size(); ++k)
    ASSERT_EQ(line_times[k] - line_times[k - 1], ms) << k;
  // Interpolated while moving (the SHDR lines 20 ms apart): at 10 ms, 0.5 mm; still after.
  EXPECT_NEAR(line_mm[10], 0.5, 1e-6);
  EXPECT_NEAR(line_mm[1'000], 50.0, 1e-6);
  EXPECT_NEAR(line_mm.back(), 50.0, 1e-6);

  // The stop: still from 1.0 s, 1.5 s of it proven by the feed at the laser's reading at 2.5 s.
  ASSERT_EQ(captures.size(), 1u);  // before the fix none: the feed proved 1.499 s
  EXPECT_EQ(captures[0].start_ns, 1'000 * ms);
  EXPECT_EQ(captures[0].end_ns, 2'500 * ms);
  EXPECT_NEAR(captures[0].mean_mm, 50.0, 1e-6);
  std::filesystem::remove(in);
  std::filesystem::remove(out);
}

TEST(Densify, RefusesWhatItCannotMake) {
  const auto in = shdr_capture();
  const auto out = std::filesystem::temp_directory_path() / "caldaq_densify_bad.cdq";
  EXPECT_THROW(cal::replay::densify(in, out, "laser", 1000.0), std::runtime_error);
  EXPECT_THROW(cal::replay::densify(in, out, "halsampler", 0.0), std::runtime_error);
  // No thermometer in this capture.
  EXPECT_THROW(cal::replay::densify(in, out, "gauge", 90.0), std::runtime_error);
  std::filesystem::remove(in);
  std::filesystem::remove(out);
}

}  // namespace
