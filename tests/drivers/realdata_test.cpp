// The real recordings of ../shared/realdata (see its README.md: the sources, and what the
// project must get from each), read through the drivers' own decoders and codecs. Expected
// values are read from the files here with a parser of the test's own (split at '|' or
// whitespace), not with the codecs under test.
#include "../support/realdata.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "cal/drivers/registry.hpp"
#include "codec_test_util.hpp"
#include "halsampler/codec.hpp"

namespace {

namespace d = cal::drivers;
namespace fs = std::filesystem;

using cal::test::realdata;

std::string read(const std::string& name) { return cal::test::read_realdata(name); }

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) {
    while (!l.empty() && (l.back() == '\r' || l.back() == ' ')) l.pop_back();
    if (!l.empty()) out.push_back(l);
  }
  return out;
}

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> out;
  std::size_t start = 0;
  while (true) {
    const auto at = s.find(sep, start);
    out.push_back(s.substr(start, at == std::string::npos ? at : at - start));
    if (at == std::string::npos) return out;
    start = at + 1;
  }
}

std::vector<double> numbers_of(const std::string& line) {
  std::vector<double> out;
  std::istringstream in(line);
  for (double v; in >> v;) out.push_back(v);
  return out;
}

// Decodes a whole file line by line, as `daq decode` does.
std::vector<d::DecodedItem> decode(const std::string& driver, const std::string& text,
                                   std::vector<std::pair<std::string, std::string>> set,
                                   cal::drivers::codec::CodecStats* stats = nullptr) {
  const auto& drv = d::driver(driver);
  auto decoder = drv.make_decoder(d::options_from_text(drv, set));
  std::vector<d::DecodedItem> items;
  std::size_t at = 0;
  while (at < text.size()) {
    const auto eol = text.find('\n', at);
    const auto end = eol == std::string::npos ? text.size() : eol + 1;
    decoder->feed(std::as_bytes(std::span(text.data() + at, end - at)), items);
    at = end;
  }
  decoder->finish(items);
  if (stats) *stats = decoder->stats();
  return items;
}

std::size_t count(const std::vector<d::DecodedItem>& items, d::DecodedItem::Kind k) {
  return static_cast<std::size_t>(
      std::count_if(items.begin(), items.end(), [&](const auto& i) { return i.kind == k; }));
}

// "2022-08-08T13:51:34.7167146Z" as Unix ns, with timegm and the digits read here.
std::int64_t unix_ns(const std::string& ts) {
  std::tm tm{};
  int frac_start = 0;
  std::sscanf(ts.c_str(), "%4d-%2d-%2dT%2d:%2d:%2d.%n", &tm.tm_year, &tm.tm_mon, &tm.tm_mday,
              &tm.tm_hour, &tm.tm_min, &tm.tm_sec, &frac_start);
  tm.tm_year -= 1900;
  tm.tm_mon -= 1;
  std::int64_t ns = static_cast<std::int64_t>(timegm(&tm)) * 1'000'000'000;
  std::int64_t scale = 100'000'000;
  for (std::size_t i = static_cast<std::size_t>(frac_start); i < ts.size() && ts[i] != 'Z'; ++i) {
    ns += (ts[i] - '0') * scale;
    scale /= 10;
  }
  return ns;
}

TEST(RealData, TheRecordingsAreThere) {
  ASSERT_TRUE(fs::is_directory(realdata()))
      << realdata()
      << ": the real recordings are expected in ../shared/realdata beside the "
         "checkout (CI has ../shared/ there)";
  for (const char* f : {"shdr_okuma_osp_p300.txt", "halsampler_tagged_limit3.txt",
                        "halsampler_tagged_timedelay0.txt", "halsampler_untagged_near0.txt",
                        "halsampler_untagged_abs0.txt", "halsampler_untagged_biquad.txt",
                        "shdr_gf_agie_hpm600u_2015.txt", "shdr_handtmann482_840d_telnet.txt",
                        "halsampler_untagged_mux.txt", "halsampler_untagged_and_or_not_mux.txt",
                        "halsampler_tagged_limit_max_velocity.txt"})
    EXPECT_TRUE(fs::is_regular_file(realdata() / f)) << f;
}

