// The configurable line gauge codec: values in SI converted by hand, units printed or
// configured, a custom pattern, and every error kind counted, whatever the chunking.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "cal/analysis/error.hpp"
#include "cal/drivers/registry.hpp"
#include "codec_test_util.hpp"
#include "line_gauge/codec.hpp"

namespace {

using namespace cal::drivers::codec;

TEST(GaugeCodec, ConvertsPlainAndUnitLinesToMetres) {
  // +012.3456 mm = 0.0123456 m; -0.00125 mm = -1.25e-6 m; 12.5 um = 1.25e-5 m;
  // 0.5 in = 0.0127 m (1 in = 25.4 mm exactly).
  const std::string stream = "+012.3456\r\n-0.00125 mm\r\n12.5 um\r\n0.5 in\r\n";
  for (int mode = 0; mode < 3; ++mode) {
    const auto d = mode == 0   ? codec_test::feed_whole(GaugeCodec{}, stream)
                   : mode == 1 ? codec_test::feed_bytewise(GaugeCodec{}, stream)
                               : codec_test::feed_random_chunks(GaugeCodec{}, stream, 11);
    ASSERT_EQ(d.frames.size(), 4u) << mode;
    EXPECT_DOUBLE_EQ(d.frames[0].value_si, 0.0123456);
    EXPECT_DOUBLE_EQ(d.frames[1].value_si, -1.25e-6);
    EXPECT_DOUBLE_EQ(d.frames[2].value_si, 1.25e-5);
    EXPECT_DOUBLE_EQ(d.frames[3].value_si, 0.0127);
    EXPECT_EQ(d.frames[0].text, "+012.3456");
    EXPECT_EQ(d.stats.errors(), 0u);
  }
}

TEST(GaugeCodec, CustomPatternScaleAndTemperature) {
  // A thermometer printing "T=+020.125 C": degC, no length conversion.
  GaugeCodec t(
      {.pattern = R"(T=([+-]?[0-9.]+))", .unit = GaugeUnit::degc, .min_si = -40, .max_si = 150});
  std::vector<GaugeFrame> f;
  t.feed("T=+020.125 C\n", f);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_DOUBLE_EQ(f[0].value_si, 20.125);
  // A gauge counting 0.1 um steps: 12345 counts = 1234.5 um = 1.2345e-3 m.
  GaugeCodec c({.unit = GaugeUnit::um, .scale = 0.1});
  f.clear();
  c.feed("12345\n", f);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_DOUBLE_EQ(f[0].value_si, 1.2345e-3);
}

TEST(GaugeCodec, CountsEveryKindOfBadLineAndResynchronises) {
  GaugeCodec g({.min_si = -0.05, .max_si = 0.05, .max_line_bytes = 16});
  std::vector<GaugeFrame> f;
  std::vector<CodecError> e;
  // garbage (a NUL), malformed, an unknown unit, out of range (60 mm), over-long, then good.
  g.feed(std::string_view("+1.0\0\n", 6), f, e);
  g.feed("hello\n+1.0 furlong\n+60.0\n", f, e);
  g.feed("+0.000000000000000001\n+1.5\n", f, e);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_DOUBLE_EQ(f[0].value_si, 1.5e-3);
  EXPECT_EQ(g.stats().garbage, 1u);
  EXPECT_EQ(g.stats().malformed, 2u);
  EXPECT_EQ(g.stats().out_of_range, 1u);
  EXPECT_EQ(g.stats().overlong_line, 1u);
  ASSERT_EQ(e.size(), 5u);
  EXPECT_EQ(e[3].description, "gauge: value 60 outside [-0.05, 0.05]");
}

TEST(GaugeCodec, APrintedNumberBeyondTheDoublesRangeIsNoValueWhateverItsUnit) {
  // "1e309" is no double (DBL_MAX is 1.8e308), though 1e309 mm would be 1e306 m, which is one:
  // the line is refused as printed, even with a range that would take 1e306 m. 1e306 mm is
  // 1e303 m and read.
  GaugeCodec g({.min_si = -1e307, .max_si = 1e307});
  std::vector<GaugeFrame> f;
  std::vector<CodecError> e;
  g.feed("1e309 mm\n1e309\n-1e309 um\n1e306 mm\n", f, e);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_EQ(f[0].value_si, 1e303);
  EXPECT_EQ(g.stats().malformed, 3u);
  EXPECT_EQ(e.size(), 3u);
}

TEST(GaugeCodec, RefusesABadPattern) {
  EXPECT_THROW(GaugeCodec({.pattern = "([0-9"}), cal::InputError);
  EXPECT_THROW(GaugeCodec({.pattern = "[0-9]+"}), cal::InputError);  // no capture group
  EXPECT_EQ(gauge_unit_from_string("um"), GaugeUnit::um);
  EXPECT_THROW(gauge_unit_from_string("furlong"), cal::InputError);
}

// The readings (in SI) and error count of `bytes` through the registry's gauge decoder, as
// `daq decode gauge` reads them, configured with `options`.
struct Decoded {
  std::vector<double> values;
  std::size_t errors = 0;
};
Decoded decode_gauge(std::string_view bytes,
                     std::vector<std::pair<std::string, std::string>> options) {
  namespace dr = cal::drivers;
  const auto& gauge = dr::driver("gauge");
  auto decoder = gauge.make_decoder(dr::options_from_text(gauge, options));
  std::vector<dr::DecodedItem> items;
  decoder->feed(std::as_bytes(std::span(bytes.data(), bytes.size())), items);
  decoder->finish(items);
  Decoded out;
  for (const auto& i : items) {
    if (i.kind == dr::DecodedItem::Kind::reading) out.values.push_back(i.value);
    if (i.kind == dr::DecodedItem::Kind::error) ++out.errors;
  }
  return out;
}

TEST(GaugePresets, MitutoyoDigimaticLinesEndWithCrAndCarry01A) {
  // Mitutoyo manual 99MAF600B, USB data output: 0.123 (mm, 0.001) -> "01A+0000.123[CR]";
  // 0.1234 (inch, 0.0001) -> "01A+000.1234[CR]". CR only: each line still counts.
  auto d = decode_gauge("01A+0000.123\r01A-0012.500\r", {{"preset", "mitutoyo_digimatic"}});
  EXPECT_EQ(d.errors, 0u);
  ASSERT_EQ(d.values.size(), 2u);
  EXPECT_DOUBLE_EQ(d.values[0], 0.123e-3);
  EXPECT_DOUBLE_EQ(d.values[1], -12.5e-3);
  d = decode_gauge("01A+000.1234\r", {{"preset", "mitutoyo_digimatic"}, {"unit", "in"}});
  ASSERT_EQ(d.values.size(), 1u);
  EXPECT_DOUBLE_EQ(d.values[0], 0.1234 * 0.0254);
  // Without the preset the prefix is no number: the default pattern refuses the line.
  EXPECT_EQ(decode_gauge("01A+0000.123\r", {}).errors, 1u);
  // pytuyo (the USB-ITN reader) asks with "1" and CR.
  const auto* p = gauge_preset("mitutoyo_digimatic");
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->request, "1\r");
}

