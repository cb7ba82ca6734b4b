// TEMPer codec on reports written by hand from the layouts of OpenBSD's ugold(4) (see
// temper/codec.hpp); every expected temperature is worked out in the comment beside it.
#include <gtest/gtest.h>

#include "../support/temper_report.hpp"
#include "cal/analysis/error.hpp"
#include "cal/drivers/registry.hpp"
#include "codec_test_util.hpp"
#include "temper/codec.hpp"

namespace {

using namespace cal::drivers::codec;

using cal::test::temper_report;

TEST(TemperCodec, GoldInnerOuterAndNegative) {
  // 0x092E = 2350 -> 23.50 degC (inner, id 80); 0xFE0C = -500 -> -5.00 degC (outer, id 01).
  const auto d = codec_test::feed_whole(
      TemperCodec({.family = TemperFamily::gold}),
      temper_report({0x80, 0x80, 0x09, 0x2E}) + temper_report({0x80, 0x01, 0xFE, 0x0C}));
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
                                        temper_report({0x80, 0x01, 0x4E, 0x20}));
  EXPECT_TRUE(d.frames.empty());
  ASSERT_EQ(d.errors.size(), 1u);
  EXPECT_EQ(d.errors[0].kind, ErrorKind::out_of_range);
  EXPECT_NE(d.errors[0].description.find("probe is missing"), std::string::npos);
}

TEST(TemperCodec, Ds75TwelveBitTwoSensors) {
  // Length 4: two sensors. 0x1780 = 6016 / 256 = 23.5 degC; 0xE840 = -6080 / 256 = -23.75 degC.
  // Length 2: 0x1900 = 6400 / 256 = 25.0 degC (12 bits).
  const auto d = codec_test::feed_whole(TemperCodec({.family = TemperFamily::ds75}),
                                        temper_report({0x80, 0x04, 0x17, 0x80, 0xE8, 0x40}) +
                                            temper_report({0x80, 0x02, 0x19, 0x00}));
  ASSERT_EQ(d.frames.size(), 3u);
  EXPECT_DOUBLE_EQ(d.frames[0].temperature_degc, 23.5);
  EXPECT_EQ(d.frames[1].sensor, 1);
  EXPECT_DOUBLE_EQ(d.frames[1].temperature_degc, -23.75);
  EXPECT_DOUBLE_EQ(d.frames[2].temperature_degc, 25.0);
}

TEST(TemperCodec, Ds75RegistersThatCannotOccurAreNotTemperatures) {
  // Issue 26: a TEMPer1F_V1.3 whose probe does not answer sends 80 04 ff ff ff ff 00 00
  // (edorfaus/TEMPered#32). Masked to 0xFFF0 that was -16 / 256 = -0.0625 degC, a valid-looking
  // material temperature ~20 K off. A DS75 register's low nibble is always 0, so 0x190F is no
  // reading either. Neither may become a frame; each is an error with its reason.
  TemperConfig v13{
      .family = TemperFamily::ds75, .inner = false, .probe = true, .ds75_slots = {-1, 1}};
  const auto a =
      codec_test::feed_whole(TemperCodec(v13), temper_report({0x80, 0x04, 0xff, 0xff, 0xff, 0xff}));
  EXPECT_TRUE(a.frames.empty());
  ASSERT_EQ(a.errors.size(), 1u);
  EXPECT_NE(a.errors[0].description.find("did not answer"), std::string::npos);
  const auto b = codec_test::feed_whole(TemperCodec({.family = TemperFamily::ds75}),
                                        temper_report({0x80, 0x02, 0x19, 0x0F}));
  EXPECT_TRUE(b.frames.empty());
  ASSERT_EQ(b.errors.size(), 1u);
  EXPECT_NE(b.errors[0].description.find("19 0f cannot come from a DS75"), std::string::npos);
}