// The readings of `keys` (X, Y, Z) expected from SHDR lines, read with the test's own split:
// each line's keys at key positions (1, 3, 5, ...), in axis order within a line.
struct ShdrExpected {
  std::int64_t time_ns;
  std::uint8_t axis;
  double value_m;
  std::string printed;  // the value as the file prints it (mm)
};
std::vector<ShdrExpected> shdr_expected(const std::vector<std::string>& lines,
                                        const std::vector<std::string>& keys,
                                        std::array<std::size_t, 3>& per_axis) {
  std::vector<ShdrExpected> expected;
  per_axis = {};
  for (const auto& line : lines) {
    if (line[0] == '*') continue;
    const auto tokens = split(line, '|');
    std::vector<ShdrExpected> of_line;
    for (std::size_t i = 1; i + 1 < tokens.size(); i += 2)
      for (std::uint8_t a = 0; a < keys.size(); ++a)
        if (tokens[i] == keys[a]) {
          of_line.push_back(
              {unix_ns(tokens[0]), a, std::stod(tokens[i + 1]) * 1e-3, tokens[i + 1]});
          ++per_axis[a];
        }
    std::sort(of_line.begin(), of_line.end(),
              [](const auto& x, const auto& y) { return x.axis < y.axis; });
    expected.insert(expected.end(), of_line.begin(), of_line.end());
  }
  return expected;
}

void expect_readings(const std::vector<d::DecodedItem>& items,
                     const std::vector<ShdrExpected>& expected) {
  std::vector<d::DecodedItem> readings;
  for (const auto& i : items)
    if (i.kind == d::DecodedItem::Kind::reading) readings.push_back(i);
  ASSERT_EQ(readings.size(), expected.size());
  for (std::size_t k = 0; k < readings.size(); ++k) {
    SCOPED_TRACE(k);
    ASSERT_TRUE(readings[k].device_time_unix_ns);
    EXPECT_EQ(*readings[k].device_time_unix_ns, expected[k].time_ns);
    EXPECT_EQ(readings[k].channel, expected[k].axis);
    EXPECT_EQ(readings[k].quantity, d::Quantity::machine_position_m);
    EXPECT_DOUBLE_EQ(readings[k].value, expected[k].value_m);
  }
}

// The Okuma recording's expected readings: lines outside the --multiline-- asset blocks and not
// '*' commands, with one of the keys at a key position (1, 3, 5, ...); `frames` counts the lines.
std::vector<ShdrExpected> okuma_expected(const std::string& text, std::size_t& frames) {
  const std::map<std::string, std::uint8_t> keys{{"X1actw", 0}, {"YI1actw", 1}, {"Z1actw", 2}};
  std::vector<ShdrExpected> expected;
  frames = 0;
  std::string terminator;
  for (const auto& line : lines_of(text)) {
    if (!terminator.empty()) {
      if (line == terminator) terminator.clear();
      continue;
    }
    if (const auto at = line.find("--multiline--"); at != std::string::npos) {
      terminator = line.substr(at);
      continue;
    }
    if (line[0] == '*') continue;
    const auto tokens = split(line, '|');
    std::vector<ShdrExpected> of_line;  // a frame's readings come X, Y, Z whatever the line's order
    for (std::size_t i = 1; i + 1 < tokens.size(); i += 2)
      if (const auto k = keys.find(tokens[i]); k != keys.end())
        of_line.push_back(
            {unix_ns(tokens[0]), k->second, std::stod(tokens[i + 1]) * 1e-3, tokens[i + 1]});
    std::sort(of_line.begin(), of_line.end(),
              [](const ShdrExpected& a, const ShdrExpected& b) { return a.axis < b.axis; });
    expected.insert(expected.end(), of_line.begin(), of_line.end());
    frames += !of_line.empty();
  }
  return expected;
}

TEST(RealData, OkumaShdrGivesItsPositionFramesWithTheFilesTimesAndValues) {
  // README: 3,989 position frames for X1actw, YI1actw, Z1actw, every one with the file's time
  // and value, no codec error.
  const std::string text = read("shdr_okuma_osp_p300.txt");
  std::size_t frames = 0;
  const auto expected = okuma_expected(text, frames);
  EXPECT_EQ(frames, 3989u);
  cal::drivers::codec::CodecStats stats;
  const auto items = decode("shdr", text, {{"keys", "X1actw,YI1actw,Z1actw"}}, &stats);
  EXPECT_EQ(count(items, d::DecodedItem::Kind::error), 0u);
  EXPECT_EQ(stats.errors(), 0u);
  EXPECT_EQ(stats.frames, 3989u);
  EXPECT_EQ(expected.size(), 4905u);  // 1330 X1actw + 607 YI1actw + 2968 Z1actw
  expect_readings(items, expected);
  // The '*' command lines ("*adapterVersion:UNAVAILABLE") and the assets are notes, not errors.
  EXPECT_GT(count(items, d::DecodedItem::Kind::note), 0u);
}