TEST(GaugePresets, SylvacLinesSignOrSpaceThenTheValueAndCr) {
  // Sylvac OPTO-RS: [sign ("+", "-" or space) | integer | "." | fraction | CR]; in tolerance
  // mode '<', '=' or '>' follows; errors are "ERR" and a number.
  const auto d = decode_gauge("+12.345\r-0.004\r 7.500\r12.345=\rERR3\r", {{"preset", "sylvac"}});
  ASSERT_EQ(d.values.size(), 4u);
  EXPECT_DOUBLE_EQ(d.values[0], 12.345e-3);
  EXPECT_DOUBLE_EQ(d.values[1], -0.004e-3);
  EXPECT_DOUBLE_EQ(d.values[2], 7.5e-3);
  EXPECT_DOUBLE_EQ(d.values[3], 12.345e-3);
  EXPECT_EQ(d.errors, 1u);  // ERR3: exceeded measurement range, an error, never a value
  EXPECT_EQ(gauge_preset("sylvac")->request, "?\r");
}

TEST(GaugePresets, MahrMillimarPrintsItsUnitAfterTheValue) {
  // Millimar C1208 OPTORSD: "?" CR -> "xxx.xxx<unit>" CR LF, the unit mm, in or um (UNI?).
  const auto d = decode_gauge("0.0123mm\r\n-1.5um\r\n0.5in\r\n", {{"preset", "mahr_millimar"}});
  EXPECT_EQ(d.errors, 0u);
  ASSERT_EQ(d.values.size(), 3u);
  EXPECT_DOUBLE_EQ(d.values[0], 0.0123e-3);
  EXPECT_DOUBLE_EQ(d.values[1], -1.5e-6);
  EXPECT_DOUBLE_EQ(d.values[2], 0.0127);
}

TEST(GaugePresets, EveryPresetReadsItsOwnDocumentedExampleAndAGivenKeyWins) {
  for (const auto& p : gauge_presets()) {
    SCOPED_TRACE(std::string(p.name));
    const auto d = decode_gauge(std::string(p.example) + "\r", {{"preset", std::string(p.name)}});
    ASSERT_EQ(d.values.size(), 1u);
    EXPECT_DOUBLE_EQ(d.values[0], p.example_mm * 1e-3);
    EXPECT_FALSE(p.source.empty());
  }
  // A pattern given with the preset is the user's: the preset's is not used (here it takes
  // the first fraction digit only).
  const auto d = decode_gauge("01A+0000.123\r",
                              {{"preset", "mitutoyo_digimatic"}, {"pattern", R"(\.([0-9]))"}});
  ASSERT_EQ(d.values.size(), 1u);
  EXPECT_DOUBLE_EQ(d.values[0], 1e-3);
  EXPECT_EQ(decode_gauge("+1.0\r", {{"preset", "mitutoyo_digimatic"}}).errors, 1u);
}

}  // namespace

