// The configurable line gauge codec: values in SI converted by hand, units printed or
// configured, a custom pattern, and every error kind counted, whatever the chunking.
#include <gtest/gtest.h>

#include "cal/analysis/error.hpp"
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

TEST(GaugeCodec, RefusesABadPattern) {
  EXPECT_THROW(GaugeCodec({.pattern = "([0-9"}), cal::InputError);
  EXPECT_THROW(GaugeCodec({.pattern = "[0-9]+"}), cal::InputError);  // no capture group
  EXPECT_EQ(gauge_unit_from_string("um"), GaugeUnit::um);
  EXPECT_THROW(gauge_unit_from_string("furlong"), cal::InputError);
}

}  // namespace