// Frames of a halsampler file through the codec (its sample numbers are in the frames).
std::vector<cal::drivers::codec::PositionFrame> halsampler(const std::string& name, bool tagged,
                                                           int column,
                                                           cal::drivers::codec::CodecStats& st) {
  cal::drivers::codec::HalsamplerCodec c({.sample_numbers = tagged, .column = {column, -1, -1}});
  std::vector<cal::drivers::codec::PositionFrame> frames;
  c.feed(read(name), frames);
  st = c.stats();
  return frames;
}

TEST(RealData, HalsamplerTaggedFilesGiveEverySampleInOrder) {
  // limit3: halsampler -t, cfg=f: 800 frames, samples 0..799, one float each.
  cal::drivers::codec::CodecStats st;
  const auto lines = lines_of(read("halsampler_tagged_limit3.txt"));
  const auto f = halsampler("halsampler_tagged_limit3.txt", true, 0, st);
  EXPECT_EQ(st.errors(), 0u);
  ASSERT_EQ(f.size(), 800u);
  ASSERT_EQ(lines.size(), 800u);
  for (std::size_t k = 0; k < f.size(); ++k) {
    ASSERT_TRUE(f[k].sample);
    EXPECT_EQ(*f[k].sample, k);
    EXPECT_EQ(f[k].lost_before, 0u);
    EXPECT_DOUBLE_EQ(*f[k].position_m[0], numbers_of(lines[k]).at(1) * 1e-3);
  }
  // timedelay.0: -t, cfg=bb: 64 frames of two bit pins.
  const auto t = halsampler("halsampler_tagged_timedelay0.txt", true, 1, st);
  EXPECT_EQ(st.errors(), 0u);
  ASSERT_EQ(t.size(), 64u);
  EXPECT_EQ(*t.front().sample, 0u);
  EXPECT_EQ(*t.back().sample, 63u);
}

TEST(RealData, HalsamplerUntaggedFilesReadEveryLineAndColumnZeroIsAPin) {
  // The default configuration is untagged, as halsampler's own default: through the decoder.
  const struct {
    const char* file;
    std::size_t lines;
    int column;
  } files[] = {{"halsampler_untagged_near0.txt", 122, 1},   // cfg=ffbb, four columns
               {"halsampler_untagged_abs0.txt", 7, 1},      // cfg=ff
               {"halsampler_untagged_biquad.txt", 10, 0}};  // cfg=bff: column 0 is a bit pin
  for (const auto& f : files) {
    SCOPED_TRACE(f.file);
    const std::string text = read(f.file);
    const auto lines = lines_of(text);
    ASSERT_EQ(lines.size(), f.lines);
    cal::drivers::codec::CodecStats stats;
    const auto items = decode("halsampler", text, {{"column", std::to_string(f.column)}}, &stats);
    EXPECT_EQ(stats.errors(), 0u);
    EXPECT_EQ(stats.frames, f.lines);
    ASSERT_EQ(count(items, d::DecodedItem::Kind::reading), f.lines);
    std::size_t k = 0;
    for (const auto& i : items) {
      if (i.kind != d::DecodedItem::Kind::reading) continue;
      EXPECT_DOUBLE_EQ(i.value, numbers_of(lines[k]).at(static_cast<std::size_t>(f.column)) * 1e-3);
      ++k;
    }
  }
  // biquad's column 0 is a bit: a value 0 or 1, never a sample number (the codec has none).
  cal::drivers::codec::CodecStats st;
  for (const auto& frame : halsampler("halsampler_untagged_biquad.txt", false, 0, st)) {
    EXPECT_FALSE(frame.sample);
    EXPECT_TRUE(*frame.position_m[0] == 0.0 || *frame.position_m[0] == 1e-3);
  }
}