TEST(TemperCodec, TemperxTemperatureAndHumidity) {
  // 0x08FC = 2300 -> 23.00 degC; 0x1194 = 4500 -> 45.00 %RH.
  const auto d = codec_test::feed_whole(TemperCodec({.family = TemperFamily::temperx}),
                                        temper_report({0x80, 0x80, 0x08, 0xFC, 0x11, 0x94}));
  ASSERT_EQ(d.frames.size(), 1u);
  EXPECT_DOUBLE_EQ(d.frames[0].temperature_degc, 23.0);
  ASSERT_TRUE(d.frames[0].humidity_pct);
  EXPECT_DOUBLE_EQ(*d.frames[0].humidity_pct, 45.0);
  // 0x2AF8 = 11000 -> 110 %RH: impossible, refused.
  const auto bad = codec_test::feed_whole(TemperCodec({.family = TemperFamily::temperx}),
                                          temper_report({0x80, 0x80, 0x08, 0xFC, 0x2A, 0xF8}));
  EXPECT_TRUE(bad.frames.empty());
  EXPECT_EQ(bad.stats.out_of_range, 1u);
}

TEST(TemperCodec, InitAndModelAnswersAreNotReadings) {
  TemperCodec c({.family = TemperFamily::gold});
  std::vector<TemperFrame> frames;
  std::vector<CodecError> errors;
  c.feed(temper_report({0x82, 0x02}) + "TEMPerGo" + "ld_V3.1 ", frames, errors);
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
  const auto stream = temper_report({0x07, 0x01, 0x02}) +        // control bytes: garbage
                      temper_report({0x80, 0x33, 0x09, 0x2E}) +  // gold: sensor id 33 unknown
                      temper_report({0x80, 0x80, 0x09, 0x2E});   // then a good one: 23.50
  const auto d = codec_test::feed_whole(TemperCodec({.family = TemperFamily::gold}), stream);
  EXPECT_EQ(d.stats.garbage, 1u);
  EXPECT_EQ(d.stats.malformed, 1u);
  ASSERT_EQ(d.frames.size(), 1u);
  EXPECT_DOUBLE_EQ(d.frames[0].temperature_degc, 23.5);
  EXPECT_EQ(d.errors[1].offset, 8u);  // the second report starts at byte 8
  const auto ds = codec_test::feed_whole(TemperCodec({.family = TemperFamily::ds75}),
                                         temper_report({0x80, 0x03, 0x17, 0x80}));
  EXPECT_EQ(ds.stats.malformed, 1u);  // ds75 data length 3
}

TEST(TemperCodec, ReportsSplitAtAnyByteGiveTheSameFrames) {
  const auto stream = temper_report({0x80, 0x80, 0x09, 0x2E}) + temper_report({0x82, 0x01}) +
                      temper_report({0x80, 0x01, 0xFE, 0x0C}) +
                      temper_report({0x80, 0x80, 0x4E, 0x20});
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

TEST(TemperModels, DetectedFromTheFirmwareStringsThePublicProjectsShow) {
  // Firmware strings as the projects print them (with their padding), and what they say:
  struct Case {
    std::string firmware;
    TemperFamily family;
    bool inner, probe, humidity;
  };
  const Case cases[] = {
      // OpenBSD ugold.c: "TEMPerGold_" + "V3.5 "; ccwienk/temper lists it on 3553:a001.
      {"TEMPerGold_V3.5 ", TemperFamily::gold, true, false, false},
      // urwen/temper: TEMPer2_V3.7, inner at offset 2, external at 10 (the second report).
      {"TEMPer2_V3.7    ", TemperFamily::gold, true, true, false},
      // ugold.c: "TEMPer2_V4.1\0\0\0\0" and "TEMPer1F_V4.1\0\0\0" (TEMPer1F: no inner sensor).
      {std::string("TEMPer2_V4.1\0\0\0\0", 16), TemperFamily::gold, true, true, false},
      {std::string("TEMPer1F_V4.1\0\0\0", 16), TemperFamily::gold, false, true, false},
      // ccwienk/temper: TEMPer1F_V3.9, one value, the external probe (README: "E").
      {"TEMPer1F_V3.9 ", TemperFamily::gold, false, true, false},
      // padelt/temper-python 1.5.1: TEMPer1F_V1.3 "has only 1 sensor at offset 4".
      {"TEMPer1F_V1.3", TemperFamily::ds75, false, true, false},
      // urwen/temper: TEMPer1F_H1V1.5F, temperature and humidity with SHT2x equations.
      {"TEMPer1F_H1V1.5F", TemperFamily::sht2x, true, false, true},
      // ugold.c: "TEMPerX_" + "V3.3    " and "TEMPerHUM" + "_V3.9  ": temperx.
      // urwen/temper PR #16: a TEMPer1F on TEMPerX_V3.3 sends its probe (id 01), so the
      // firmware allows one (a TEMPerX stick of that firmware never sends 01).
      {"TEMPerX_V3.3    ", TemperFamily::temperx, true, true, true},
      // ccwienk/temper PR #45 (urwen/temper #29, #34): "TEMPerHUM_V3.8  ", as V3.9.
      {"TEMPerHUM_V3.8  ", TemperFamily::temperx, true, false, true},
      {"TEMPerHUM_V3.9  ", TemperFamily::temperx, true, false, true},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.firmware);
    const auto* m = temper_model_of(c.firmware);
    ASSERT_NE(m, nullptr);
    EXPECT_EQ(m->family, c.family);
    EXPECT_EQ(m->inner, c.inner);
    EXPECT_EQ(m->probe, c.probe);
    EXPECT_EQ(m->humidity, c.humidity);
    EXPECT_FALSE(m->source.empty());
  }
  // Unknown firmware is refused, never guessed: a serial TEMPerX232, a made-up one.
  EXPECT_EQ(temper_model_of("TEMPerX232_V2.0"), nullptr);
  EXPECT_EQ(temper_model_of("TEMPerGold_V9.9"), nullptr);
  EXPECT_EQ(temper_model_of(""), nullptr);
}

