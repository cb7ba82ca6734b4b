// TEMPer codec on reports written by hand from the layouts of OpenBSD's ugold(4) (see
// codec/temper.hpp); every expected temperature is worked out in the comment beside it.
#include <gtest/gtest.h>

#include "cal/analysis/error.hpp"
#include "codec_test_util.hpp"
#include "temper/codec.hpp"

namespace {

using namespace cal::drivers::codec;

std::string report(std::initializer_list<int> bytes) {
  std::string s;
  for (int b : bytes) s.push_back(static_cast<char>(b));
  s.resize(8, '\0');
  return s;
}

TEST(TemperCodec, GoldInnerOuterAndNegative) {
  // 0x092E = 2350 -> 23.50 degC (inner, id 80); 0xFE0C = -500 -> -5.00 degC (outer, id 01).
  const auto d =
      codec_test::feed_whole(TemperCodec({.family = TemperFamily::gold}),
                             report({0x80, 0x80, 0x09, 0x2E}) + report({0x80, 0x01, 0xFE, 0x0C}));
  ASSERT_EQ(d.frames.size(), 2u);
  EXPECT_EQ(d.frames[0].sensor, 0);
  EXPECT_DOUBLE_EQ(d.frames[0].temperature_degc, 23.50);
  EXPECT_EQ(d.frames[1].sensor, 1);
  EXPECT_DOUBLE_EQ(d.frames[1].temperature_degc, -5.00);
  EXPECT_FALSE(d.frames[0].humidity_pct);
  EXPECT_EQ(d.stats.errors(), 0u);
}

TEST(TemperCodec, GoldProbeMissingIsOutOfRangeNotATemperature) {
  // 0x4E20 = 20000 -> 200.00 degC: what TEMPer1F/TEMPer2 report without their probe.
  const auto d = codec_test::feed_whole(TemperCodec({.family = TemperFamily::gold}),
                                        report({0x80, 0x01, 0x4E, 0x20}));
  EXPECT_TRUE(d.frames.empty());
  ASSERT_EQ(d.errors.size(), 1u);
  EXPECT_EQ(d.errors[0].kind, ErrorKind::out_of_range);
  EXPECT_NE(d.errors[0].description.find("probe is missing"), std::string::npos);
}

TEST(TemperCodec, Ds75TwelveBitTwoSensors) {
  // Length 4: two sensors. 0x1780 = 6016 / 256 = 23.5 degC; 0xE840 = -6080 / 256 = -23.75 degC.
  // Length 2 with the low nibble set: 0x190F -> 0x1900 = 6400 / 256 = 25.0 degC (12 bits).
  const auto d = codec_test::feed_whole(
      TemperCodec({.family = TemperFamily::ds75}),
      report({0x80, 0x04, 0x17, 0x80, 0xE8, 0x40}) + report({0x80, 0x02, 0x19, 0x0F}));
  ASSERT_EQ(d.frames.size(), 3u);
  EXPECT_DOUBLE_EQ(d.frames[0].temperature_degc, 23.5);
  EXPECT_EQ(d.frames[1].sensor, 1);
  EXPECT_DOUBLE_EQ(d.frames[1].temperature_degc, -23.75);
  EXPECT_DOUBLE_EQ(d.frames[2].temperature_degc, 25.0);
}

TEST(TemperCodec, TemperxTemperatureAndHumidity) {
  // 0x08FC = 2300 -> 23.00 degC; 0x1194 = 4500 -> 45.00 %RH.
  const auto d = codec_test::feed_whole(TemperCodec({.family = TemperFamily::temperx}),
                                        report({0x80, 0x80, 0x08, 0xFC, 0x11, 0x94}));
  ASSERT_EQ(d.frames.size(), 1u);
  EXPECT_DOUBLE_EQ(d.frames[0].temperature_degc, 23.0);
  ASSERT_TRUE(d.frames[0].humidity_pct);
  EXPECT_DOUBLE_EQ(*d.frames[0].humidity_pct, 45.0);
  // 0x2AF8 = 11000 -> 110 %RH: impossible, refused.
  const auto bad = codec_test::feed_whole(TemperCodec({.family = TemperFamily::temperx}),
                                          report({0x80, 0x80, 0x08, 0xFC, 0x2A, 0xF8}));
  EXPECT_TRUE(bad.frames.empty());
  EXPECT_EQ(bad.stats.out_of_range, 1u);
}

TEST(TemperCodec, InitAndModelAnswersAreNotReadings) {
  TemperCodec c({.family = TemperFamily::gold});
  std::vector<TemperFrame> frames;
  std::vector<CodecError> errors;
  c.feed(report({0x82, 0x02}) + "TEMPerGo" + "ld_V3.1 ", frames, errors);
  EXPECT_TRUE(frames.empty());
  EXPECT_TRUE(errors.empty());
  EXPECT_EQ(c.sensor_count(), 2);
  EXPECT_EQ(c.model(), "TEMPerGold_V3.1 ");
  EXPECT_EQ(temper_family_of_model(c.model()), TemperFamily::gold);
  EXPECT_EQ(temper_family_of_model("TEMPer2_V4.1"), TemperFamily::gold);
  EXPECT_EQ(temper_family_of_model("TEMPerX_V3.3    "), TemperFamily::temperx);
  EXPECT_EQ(temper_family_of_model("TEMPer1F_V1.3"), TemperFamily::ds75);
  EXPECT_EQ(temper_family_of_model("Thermo"), std::nullopt);
}

TEST(TemperCodec, GarbageWrongIdsAndLengthsAreCountedAndTheNextReportIsRead) {
  const auto stream = report({0x07, 0x01, 0x02}) +        // control bytes: garbage
                      report({0x80, 0x33, 0x09, 0x2E}) +  // gold: sensor id 33 unknown
                      report({0x80, 0x80, 0x09, 0x2E});   // then a good one: 23.50
  const auto d = codec_test::feed_whole(TemperCodec({.family = TemperFamily::gold}), stream);
  EXPECT_EQ(d.stats.garbage, 1u);
  EXPECT_EQ(d.stats.malformed, 1u);
  ASSERT_EQ(d.frames.size(), 1u);
  EXPECT_DOUBLE_EQ(d.frames[0].temperature_degc, 23.5);
  EXPECT_EQ(d.errors[1].offset, 8u);  // the second report starts at byte 8
  const auto ds = codec_test::feed_whole(TemperCodec({.family = TemperFamily::ds75}),
                                         report({0x80, 0x03, 0x17, 0x80}));
  EXPECT_EQ(ds.stats.malformed, 1u);  // ds75 data length 3
}

TEST(TemperCodec, ReportsSplitAtAnyByteGiveTheSameFrames) {
  const auto stream = report({0x80, 0x80, 0x09, 0x2E}) + report({0x82, 0x01}) +
                      report({0x80, 0x01, 0xFE, 0x0C}) + report({0x80, 0x80, 0x4E, 0x20});
  const auto whole = codec_test::feed_whole(TemperCodec({.family = TemperFamily::gold}), stream);
  const auto bytewise =
      codec_test::feed_bytewise(TemperCodec({.family = TemperFamily::gold}), stream);
  ASSERT_EQ(whole.frames.size(), 2u);
  ASSERT_EQ(bytewise.frames.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i)
    EXPECT_EQ(whole.frames[i].temperature_degc, bytewise.frames[i].temperature_degc);
  EXPECT_EQ(whole.stats, bytewise.stats);
  for (std::uint32_t seed = 1; seed <= 20; ++seed)
    EXPECT_EQ(
        codec_test::feed_random_chunks(TemperCodec({.family = TemperFamily::gold}), stream, seed)
            .stats,
        whole.stats);
}

TEST(TemperCodec, CommandsAreTheDocumentedReports) {
  // hidapi's report ID 0 first, then 01 80 33 01 00 00 00 00.
  EXPECT_EQ(TemperCodec::read_command(), std::string("\x00\x01\x80\x33\x01\x00\x00\x00\x00", 9));
  EXPECT_EQ(TemperCodec::init_command(), std::string("\x00\x01\x82\x77\x01\x00\x00\x00\x00", 9));
  EXPECT_EQ(TemperCodec::model_command(), std::string("\x00\x01\x86\xff\x01\x00\x00\x00\x00", 9));
  EXPECT_THROW(temper_family_from_string("silver"), cal::InputError);
}

}  // namespace