TEST(RealData, GfAgieShdrGivesEveryPositionWithTheFilesTime) {
  // README: every Xposition, Yposition, Zposition value with the file's time (3,825 / 3,484 /
  // 2,288), no codec error. LF lines, 6-digit fractions, conditions, assets, a THREE_SPACE
  // path_pos (three numbers in one value: not a position item here).
  const std::string text = read("shdr_gf_agie_hpm600u_2015.txt");
  std::array<std::size_t, 3> per_axis{};
  const auto expected =
      shdr_expected(lines_of(text), {"Xposition", "Yposition", "Zposition"}, per_axis);
  EXPECT_EQ(per_axis, (std::array<std::size_t, 3>{3825, 3484, 2288}));
  cal::drivers::codec::CodecStats stats;
  const auto items = decode("shdr", text, {{"keys", "Xposition,Yposition,Zposition"}}, &stats);
  EXPECT_EQ(count(items, d::DecodedItem::Kind::error), 0u);
  EXPECT_EQ(stats.errors(), 0u);
  expect_readings(items, expected);
  // Pinned, not by the test's own split: the first reading is X 16.50304 mm at
  // 2015-10-27T17:38:06.715274Z (line 26), the last Z 20.3753 mm at 19:00:12.077232Z (line
  // 20,700).
  std::vector<d::DecodedItem> readings;
  for (const auto& i : items)
    if (i.kind == d::DecodedItem::Kind::reading) readings.push_back(i);
  ASSERT_EQ(readings.size(), 3825u + 3484u + 2288u);
  EXPECT_EQ(readings.front().channel, 0);
  EXPECT_DOUBLE_EQ(readings.front().value, 0.01650304);
  EXPECT_EQ(readings.front().device_time_unix_ns, 1'445'967'486'715'274'000);
  EXPECT_EQ(readings.back().channel, 2);
  EXPECT_DOUBLE_EQ(readings.back().value, 0.0203753);
  EXPECT_EQ(readings.back().device_time_unix_ns, 1'445'972'412'077'232'000);
}

TEST(RealData, HandtmannTelnetCaptureGivesTheActualPositionsOfItsFirstNineLines) {
  // README: CR LF lines, millisecond times without a zone (read as UTC, as the agent does), a
  // 1,438-byte line of ~90 items; only lines 1-9 are the adapter's bytes (the telnet console
  // wrapped the rest at 120 columns). X11_actual, Y11_actual, Z11_actual of lines 1-9.
  const std::string text = read("shdr_handtmann482_840d_telnet.txt");
  std::string first9;
  std::size_t at = 0;
  for (int k = 0; k < 9; ++k) at = text.find('\n', at) + 1;
  first9 = text.substr(0, at);
  ASSERT_NE(first9.find("\r\n"), std::string::npos);  // the capture's CR LF
  std::array<std::size_t, 3> per_axis{};
  const auto lines = lines_of(first9);
  ASSERT_EQ(lines.size(), 9u);
  EXPECT_EQ(std::max_element(lines.begin(), lines.end(),
                             [](const auto& a, const auto& b) { return a.size() < b.size(); })
                ->size(),
            1437u);  // 1,438 bytes with its CR
  const auto expected = shdr_expected(lines, {"X11_actual", "Y11_actual", "Z11_actual"}, per_axis);
  // Lines 1-9 carry 3 X11_actual, 2 Y11_actual and 4 Z11_actual (counted by hand).
  EXPECT_EQ(per_axis, (std::array<std::size_t, 3>{3, 2, 4}));
  cal::drivers::codec::CodecStats stats;
  const auto items = decode("shdr", first9, {{"keys", "X11_actual,Y11_actual,Z11_actual"}}, &stats);
  EXPECT_EQ(count(items, d::DecodedItem::Kind::error), 0u);
  EXPECT_EQ(stats.errors(), 0u);
  expect_readings(items, expected);
  // The first reading is the long line's X11_actual, 1536.595860 mm at 2018-02-12T20:12:27.378
  // (no zone: UTC, as the agent reads it); the last line 9's Z11_actual, 654.313830 mm at
  // 20:12:30.002. Pinned here, not by the test's own split.
  ASSERT_EQ(expected.size(), 9u);
  EXPECT_DOUBLE_EQ(expected.front().value_m, 1.536595860);
  EXPECT_EQ(expected.front().time_ns, 1'518'466'347'378'000'000);
  EXPECT_DOUBLE_EQ(expected.back().value_m, 0.654313830);
  EXPECT_EQ(expected.back().axis, 2);
  EXPECT_EQ(expected.back().time_ns, 1'518'466'350'002'000'000);
}