TEST(TemperModels, OnlyTheVersionsTheSourcesNameAreDetected) {
  // ugold.c reads "TEMPer1F*", "TEMPer2F*", "TEMPerF1*" as DS75 only on Microdia 0c45:7401; no
  // source names these strings, so they are refused rather than read with a phantom sensor.
  EXPECT_EQ(temper_model_of("TEMPer1F_V9.9"), nullptr);
  EXPECT_EQ(temper_model_of("TEMPer2F_V1.0"), nullptr);
  EXPECT_EQ(temper_model_of("TEMPerF1.9"), nullptr);
  // ugold.c lists TEMPerGold V3.1, V3.4, V3.5 and urwen/temper V3.1, V3.3, V3.4: not V3.2 or V3.9.
  EXPECT_EQ(temper_model_of("TEMPerGold_V3.2 "), nullptr);
  EXPECT_EQ(temper_model_of("TEMPerGold_V3.9 "), nullptr);
  for (const char* fw : {"TEMPerGold_V3.1 ", "TEMPerGold_V3.3 ", "TEMPerGold_V3.4 "}) {
    SCOPED_TRACE(fw);
    ASSERT_NE(temper_model_of(fw), nullptr);
    EXPECT_EQ(temper_model_of(fw)->family, TemperFamily::gold);
  }
  // urwen/temper's documented DS75 strings stay: TEMPerF1.2/1.4 the stick only, TEMPer1F1.1
  // (the ugold.c comment's 'TEMPer1F' + '1.1Per1F') the probe only, as the first value.
  ASSERT_NE(temper_model_of("TEMPerF1.4"), nullptr);
  EXPECT_FALSE(temper_model_of("TEMPerF1.4")->probe);
  const auto* f11 = temper_model_of("TEMPer1F1.1Per1F");
  ASSERT_NE(f11, nullptr);
  EXPECT_FALSE(f11->inner);
  EXPECT_EQ(f11->ds75_slots[0], 1);
}

