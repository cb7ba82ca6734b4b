// Renishaw .rtx reader: files written here byte by byte in the publicly described layout
// (HEADER:: lines, Data:, little-endian float64 samples, EOF::), then damaged.
#include "cal/replay/rtx.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <fstream>

namespace {

using cal::replay::RtxError;
using cal::replay::RtxReader;

const std::string kHeader =
    "HEADER::\r\nOwner: CARTO-Dynamic\r\nVersion no: 4.13.9237.28405\r\nFile Type: Linear\r\n"
    "Velocity: 0\r\nSample rate: 50000\r\nSample no: 4\r\nTrigger point: 0\r\n"
    "Trigger interval: 2E-05\r\nActual sample rate: 10000\r\nFlags: 0 1 2 0 2\r\n"
    "Machine: VMC-1\r\nSerial No: 123X45\r\nDate: 10/02/2025 12:58:22\r\nBy: User\r\n"
    "Axis: X\r\nLocation: \r\nData:\r\n";

// IEEE 754 binary64, little-endian, written out by hand: 1.0 = 3FF0000000000000,
// -2.5 = C004000000000000, 0.125 = 3FC0000000000000, 1000.0 = 408F400000000000.
std::string samples() {
  const std::array<std::array<unsigned char, 8>, 4> le{{
      {0, 0, 0, 0, 0, 0, 0xF0, 0x3F},
      {0, 0, 0, 0, 0, 0, 0x04, 0xC0},
      {0, 0, 0, 0, 0, 0, 0xC0, 0x3F},
      {0, 0, 0, 0, 0, 0x40, 0x8F, 0x40},
  }};
  std::string s;
  for (const auto& b : le) s.append(reinterpret_cast<const char*>(b.data()), 8);
  return s;
}

std::filesystem::path write(const std::string& name, const std::string& bytes) {
  const auto p = std::filesystem::temp_directory_path() / ("caldaq_rtx_" + name);
  std::ofstream(p, std::ios::binary) << bytes;
  return p;
}

std::vector<double> all(RtxReader& r) {
  std::vector<double> out, buf(3);  // a buffer smaller than the file: reads in pieces
  while (const auto n = r.read(buf)) out.insert(out.end(), buf.begin(), buf.begin() + n);
  return out;
}

TEST(Rtx, ReadsTheHeaderAndTheSamples) {
  RtxReader r(write("ok.rtx", kHeader + samples() + "EOF::\r\n"));
  const auto& h = r.header();
  EXPECT_EQ(h.sample_rate_hz, 10000.0);  // the actual rate wins over the nominal 50000
  EXPECT_EQ(h.declared_samples, 4u);
  EXPECT_EQ(h.samples, 4u);
  EXPECT_TRUE(h.eof_marker);
  EXPECT_EQ(h.trailing_bytes, 0u);
  EXPECT_EQ(h.data_offset, kHeader.size());
  ASSERT_NE(h.find("Serial No"), nullptr);
  EXPECT_EQ(*h.find("Serial No"), "123X45");
  EXPECT_EQ(*h.find("Axis"), "X");
  EXPECT_EQ(*h.find("Location"), "");
  EXPECT_EQ(h.find("Nope"), nullptr);
  EXPECT_EQ(all(r), (std::vector<double>{1.0, -2.5, 0.125, 1000.0}));
}

TEST(Rtx, APartialLastSampleAndNoEofMarkerAreReportedAndTheRestRead) {
  const auto s = samples();
  RtxReader r(write("cut.rtx", kHeader + s.substr(0, 8 * 3 + 5)));  // cut inside sample 4
  EXPECT_FALSE(r.header().eof_marker);
  EXPECT_EQ(r.header().samples, 3u);
  EXPECT_EQ(r.header().trailing_bytes, 5u);
  EXPECT_EQ(all(r), (std::vector<double>{1.0, -2.5, 0.125}));
}

TEST(Rtx, FallsBackToTheNominalRateAndAcceptsBareLineFeeds) {
  std::string h = "HEADER::\nSample rate: 50000\nActual sample rate: 0\nData:\n";
  RtxReader r(write("lf.rtx", h + samples()));
  EXPECT_EQ(r.header().sample_rate_hz, 50000.0);
  EXPECT_EQ(r.header().samples, 4u);
}

void expect_error(const std::string& name, const std::string& bytes, const std::string& what) {
  try {
    RtxReader r(write(name, bytes));
    FAIL() << name << " was accepted";
  } catch (const RtxError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(name), std::string::npos) << msg;  // names the file
    EXPECT_NE(msg.find(what), std::string::npos) << msg;
  }
}

TEST(Rtx, RefusesWhatIsNotAnRtxFileNamingFileAndPlace) {
  expect_error("csv.rtx", "time,value\n0,1\n", "byte 0: not a Renishaw .rtx file");
  expect_error("nodata.rtx", "HEADER::\r\nSample rate: 50000\r\n", "no 'Data:' line");
  expect_error("norate.rtx", "HEADER::\r\nOwner: x\r\nData:\r\n" + samples(),
               "no usable 'Actual sample rate' or 'Sample rate'");
  expect_error("badline.rtx", "HEADER::\r\nOwner x\r\nData:\r\n", "byte 10: header line 'Owner x'");
  EXPECT_THROW(RtxReader(std::filesystem::path("/nonexistent/x.rtx")), RtxError);
}

}  // namespace