TEST(RealData, HalsamplerMuxAndAndOrNotMuxGiveTheConfiguredColumnOnEveryLine) {
  // mux: 20 pins of all four HAL types (cfg=bfsubfsubfsubfsubfbu), untagged: column 17 holds
  // 1.11 ... 5.55; every column reads as printed, 5000000000.001000 and 4294967295 included.
  // and-or-not-mux (cfg=bbbff): three bit pins first; column 3 and 4 the floats.
  const struct {
    const char* file;
    std::size_t lines;
    int columns;
  } files[] = {{"halsampler_untagged_mux.txt", 105, 20},
               {"halsampler_untagged_and_or_not_mux.txt", 16, 5}};
  for (const auto& f : files) {
    const std::string text = read(f.file);
    const auto lines = lines_of(text);
    ASSERT_EQ(lines.size(), f.lines) << f.file;
    for (int column = 0; column < f.columns; ++column) {
      SCOPED_TRACE(std::string(f.file) + " column " + std::to_string(column));
      cal::drivers::codec::CodecStats stats;
      const auto items = decode("halsampler", text, {{"column", std::to_string(column)}}, &stats);
      EXPECT_EQ(stats.errors(), 0u);
      ASSERT_EQ(count(items, d::DecodedItem::Kind::reading), f.lines);
      std::size_t k = 0;
      for (const auto& i : items) {
        if (i.kind != d::DecodedItem::Kind::reading) continue;
        EXPECT_DOUBLE_EQ(i.value, numbers_of(lines[k]).at(static_cast<std::size_t>(column)) * 1e-3);
        ++k;
      }
    }
  }
  cal::drivers::codec::CodecStats st;
  const auto mux = halsampler("halsampler_untagged_mux.txt", false, 17, st);
  ASSERT_EQ(mux.size(), 105u);
  std::set<double> seen;
  for (const auto& frame : mux) {
    EXPECT_FALSE(frame.sample);
    seen.insert(*frame.position_m[0] * 1e3);
  }
  EXPECT_EQ(seen.size(), 5u);
  EXPECT_DOUBLE_EQ(*seen.begin(), 1.11);
  EXPECT_DOUBLE_EQ(*seen.rbegin(), 5.55);
  // and-or-not-mux: no bit read as a sample number, no gap invented from the bits' jumps.
  for (const auto& frame : halsampler("halsampler_untagged_and_or_not_mux.txt", false, 0, st)) {
    EXPECT_FALSE(frame.sample);
    EXPECT_EQ(frame.lost_before, 0u);
  }
}

TEST(RealData, HalsamplerLimitMaxVelocityGivesSamples0To799WithNoGap) {
  // limit3/limit-max-velocity: halsampler -t, cfg=f: sample N, then 0.5 (N + 1).
  cal::drivers::codec::CodecStats st;
  const auto f = halsampler("halsampler_tagged_limit_max_velocity.txt", true, 0, st);
  EXPECT_EQ(st.errors(), 0u);
  ASSERT_EQ(f.size(), 800u);
  for (std::size_t k = 0; k < f.size(); ++k) {
    SCOPED_TRACE(k);
    ASSERT_TRUE(f[k].sample);
    EXPECT_EQ(*f[k].sample, k);
    EXPECT_EQ(f[k].lost_before, 0u);
    EXPECT_DOUBLE_EQ(*f[k].position_m[0], 0.5 * static_cast<double>(k + 1) * 1e-3);
  }
}

// ---- Every position as its printed decimal in metres, bit for bit ----
// The independent value: the file's own text with its exponent moved, read by strtod
// ("1039.897" mm is strtod("1039.897e-3")). Before, the drivers stored the printed double x
// 1e-3, one ulp off for a share of them (counted: the test would not see the change otherwise).

double printed_in_metres(const std::string& text) { return codec_test::strtod_shifted(text, -3); }
using codec_test::bits;

