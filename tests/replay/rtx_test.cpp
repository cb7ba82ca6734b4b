// Renishaw .rtx reader: files written here byte by byte in the publicly described layout
// (HEADER:: lines, Data:, little-endian float64 samples, EOF::), then damaged.
#include "cal/replay/rtx.hpp"

#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <fstream>
#include <tuple>

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
  std::string h = "HEADER::\nFile Type: Linear\nSample rate: 50000\nActual sample rate: 0\nData:\n";
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
  expect_error("norate.rtx", "HEADER::\r\nOwner: x\r\nFile Type: Linear\r\nData:\r\n" + samples(),
               "no usable 'Actual sample rate' or 'Sample rate'");
  expect_error("badline.rtx", "HEADER::\r\nOwner x\r\nData:\r\n", "byte 10: header line 'Owner x'");
  EXPECT_THROW(RtxReader(std::filesystem::path("/nonexistent/x.rtx")), RtxError);
}

// Issue 13: the end marker as real files have it. RTX2CSV-Converter (travdt, RTXFileProcessor.cs,
// EOFCheck) stops at the 8-byte sample whose bytes start 0D 0A 45 4F 46, i.e. the file ends
// "\r\nEOF::\r\n" where the next sample would start. A complete file gets no damage note.
TEST(Rtx, TheRealEndMarkerEndsACompleteFile) {
  const std::string bytes = kHeader + samples() + "\r\nEOF::\r\n";
  RtxReader r(bytes, "real.rtx");
  const auto& h = r.header();
  EXPECT_TRUE(h.eof_marker);
  EXPECT_EQ(h.eof_offset, kHeader.size() + 32);
  EXPECT_EQ(h.samples, 4u);
  EXPECT_EQ(h.trailing_bytes, 0u);  // before: "ends inside a sample (2 bytes dropped)"
  EXPECT_EQ(h.declared_samples, h.samples);
  EXPECT_EQ(all(r), (std::vector<double>{1.0, -2.5, 0.125, 1000.0}));
  EXPECT_EQ(h.kind, cal::replay::RtxKind::linear);
}

TEST(Rtx, AMarkerCutOrOffTheSampleGridIsDamage) {
  // Cut inside the marker: four whole samples and four bytes of the marker, no end.
  RtxReader cut(kHeader + samples() + "\r\nEO", "cut.rtx");
  EXPECT_FALSE(cut.header().eof_marker);
  EXPECT_EQ(cut.header().samples, 4u);
  EXPECT_EQ(cut.header().trailing_bytes, 4u);
  // One stray byte before the marker: the marker is not where a sample starts, but it runs to
  // the end of the file, so it is the end; the stray byte is a partial sample (damage). Read
  // as samples (before issue 27), "x\r\nEOF::\r" was a fifth sample of 4.95e27.
  RtxReader stray(kHeader + samples() + "x\r\nEOF::\r\n", "stray.rtx");
  EXPECT_TRUE(stray.header().eof_marker);
  EXPECT_EQ(stray.header().eof_offset, kHeader.size() + 33);
  EXPECT_EQ(stray.header().samples, 4u);
  EXPECT_EQ(stray.header().trailing_bytes, 1u);
  EXPECT_EQ(all(stray), (std::vector<double>{1.0, -2.5, 0.125, 1000.0}));
}

TEST(Rtx, AHeaderThatIsNotUtf8IsRefusedOrReadAsWindows1252) {
  const std::string header = "HEADER::\r\nFile Type: Linear\r\nActual sample rate: 1000\r\n"
                             "By: M\xFCller\r\nData:\r\n";
  try {
    RtxReader(header + samples() + "\r\nEOF::\r\n", "w.rtx");
    FAIL() << "accepted";
  } catch (const RtxError& e) {
    EXPECT_NE(std::string(e.what()).find("w.rtx: line 4, byte 60: the header is not UTF-8 text"),
              std::string::npos)
        << e.what();
  }
  RtxReader r(header + samples() + "\r\nEOF::\r\n", "w.rtx",
              cal::replay::RtxHeaderEncoding::windows1252);
  EXPECT_EQ(*r.header().find("By"), "M\xC3\xBCller");
}

TEST(Rtx, TheFileTypeDecidesWhatTheSamplesAre) {
  auto with_type = [](const std::string& type) {
    std::string h = kHeader;
    h.replace(h.find("File Type: Linear"), 17, "File Type: " + type);
    return h + samples() + "\r\nEOF::\r\n";
  };
  EXPECT_EQ(RtxReader(with_type("Angular"), "a.rtx").header().kind, cal::replay::RtxKind::angular);
  EXPECT_EQ(RtxReader(with_type("LINEAR"), "l.rtx").header().kind, cal::replay::RtxKind::linear);
  for (const std::string type : {"Straightness", "Flatness", "Rotary", "Linear2", "csv"}) {
    try {
      RtxReader r(with_type(type), "t.rtx");
      FAIL() << type << " was accepted";
    } catch (const RtxError& e) {
      EXPECT_NE(std::string(e.what()).find("File Type '" + type + "' is not supported"),
                std::string::npos)
          << e.what();
    }
  }
  std::string none = kHeader;
  none.erase(none.find("File Type: Linear\r\n"), 19);
  EXPECT_THROW(RtxReader(none + samples(), "none.rtx"), RtxError);
}

// Issue 15: nonsense header values are refused with the field and the value, never stored
// (an infinite or 1e-300 Hz rate put every sample at time 0 or INT64_MIN; Sample no 1e300 was
// undefined behaviour in the conversion to an integer).
TEST(Rtx, RefusesNonsenseHeaderValues) {
  auto with = [](std::string h, const std::string& field, const std::string& value) {
    const auto at = h.find(field + ": ");
    const auto eol = h.find("\r\n", at);
    h.replace(at, eol - at, field + ": " + value);
    return h;
  };
  const std::vector<std::tuple<std::string, std::string, std::string>> cases{
      {"Actual sample rate", "inf", "Actual sample rate 'inf' is not a rate within"},
      {"Actual sample rate", "1e-300", "Actual sample rate '1e-300' is not a rate within"},
      {"Actual sample rate", "nan", "Actual sample rate 'nan' is not a rate within"},
      {"Actual sample rate", "-50000", "Actual sample rate '-50000' is not a rate within"},
      {"Actual sample rate", "fast", "Actual sample rate 'fast' is not a rate within"},
      {"Sample rate", "1e308", "Sample rate '1e308' is not a rate within"},
      {"Sample no", "1e300", "Sample no '1e300' is not a whole number of samples"},
      {"Sample no", "-4", "Sample no '-4' is not a whole number of samples"},
      {"Sample no", "3.5", "Sample no '3.5' is not a whole number of samples"},
      {"Sample no", "nan", "Sample no 'nan' is not a whole number of samples"}};
  for (const auto& [field, value, what] : cases) {
    std::string h = with(kHeader, field, value);
    // The nominal rate is only read when the actual rate is not stated (0).
    if (field == "Sample rate") h = with(h, "Actual sample rate", "0");
    const std::string bytes = h + samples() + "\r\nEOF::\r\n";
    try {
      RtxReader r(bytes, "nonsense.rtx");
      FAIL() << field << ": " << value << " was accepted";
    } catch (const RtxError& e) {
      EXPECT_NE(std::string(e.what()).find("nonsense.rtx: header: " + what), std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