TEST(TemperCodec, AProbeOnlyModelGivesNoPhantomInnerSensor) {
  // TEMPer1F_V1.3 (ds75): the one sensor is the second value; 0x0B40 = 2880 -> 11.25 degC.
  TemperConfig v13{
      .family = TemperFamily::ds75, .inner = false, .probe = true, .ds75_slots = {-1, 1}};
  const auto a =
      codec_test::feed_whole(TemperCodec(v13), temper_report({0x80, 0x04, 0x17, 0x00, 0x0B, 0x40}));
  ASSERT_EQ(a.frames.size(), 1u);
  EXPECT_EQ(a.frames[0].sensor, 1);
  EXPECT_DOUBLE_EQ(a.frames[0].temperature_degc, 11.25);
  // TEMPer1F_V3.9 (gold, probe only): 0x09C4 = 2500 -> 25.00 degC on channel 1; a report of an
  // inner sensor it does not have is malformed, not a reading.
  TemperConfig v39{.family = TemperFamily::gold, .inner = false, .probe = true};
  const auto b =
      codec_test::feed_whole(TemperCodec(v39), temper_report({0x80, 0x01, 0x09, 0xC4}) +
                                                   temper_report({0x80, 0x80, 0x08, 0x00}));
  ASSERT_EQ(b.frames.size(), 1u);
  EXPECT_EQ(b.frames[0].sensor, 1);
  EXPECT_DOUBLE_EQ(b.frames[0].temperature_degc, 25.0);
  EXPECT_EQ(b.stats.malformed, 1u);
}

TEST(TemperCodec, Sht2xSi7005AndSi7006Equations) {
  // sht2x (urwen/temper): t = 6700: -46.85 + 175.72 * 26800 / 65536 = 25.00815 degC;
  // h = 1835: -6 + 125 * 29360 / 65536 = 49.99976 %RH.
  const auto s = codec_test::feed_whole(TemperCodec({.family = TemperFamily::sht2x}),
                                        temper_report({0x80, 0x80, 0x1A, 0x2C, 0x07, 0x2B}));
  ASSERT_EQ(s.frames.size(), 1u);
  EXPECT_NEAR(s.frames[0].temperature_degc, 25.00815, 1e-5);
  EXPECT_NEAR(*s.frames[0].humidity_pct, 49.99976, 1e-5);
  // si7005 (OpenBSD ugold): t = 0x0960 = 2400: 2400 / 32 - 50 = 25 degC; h = 0x0480 = 1152:
  // 1152 / 16 - 24 = 48 %RH.
  const auto a = codec_test::feed_whole(TemperCodec({.family = TemperFamily::si7005}),
                                        temper_report({0x80, 0x80, 0x09, 0x60, 0x04, 0x80}));
  ASSERT_EQ(a.frames.size(), 1u);
  EXPECT_DOUBLE_EQ(a.frames[0].temperature_degc, 25.0);
  EXPECT_DOUBLE_EQ(*a.frames[0].humidity_pct, 48.0);
  // si7006 (ugold): t = 0x6A02 (status bits 02 cleared -> 27136): 27136 * 175.72 / 65536 -
  // 46.85 = 25.90906 degC; h = 0x7000 = 28672: 28672 * 125 / 65536 - 6 = 48.6875 %RH.
  const auto b = codec_test::feed_whole(TemperCodec({.family = TemperFamily::si7006}),
                                        temper_report({0x80, 0x80, 0x6A, 0x02, 0x70, 0x00}));
  ASSERT_EQ(b.frames.size(), 1u);
  EXPECT_NEAR(b.frames[0].temperature_degc, 25.90906, 1e-5);
  EXPECT_DOUBLE_EQ(*b.frames[0].humidity_pct, 48.6875);
  EXPECT_EQ(temper_family_from_string("sht2x"), TemperFamily::sht2x);
}

// `daq decode temper` on a text of hex reports (one per line), as the command feeds it.
std::vector<cal::drivers::DecodedItem> decode_temper(const std::string& text) {
  return codec_test::decode_whole("temper", text);
}

std::vector<cal::drivers::DecodedItem> of_kind(const std::vector<cal::drivers::DecodedItem>& all,
                                               cal::drivers::DecodedItem::Kind kind) {
  std::vector<cal::drivers::DecodedItem> out;
  for (const auto& i : all)
    if (i.kind == kind) out.push_back(i);
  return out;
}