// Compares the readings of `items` with the printed decimals; returns how many the old
// product (the printed double x 1e-3) misses.
std::size_t expect_printed_decimals(const std::vector<d::DecodedItem>& items,
                                    const std::vector<ShdrExpected>& expected) {
  std::vector<double> values;
  for (const auto& i : items)
    if (i.kind == d::DecodedItem::Kind::reading) values.push_back(i.value);
  EXPECT_EQ(values.size(), expected.size());
  std::size_t product_missed = 0;
  for (std::size_t k = 0; k < std::min(values.size(), expected.size()); ++k) {
    const double want = printed_in_metres(expected[k].printed);
    EXPECT_EQ(bits(values[k]), bits(want))
        << "reading " << k << " '" << expected[k].printed << "': " << values[k];
    product_missed += std::stod(expected[k].printed) * 1e-3 != want;
  }
  return product_missed;
}

TEST(RealData, ShdrPositionsAreTheirPrintedDecimalsInMetresBitForBit) {
  std::size_t frames = 0;
  const std::string okuma = read("shdr_okuma_osp_p300.txt");
  const auto okuma_missed = expect_printed_decimals(
      decode("shdr", okuma, {{"keys", "X1actw,YI1actw,Z1actw"}}), okuma_expected(okuma, frames));
  std::array<std::size_t, 3> per_axis{};
  const std::string gf = read("shdr_gf_agie_hpm600u_2015.txt");
  const auto gf_missed = expect_printed_decimals(
      decode("shdr", gf, {{"keys", "Xposition,Yposition,Zposition"}}),
      shdr_expected(lines_of(gf), {"Xposition", "Yposition", "Zposition"}, per_axis));
  const std::string handtmann = read("shdr_handtmann482_840d_telnet.txt");
  std::size_t at = 0;
  for (int k = 0; k < 9; ++k) at = handtmann.find('\n', at) + 1;
  const std::string first9 = handtmann.substr(0, at);
  const auto handtmann_missed = expect_printed_decimals(
      decode("shdr", first9, {{"keys", "X11_actual,Y11_actual,Z11_actual"}}),
      shdr_expected(lines_of(first9), {"X11_actual", "Y11_actual", "Z11_actual"}, per_axis));
  // Of 4,905 Okuma and 9,597 GF Agie readings the product missed (counted when written):
  EXPECT_GT(okuma_missed, 100u);
  EXPECT_GT(gf_missed, 100u);
  RecordProperty("product_missed", std::to_string(okuma_missed) + " okuma, " +
                                       std::to_string(gf_missed) + " gf agie, " +
                                       std::to_string(handtmann_missed) + " handtmann");
}

TEST(RealData, HalsamplerValuesAreTheirPrintedDecimalsInMetresBitForBit) {
  // Every column of every recording (bit pins "0" and "1" too), through the driver's decoder.
  const struct {
    const char* file;
    bool tagged;
    int columns;
  } files[] = {{"halsampler_tagged_limit3.txt", true, 1},
               {"halsampler_tagged_limit_max_velocity.txt", true, 1},
               {"halsampler_tagged_timedelay0.txt", true, 2},
               {"halsampler_untagged_near0.txt", false, 4},
               {"halsampler_untagged_abs0.txt", false, 2},
               {"halsampler_untagged_biquad.txt", false, 3},
               {"halsampler_untagged_mux.txt", false, 20},
               {"halsampler_untagged_and_or_not_mux.txt", false, 5}};
  std::size_t product_missed = 0, values = 0;
  for (const auto& f : files) {
    const std::string text = read(f.file);
    const auto lines = lines_of(text);
    for (int column = 0; column < f.columns; ++column) {
      SCOPED_TRACE(std::string(f.file) + " column " + std::to_string(column));
      const auto items =
          decode("halsampler", text,
                 {{"column", std::to_string(column)}, {"tagged", f.tagged ? "true" : "false"}});
      std::size_t k = 0;
      for (const auto& i : items) {
        if (i.kind != d::DecodedItem::Kind::reading) continue;
        ASSERT_LT(k, lines.size());
        std::istringstream in(lines[k++]);
        std::string token;
        for (int c = 0; c <= column + (f.tagged ? 1 : 0); ++c) in >> token;
        const double want = printed_in_metres(token);
        EXPECT_EQ(bits(i.value), bits(want)) << "line " << k << " '" << token << "'";
        product_missed += std::stod(token) * 1e-3 != want;
        ++values;
      }
      EXPECT_EQ(k, lines.size());
    }
  }
  EXPECT_GT(product_missed, 0u);
  RecordProperty("values", std::to_string(values));
  RecordProperty("product_missed", std::to_string(product_missed));
}

}  // namespace
