// The checked-in capture tests/data/captures/twin_session.cdq (recorded from the SIMULATED
// twins by record_captures; session and truth in twin_session.hpp), replayed through the
// real instruments. Every reading is checked against the simulated truth, so a change in a
// codec, an instrument, the replay bus or the reading of version-1 capture files that alters
// what the recorded bytes mean fails here. The same checks run on a fresh recording from the
// twins (cli test record_captures_fresh), so the recorder cannot rot either.
#include <gtest/gtest.h>

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cal/analysis/air.hpp"
#include "cal/replay/session.hpp"
#include "twin_session.hpp"

namespace {

namespace d = cal::drivers;
namespace ts = twin_session;
namespace fs = std::filesystem;

struct Replayed {
  std::vector<d::Reading> readings;
  std::vector<std::pair<std::uint16_t, d::Gap>> gaps;
  std::size_t codec_errors = 0;
  cal::replay::ReplayEnd end;
  std::string header;

  std::vector<d::Reading> of(std::uint16_t device, d::Quantity q, std::uint8_t channel = 0,
                             d::ReadingStatus s = d::ReadingStatus::ok) const {
    std::vector<d::Reading> out;
    for (const auto& r : readings)
      if (r.device == device && r.quantity == q && r.channel == channel && r.status == s)
        out.push_back(r);
    return out;
  }
};

Replayed replay(const fs::path& capture) {
  boost::asio::io_context io;
  cal::replay::ReplayBus bus(io, capture);
  Replayed out;
  out.header = bus.header_json();
  const auto transport = [&](std::uint16_t device) {
    return bus.transport(device, "replay of device " + std::to_string(device));
  };
  auto instruments = ts::instruments(io, transport, {.clock = bus.clock(), .replay = true});
  for (std::uint16_t id = 0; id < instruments.size(); ++id)
    instruments[id]->start({.reading = [&](const d::Reading& r) { out.readings.push_back(r); },
                            .gap = [&, id](const d::Gap& g) { out.gaps.emplace_back(id, g); },
                            .codec_error = [&](const auto&) { ++out.codec_errors; }});
  bool done = false;
  bus.start([&](const cal::replay::ReplayEnd& e) {
    out.end = e;
    done = true;
  });
  while (!done) io.run_one();
  io.poll();
  for (auto& i : instruments) i->stop();
  return out;
}

bool same(const d::Reading& a, const d::Reading& b) {
  return a.time_ns == b.time_ns && a.device == b.device && a.channel == b.channel &&
         a.quantity == b.quantity && a.status == b.status && a.value == b.value;
}

double seconds(std::int64_t ns) { return static_cast<double>(ns) * 1e-9; }

// The checks of one replayed twin session against the simulated truth.
void expect_truth(const Replayed& r) {
  const auto header = nlohmann::json::parse(r.header);
  EXPECT_TRUE(header.at("simulated").get<bool>());
  EXPECT_EQ(header.at("devices").size(), 4u);
  EXPECT_FALSE(r.end.damage.has_value());
  EXPECT_EQ(r.codec_errors, 0u);

  // Ciddor at 21.3 degC, 99 870 Pa, 42 %RH, 450 umol/mol, 632.991 nm. cal::air agrees with
  // NIST's equations to 1e-12 (analysis tests). Hand check from n - 1 = 2.71374e-4 at 20 degC,
  // 101 325 Pa, 50 %RH: scaled by p and 1/T, 2.71374e-4 * (99870 / 101325) * (293.15 / 294.45)
  // = 2.66297e-4; the water vapour falls from 1169 Pa to 1065 Pa, and each Pa of it lowers n
  // by about 3.7e-10, so + 0.0038e-6: 2.66335e-4, within the 2e-8 that the ideal-gas scaling
  // neglects (compressibility).
  const double n = cal::air::refractive_index({.temperature_degc = ts::air_temperature_degc,
                                               .pressure_pa = ts::air_pressure_pa,
                                               .humidity = cal::air::Humidity::relative_pct(42.0)})
                       .n;
  EXPECT_NEAR(n - 1.0, 2.66335e-4, 5e-8);

  // Laser: n * X, parked at 250 mm, moving to 260 mm monotonically (a first-order servo does
  // not overshoot), parked at 260 mm; the IDS prints whole picometres.
  const auto x = r.of(ts::laser, d::Quantity::displacement_m);
  ASSERT_GT(x.size(), 100u);
  EXPECT_NEAR(x.front().value, n * ts::start_x_mm * 1e-3, 1e-12);
  EXPECT_NEAR(x.back().value, n * ts::end_x_mm * 1e-3, 1e-12);
  for (std::size_t i = 1; i < x.size(); ++i) {
    ASSERT_GE(x[i].time_ns, x[i - 1].time_ns) << i;
    ASSERT_GE(x[i].value, x[i - 1].value - 1e-12) << "reading " << i << " moved backwards";
  }
  // The beam was blocked from 0.6 s to 0.8 s of simulated time (the instruments' clock
  // started within milliseconds of it): flagged readings there and only there.
  const auto lost = r.of(ts::laser, d::Quantity::displacement_m, 0, d::ReadingStatus::signal_lost);
  ASSERT_GE(lost.size(), 3u);
  for (const auto& l : lost) {
    EXPECT_GT(seconds(l.time_ns), 0.55);
    EXPECT_LT(seconds(l.time_ns), 1.0);  // margin for a loaded machine when recording
  }
  // ECU air, as configured; its refractive index by the same air.
  for (const auto& t : r.of(ts::laser, d::Quantity::air_temperature_degc))
    EXPECT_NEAR(t.value, ts::air_temperature_degc, 1e-9);
  for (const auto& p : r.of(ts::laser, d::Quantity::air_pressure_pa))
    EXPECT_NEAR(p.value, ts::air_pressure_pa, 1e-6);
  const auto ecu_n = r.of(ts::laser, d::Quantity::refractive_index);
  ASSERT_GE(ecu_n.size(), 5u);
  EXPECT_NEAR(ecu_n.back().value, n, 1e-8);

  // The dropped connection at 3.2 s: one gap on the laser, recorded, and readings resume.
  ASSERT_EQ(r.gaps.size(), 1u);
  EXPECT_EQ(r.gaps[0].first, ts::laser);
  const auto& gap = r.gaps[0].second;
  EXPECT_GT(seconds(gap.start_ns), 3.15);
  EXPECT_LT(seconds(gap.start_ns), 3.6);
  EXPECT_GT(gap.end_ns, gap.start_ns);
  EXPECT_TRUE(
      std::any_of(x.begin(), x.end(), [&](const auto& v) { return v.time_ns > gap.end_ns; }));
  EXPECT_TRUE(std::none_of(x.begin(), x.end(), [&](const auto& v) {
    return v.time_ns > gap.start_ns && v.time_ns < gap.end_ns;
  }));

  // PTU300: P in hPa with 2 decimals, T with 2, RH with 1, so exactly the configured air.
  const auto p = r.of(ts::ptu300, d::Quantity::air_pressure_pa);
  ASSERT_GE(p.size(), 10u);  // polled every 250 ms for 4.5 s
  for (const auto& v : p) EXPECT_DOUBLE_EQ(v.value, ts::air_pressure_pa);
  for (const auto& v : r.of(ts::ptu300, d::Quantity::air_temperature_degc))
    EXPECT_DOUBLE_EQ(v.value, ts::air_temperature_degc);
  for (const auto& v : r.of(ts::ptu300, d::Quantity::air_humidity_pct))
    EXPECT_DOUBLE_EQ(v.value, ts::air_humidity_pct);

  // Ballbar to (150, 0, 0) zeroed at 100 mm: X - 250 mm, i.e. 0 then +10 mm, 5 decimals.
  const auto bar = r.of(ts::ballbar, d::Quantity::length_m);
  ASSERT_GT(bar.size(), 400u);  // 100 samples per simulated second
  EXPECT_NEAR(bar.front().value, 0.0, 1e-8);
  EXPECT_NEAR(bar.back().value, (ts::end_x_mm - ts::start_x_mm) * 1e-3, 1e-8);
  for (std::size_t i = 1; i < bar.size(); ++i) ASSERT_GE(bar[i].value, bar[i - 1].value) << i;

  // SHDR commanded position: Xcom from 250 to 260 mm, Y and Z at 0. The checked-in capture's
  // twin sent a line every 5 ms; an adapter (and today's twin) sends a value only when it
  // changes: a few tens of lines while X moves for 1 s, one while it is parked.
  const auto px = r.of(ts::position, d::Quantity::machine_position_m, 0);
  ASSERT_GT(px.size(), 20u);
  EXPECT_DOUBLE_EQ(px.front().value, 0.250);
  EXPECT_DOUBLE_EQ(px.back().value, 0.260);
  for (const auto& v : px) {
    EXPECT_GE(v.value, 0.250);
    EXPECT_LE(v.value, 0.260);
  }
  for (const std::uint8_t axis : {std::uint8_t{1}, std::uint8_t{2}})
    for (const auto& v : r.of(ts::position, d::Quantity::machine_position_m, axis))
      EXPECT_EQ(v.value, 0.0);
}

fs::path checked_in() { return fs::path(CALDAQ_CAPTURES_DIR) / "twin_session.cdq"; }

TEST(CheckedInCapture, ReplaysToTheSimulatedTruth) {
  SCOPED_TRACE(checked_in().string());
  expect_truth(replay(checked_in()));
}

TEST(CheckedInCapture, ReplayIsDeterministic) {
  const auto a = replay(checked_in());
  const auto b = replay(checked_in());
  ASSERT_EQ(a.readings.size(), b.readings.size());
  for (std::size_t i = 0; i < a.readings.size(); ++i)
    ASSERT_TRUE(same(a.readings[i], b.readings[i])) << "reading " << i;
  ASSERT_EQ(a.gaps.size(), b.gaps.size());
  EXPECT_EQ(a.gaps[0].second.start_ns, b.gaps[0].second.start_ns);
}

// A copy cut at 60 % of its bytes (a crash mid-write): the damage is reported with its block,
// and the readings before it are exactly the first readings of the whole capture.
TEST(CheckedInCapture, TruncatedCopyKeepsEverythingBeforeTheCut) {
  const auto full = replay(checked_in());
  const auto cut = fs::temp_directory_path() / "caldaq_twin_session_cut.cdq";
  fs::copy_file(checked_in(), cut, fs::copy_options::overwrite_existing);
  fs::resize_file(cut, fs::file_size(cut) * 6 / 10);
  const auto part = replay(cut);
  fs::remove(cut);
  ASSERT_TRUE(part.end.damage.has_value());
  EXPECT_NE(cal::replay::describe(*part.end.damage).find("block"), std::string::npos);
  // 8 KiB blocks: at most one block's worth (a few hundred readings) is lost past the cut.
  EXPECT_GT(part.readings.size(), full.readings.size() / 2);
  ASSERT_LT(part.readings.size(), full.readings.size());
  for (std::size_t i = 0; i < part.readings.size(); ++i)
    ASSERT_TRUE(same(part.readings[i], full.readings[i])) << "reading " << i;
}

// Issue 15: a capture cut exactly between two blocks (a writer killed, a copy cut) loses its
// end block: at every block boundary the replay reports it with that byte offset, and every
// record before it is replayed: exactly the first readings of the whole capture.
TEST(CheckedInCapture, CutsAtEveryBlockBoundaryAreReportedWithTheirOffset) {
  const auto full = replay(checked_in());
  ASSERT_FALSE(full.end.damage) << cal::replay::describe(*full.end.damage);
  // The boundaries, from the documented layout: header 20 + H bytes, then blocks of 16 + L.
  std::ifstream in(checked_in(), std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto u32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    std::memcpy(&v, bytes.data() + at, 4);
    return v;
  };
  std::vector<std::size_t> boundaries{20 + u32(12)};
  while (u32(boundaries.back()) == 0x4B4C4243)  // CBLK; the last boundary is before CEND
    boundaries.push_back(boundaries.back() + 16 + u32(boundaries.back() + 4));
  ASSERT_GT(boundaries.size(), 5u);
  std::size_t previous = 0;
  for (std::size_t b = 0; b < boundaries.size(); ++b) {
    SCOPED_TRACE("cut at byte " + std::to_string(boundaries[b]));
    const auto cut = fs::temp_directory_path() / "caldaq_twin_session_boundary.cdq";
    std::ofstream(cut, std::ios::binary) << bytes.substr(0, boundaries[b]);
    const auto part = replay(cut);
    fs::remove(cut);
    ASSERT_TRUE(part.end.damage.has_value());
    EXPECT_EQ(part.end.damage->offset, boundaries[b]);
    EXPECT_EQ(part.end.damage->block, b);
    EXPECT_NE(part.end.damage->what.find("no end block"), std::string::npos)
        << part.end.damage->what;
    ASSERT_LE(part.readings.size(), full.readings.size());
    for (std::size_t i = 0; i < part.readings.size(); ++i)
      ASSERT_TRUE(same(part.readings[i], full.readings[i])) << "reading " << i;
    EXPECT_GE(part.readings.size(), previous);  // each cut keeps at least what the last kept
    previous = part.readings.size();
  }
}

// What `daq replay` does after a run that ends before the capture does: the rest is read
// without delivering it, so damage further on is still found.
TEST(CheckedInCapture, ReadingToTheEndFindsDamageAfterTheRun) {
  const auto cut = fs::temp_directory_path() / "caldaq_twin_session_tail.cdq";
  fs::copy_file(checked_in(), cut, fs::copy_options::overwrite_existing);
  fs::resize_file(cut, fs::file_size(cut) - 3);  // into the end block
  for (const auto& [file, damaged] : {std::pair{checked_in(), false}, std::pair{cut, true}}) {
    boost::asio::io_context io;
    cal::replay::ReplayBus bus(io, file);
    bool done = false;
    bus.start([&](const cal::replay::ReplayEnd&) { done = true; });
    io.run_one();  // one batch delivered (to nobody), as if the run ended there
    const auto end = bus.read_to_end();
    EXPECT_FALSE(done);
    EXPECT_EQ(end.damage.has_value(), damaged) << file;
    if (damaged) {
      EXPECT_EQ(end.damage->what, "truncated end block");
    }
    EXPECT_GT(end.records, 1000u);
    io.run();  // the loop's own end is not reported again
    EXPECT_FALSE(done);
  }
  fs::remove(cut);
}

// A fresh recording from the twins (record_captures, run by ctest before this test with
// CALDAQ_FRESH_CAPTURE set) meets the same truth.
TEST(FreshCapture, RecordedFromTheTwinsMeetsTheSameTruth) {
  const char* fresh = std::getenv("CALDAQ_FRESH_CAPTURE");
  if (fresh == nullptr)
    GTEST_FAIL() << "CALDAQ_FRESH_CAPTURE is not set (see tests/replay/CMakeLists.txt)";
  SCOPED_TRACE(fresh);
  expect_truth(replay(fresh));
}

}  // namespace