TEST(TemperModels, ATemper1FOnTemperXV33FirmwareIsReadAsItsProbe) {
  // urwen/temper PR #16's usbmon trace (TEMPer1F, 413d:2107, firmware "TEMPerX_" "V3.3    "):
  // data 80 01 08 dc 4e 20 00 00: 0x08DC = 2268 -> 22.68 degC on the probe; 4e 20 (200.00) is
  // the filler where a stick has humidity, never a humidity. The same PR's title shows
  // 80 01 08 98 4e 20: 0x0898 = 2200 -> 22.00 degC.
  const auto* m = temper_model_of("TEMPerX_V3.3    ");
  ASSERT_NE(m, nullptr);
  const auto d = codec_test::feed_whole(
      TemperCodec({.family = m->family, .inner = m->inner, .probe = m->probe}),
      temper_report({0x80, 0x01, 0x08, 0xDC, 0x4E, 0x20}) +
          temper_report({0x80, 0x01, 0x08, 0x98, 0x4E, 0x20}));
  ASSERT_EQ(d.frames.size(), 2u);
  for (const auto& f : d.frames) {
    EXPECT_EQ(f.sensor, 1);
    EXPECT_FALSE(f.humidity_pct);
  }
  EXPECT_DOUBLE_EQ(d.frames[0].temperature_degc, 22.68);
  EXPECT_DOUBLE_EQ(d.frames[1].temperature_degc, 22.0);
  EXPECT_EQ(d.stats.malformed, 0u);

  // The same through `daq decode temper`: one reading, channel 1, no error.
  const auto items = decode_temper("firmware: TEMPerX_V3.3    \n80 01 08 dc 4e 20 00 00\n");
  const auto readings = of_kind(items, cal::drivers::DecodedItem::Kind::reading);
  EXPECT_TRUE(of_kind(items, cal::drivers::DecodedItem::Kind::error).empty());
  ASSERT_EQ(readings.size(), 1u);
  EXPECT_EQ(readings[0].channel, 1);
  EXPECT_DOUBLE_EQ(readings[0].value, 22.68);

  // A probe report on a temperx model without a probe (TEMPerX_V3.1) stays malformed.
  const auto* x31 = temper_model_of("TEMPerX_V3.1    ");
  ASSERT_NE(x31, nullptr);
  const auto none = codec_test::feed_whole(
      TemperCodec({.family = x31->family, .inner = x31->inner, .probe = x31->probe}),
      temper_report({0x80, 0x01, 0x08, 0xDC, 0x4E, 0x20}));
  EXPECT_TRUE(none.frames.empty());
  EXPECT_EQ(none.stats.malformed, 1u);
}

TEST(TemperModels, TemperHumV38IsReadAsV39AndAnUnknownVersionIsRefusedByName) {
  // ccwienk/temper PR #45's verbose output: firmware 54454d50657248554d5f56332e382020
  // ("TEMPerHUM_V3.8  "), data 80 20 09 01 11 93: 0x0901 = 2305 -> 23.05 degC, 0x1193 = 4499
  // -> 44.99 %RH.
  const auto items = decode_temper("firmware: TEMPerHUM_V3.8  \n80 20 09 01 11 93 00 00\n");
  EXPECT_TRUE(of_kind(items, cal::drivers::DecodedItem::Kind::error).empty());
  const auto readings = of_kind(items, cal::drivers::DecodedItem::Kind::reading);
  ASSERT_EQ(readings.size(), 2u);
  EXPECT_DOUBLE_EQ(readings[0].value, 23.05);
  EXPECT_EQ(readings[1].quantity, cal::drivers::Quantity::air_humidity_pct);
  EXPECT_DOUBLE_EQ(readings[1].value, 44.99);

  // A version no source shows is still refused, naming it.
  EXPECT_EQ(temper_model_of("TEMPerHUM_V3.7  "), nullptr);
  const auto refused = decode_temper("firmware: TEMPerHUM_V3.7  \n80 20 09 01 11 93 00 00\n");
  EXPECT_TRUE(of_kind(refused, cal::drivers::DecodedItem::Kind::reading).empty());
  const auto errors = of_kind(refused, cal::drivers::DecodedItem::Kind::error);
  ASSERT_FALSE(errors.empty());
  EXPECT_NE(errors[0].text.find("TEMPer firmware 'TEMPerHUM_V3.7  ' is not in the detection table"),
            std::string::npos)
      << errors[0].text;
}

}  // namespace