namespace {

using codec_test::bits;
using codec_test::strtod_shifted;

TEST(GaugeCodec, ReadingsAreTheirPrintedDecimalsInSiBitForBit) {
  // 100.000123 mm is stored as 0.100000123 m (the literal: the correctly rounded double), not
  // as 100.000123 x 1e-3 = 0.10000012300000001, by every path: the instrument's fast path
  // (feed_values), frames, a printed unit word, a preset's pattern.
  {
    GaugeCodec g;
    std::vector<GaugeFrame> f;
    g.feed("+100.000123\n100.000123 mm\n-250.000001\n33.333333 mm\n", f);
    ASSERT_EQ(f.size(), 4u);
    EXPECT_EQ(f[0].value_si, 0.100000123);
    EXPECT_EQ(f[1].value_si, 0.100000123);
    EXPECT_EQ(f[2].value_si, -0.250000001);
    EXPECT_EQ(f[3].value_si, 0.033333333);
    GaugeCodec fast;
    std::vector<double> values;
    std::vector<CodecError> errors;
    fast.feed_values(
        as_bytes(std::string_view("+100.000123\n-250.000001\n")),
        [&](double si, std::string_view) { values.push_back(si); }, errors);
    EXPECT_EQ(values, (std::vector<double>{0.100000123, -0.250000001}));
  }
  // Random readings at 1 nm .. 0.1 um in each unit's form, against strtod of the moved text.
  std::mt19937_64 rng(29);
  std::uniform_int_distribution<std::int64_t> counts(-300'000'000, 300'000'000);
  std::uniform_int_distribution<int> decimals(3, 6);
  const GaugePreset* mahr = gauge_preset("mahr_millimar");
  ASSERT_NE(mahr, nullptr);
  GaugeCodec plain({.min_si = -1e3, .max_si = 1e3}),
      in_um({.unit = GaugeUnit::um, .min_si = -1e3, .max_si = 1e3}),
      preset({.pattern = std::string(mahr->pattern), .min_si = -1e3, .max_si = 1e3});
  std::size_t product_missed = 0, n = 0;
  char buf[64];
  for (int i = 0; i < 50'000; ++i) {
    const int k = decimals(rng);
    std::snprintf(buf, sizeof buf, "%+.*f", k,
                  static_cast<double>(counts(rng)) * std::pow(10.0, -k));
    const std::string text = buf;
    SCOPED_TRACE(text);
    const double mm = strtod_shifted(text, -3), um = strtod_shifted(text, -6);
    std::vector<GaugeFrame> f;
    std::vector<double> fast;
    std::vector<CodecError> errors;
    plain.feed(text + "\n" + text + " mm\n" + text + " um\n", f);
    plain.feed_values(
        as_bytes(std::string_view(text + "\n")),
        [&](double si, std::string_view) { fast.push_back(si); }, errors);
    in_um.feed(text + "\n", f);
    preset.feed(text + "mm\n" + text + "um\n", f);
    ASSERT_EQ(f.size(), 6u);
    ASSERT_EQ(fast.size(), 1u);
    EXPECT_EQ(bits(f[0].value_si), bits(mm));
    EXPECT_EQ(bits(fast[0]), bits(mm));
    EXPECT_EQ(bits(f[1].value_si), bits(mm));
    EXPECT_EQ(bits(f[2].value_si), bits(um));
    EXPECT_EQ(bits(f[3].value_si), bits(um));
    EXPECT_EQ(bits(f[4].value_si), bits(mm));
    EXPECT_EQ(bits(f[5].value_si), bits(um));
    if (::testing::Test::HasFailure()) break;
    ++n;
    product_missed += std::strtod(buf, nullptr) * 1e-3 != mm;
  }
  // The product the codec used to store misses a share of them (what this test is about).
  EXPECT_GT(product_missed, n / 20);
  // Inches: 1.2345 in = 1.2345 x 0.0254 m = 0.0313563 m exactly (12345 x 254 = 3135630).
  GaugeCodec inches({.unit = GaugeUnit::inch});
  std::vector<GaugeFrame> f;
  inches.feed("1.2345\n1.2345 in\n", f);
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f[0].value_si, 0.0313563);
  EXPECT_EQ(f[1].value_si, 0.0313563);
  // A scale or an offset makes a computed value, not the printed one: as before.
  GaugeCodec counts_01um({.unit = GaugeUnit::um, .scale = 0.1});
  f.clear();
  counts_01um.feed("12345\n", f);
  ASSERT_EQ(f.size(), 1u);
  EXPECT_EQ(f[0].value_si, 12345 * 0.1 * 1e-6);
}

TEST(GaugeCodec, TheGaugeDriverStoresThePrintedDecimalInSi) {
  // Through the registry's decoder, as `daq decode gauge` and a run read the lines.
  const auto items = codec_test::decode_whole("gauge", "+100.000123\r\n-250.000001\r\n");
  std::vector<double> values;
  for (const auto& i : items)
    if (i.kind == cal::drivers::DecodedItem::Kind::reading) values.push_back(i.value);
  EXPECT_EQ(values, (std::vector<double>{0.100000123, -0.250000001}));
}

}  // namespace
