// Vaisala PTU300 codec: output lines as the User's Guide prints them, custom FORM lines with
// other units, the CS2/CS4/CSX checksums worked out by hand, and every bad line.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>

#include "cal/analysis/error.hpp"
#include "codec_test_util.hpp"
#include "ptu300/codec.hpp"

namespace {

using namespace cal::drivers::codec;

TEST(Ptu300Codec, TheManualsDefaultLine) {
  // 1033.7 hPa = 103370 Pa.
  const auto d = codec_test::feed_whole(Ptu300Codec{}, "P= 1033.7 hPa T= 22.2 'C RH= 38.3 %RH\r\n");
  ASSERT_EQ(d.frames.size(), 1u);
  EXPECT_DOUBLE_EQ(*d.frames[0].pressure_pa, 103370.0);
  EXPECT_DOUBLE_EQ(*d.frames[0].temperature_degc, 22.2);
  EXPECT_DOUBLE_EQ(*d.frames[0].relative_humidity_pct, 38.3);
  ASSERT_EQ(d.frames[0].fields.size(), 3u);
  EXPECT_EQ(d.frames[0].fields[0].label, "P");
  EXPECT_EQ(d.frames[0].fields[0].unit, "hPa");
  EXPECT_EQ(d.stats.errors(), 0u);
}

TEST(Ptu300Codec, OtherUnitsAndNoSpaces) {
  // "RH= 14.98%RH T= 74.68'F" (the manual's FORM example): (74.68 - 32) x 5/9 = 23.7111 degC.
  // 29.92 inHg x 3386.389 Pa/inHg = 101320.76 Pa; 101.3 kPa = 101300 Pa; TD 50 'F = 10 degC.
  const auto d = codec_test::feed_whole(Ptu300Codec{},
                                        "RH= 14.98%RH T= 74.68'F\r\n"
                                        "P= 29.92 inHg\r\n"
                                        "P= 101.3 kPa TD= 50.0 'F\r\n");
  ASSERT_EQ(d.frames.size(), 3u);
  EXPECT_DOUBLE_EQ(*d.frames[0].relative_humidity_pct, 14.98);
  EXPECT_NEAR(*d.frames[0].temperature_degc, 23.711111, 1e-6);
  EXPECT_NEAR(*d.frames[1].pressure_pa, 101320.759, 1e-3);
  EXPECT_DOUBLE_EQ(*d.frames[2].pressure_pa, 101300.0);
  EXPECT_NEAR(*d.frames[2].dew_point_degc, 10.0, 1e-12);
}

TEST(Ptu300Codec, ChecksumsByHand) {
  // "RH= 38.3 %RH " byte sum: R82 H72 =61 sp32 '3'51 '8'56 .46 '3'51 sp32 %37 R82 H72 sp32 = 706:
  // CS2 = 706 mod 256 = 194 = C2, CS4 = 02C2; XOR of the bytes (CSX) = 2E.
  EXPECT_EQ(ptu300_checksum_hex(Ptu300Checksum::cs2, "RH= 38.3 %RH "), "C2");
  EXPECT_EQ(ptu300_checksum_hex(Ptu300Checksum::cs4, "RH= 38.3 %RH "), "02C2");
  EXPECT_EQ(ptu300_checksum_hex(Ptu300Checksum::csx, "RH= 38.3 %RH "), "2E");
  EXPECT_EQ(ptu300_checksum(Ptu300Checksum::csx, "$A*"), 'A');  // '$' and '*' count as 0
  const auto ok =
      codec_test::feed_whole(Ptu300Codec({.checksum = Ptu300Checksum::cs2}), "RH= 38.3 %RH C2\r\n");
  ASSERT_EQ(ok.frames.size(), 1u);
  EXPECT_DOUBLE_EQ(*ok.frames[0].relative_humidity_pct, 38.3);
  const auto bad = codec_test::feed_whole(Ptu300Codec({.checksum = Ptu300Checksum::cs2}),
                                          "RH= 38.4 %RH C2\r\n"  // one digit changed
                                          "RH= 38.3 %RH\r\n");   // no checksum at all
  EXPECT_TRUE(bad.frames.empty());
  EXPECT_EQ(bad.stats.bad_checksum, 2u);
  const auto cs4 = codec_test::feed_whole(Ptu300Codec({.checksum = Ptu300Checksum::cs4}),
                                          "RH= 38.3 %RH 02C2\r\n");
  EXPECT_EQ(cs4.frames.size(), 1u);
}

TEST(Ptu300Codec, TextLinesStarsUnitsAndRanges) {
  const auto d = codec_test::feed_whole(Ptu300Codec{},
                                        ">SEND\r\n"                     // echo: a text frame
                                        "P= ****.* hPa T= 22.2 'C\r\n"  // P not available
                                        "T= 22.2 hPa\r\n"               // a pressure unit on T
                                        "P= 1500.0 hPa\r\n"             // beyond 1100 hPa
                                        "RH= 104.0 %RH\r\n"             // beyond 100 %RH
                                        "P= 1013\x01 hPa\r\n");         // control byte
  ASSERT_GE(d.frames.size(), 2u);
  EXPECT_EQ(d.frames[0].text, "SEND");
  EXPECT_FALSE(d.frames[1].pressure_pa);                  // the stars are no value ...
  EXPECT_DOUBLE_EQ(*d.frames[1].temperature_degc, 22.2);  // ... the rest of the line is
  // Stars are the device saying "no value" (issue 13): an unavailable field, not a codec error.
  ASSERT_EQ(d.frames[1].fields.size(), 2u);
  EXPECT_EQ(d.frames[1].fields[0].label, "P");
  EXPECT_FALSE(d.frames[1].fields[0].available);
  EXPECT_EQ(d.stats.out_of_range, 2u);  // 1500 hPa, 104 %RH
  EXPECT_EQ(d.stats.malformed, 1u);
  EXPECT_EQ(d.stats.garbage, 1u);
}

TEST(Ptu300Codec, EveryPressureUnitOfTheUsersGuideDewPointAndTrend) {
  // The user's guide lists hPa, psia, inHg, torr, bara, barg, psig, mbar, mmHg, kPa, Pa, mmH2O
  // and inH2O. By hand (NIST SP 811): 1.0132 bara = 101320 Pa; 10332.3 mmH2O * 9.80665 Pa =
  // 101325.2 Pa; 14.6959 psia * 6894.757 = 101324.66 Pa; 0.5 barg = 50000 Pa gauge; 2.0 psig =
  // 13789.514 Pa gauge.
  const auto d = codec_test::feed_whole(Ptu300Codec{},
                                        "P= 1.0132 bara\r\n"
                                        "P= 10332.3 mmH2O\r\n"
                                        "P= 14.6959 psia\r\n"
                                        "P= 0.5 barg T= 21.0 'C\r\n"
                                        "P= 2.0 psig\r\n"
                                        "Td= 4.5 'C Tdp= 4.6 'C\r\n"
                                        "P= 1013.2 hPa P3H= -0.4 hPa A3H= 5\r\n"
                                        "P3H= ****.* hPa A3H= *\r\n");
  EXPECT_EQ(d.stats.errors(), 0u);
  ASSERT_EQ(d.frames.size(), 8u);
  EXPECT_NEAR(*d.frames[0].pressure_pa, 101320.0, 1e-6);
  EXPECT_NEAR(*d.frames[1].pressure_pa, 101325.2, 0.1);
  EXPECT_NEAR(*d.frames[2].pressure_pa, 101324.66, 0.01);
  // Gauge pressures are decoded but never taken for the air's absolute pressure.
  EXPECT_FALSE(d.frames[3].pressure_pa);
  EXPECT_EQ(d.frames[3].fields[0].quantity, Ptu300Quantity::gauge_pressure);
  EXPECT_DOUBLE_EQ(d.frames[3].fields[0].value_si, 50000.0);
  EXPECT_DOUBLE_EQ(*d.frames[3].temperature_degc, 21.0);
  EXPECT_NEAR(d.frames[4].fields[0].value_si, 13789.514, 1e-6);
  // Td and Tdp are the dew point.
  EXPECT_DOUBLE_EQ(*d.frames[5].dew_point_degc, 4.5);
  EXPECT_EQ(d.frames[5].fields[1].quantity, Ptu300Quantity::dew_point);
  // The 3-hour trend in Pa and the tendency code; before 3 h both print stars.
  EXPECT_EQ(d.frames[6].fields[1].quantity, Ptu300Quantity::pressure_tendency);
  EXPECT_DOUBLE_EQ(d.frames[6].fields[1].value_si, -40.0);
  EXPECT_DOUBLE_EQ(d.frames[6].fields[2].value_si, 5.0);
  EXPECT_FALSE(d.frames[7].fields[0].available);
  EXPECT_FALSE(d.frames[7].fields[1].available);
}

TEST(Ptu300Codec, CommandsAsTheManualWritesThem) {
  EXPECT_EQ(ptu300_send(), "SEND\r");
  EXPECT_EQ(ptu300_send(3), "SEND 3\r");
  EXPECT_EQ(ptu300_stop(), "S\r");
  EXPECT_EQ(ptu300_run(), "R\r");
  EXPECT_EQ(ptu300_smode(Ptu300Mode::poll), "SMODE POLL\r");
  EXPECT_EQ(ptu300_intv(10, IntervalUnit::s), "INTV 10 S\r");
  EXPECT_THROW(ptu300_intv(256, IntervalUnit::s), cal::InputError);
  EXPECT_EQ(ptu300_form("/"), "FORM /\r");
  EXPECT_THROW(ptu300_form("4.2 P\r\n"), cal::InputError);
}

TEST(Ptu300Codec, SplitAtAnyByteGivesTheSameFrames) {
  const std::string stream =
      "P= 1033.7 hPa T= 22.2 'C RH= 38.3 %RH\r\nRH= 14.98%RH T= 74.68'F\r\nP= 1500.0 hPa\r\n";
  const auto whole = codec_test::feed_whole(Ptu300Codec{}, stream);
  const auto bytewise = codec_test::feed_bytewise(Ptu300Codec{}, stream);
  EXPECT_EQ(whole.frames, bytewise.frames);
  EXPECT_EQ(whole.stats, bytewise.stats);
  EXPECT_EQ(whole.frames.size(), 2u);
}

TEST(Ptu300Codec, TheInformationalAnswersAreNoMeasurement) {
  // What the informational commands print, as the Vaisala guides show it: VERS ("PTB220 /
  // 2.02", PTB220 guide ch. 8; the PTU300's "PTU300 / 5.10"), SNUM, ERRS, and "?" (PTU200
  // M210195EN "? Basic information on the transmitter settings"; DMP248 appendix 1, whose
  // analog output limits carry 'C). None of it is a pressure, temperature or humidity, and
  // none of it is a codec error.
  const auto d = codec_test::feed_whole(Ptu300Codec{},
                                        ">vers\r\n"
                                        "PTU300 / 5.10\r\n"
                                        "PTB220 / 2.02\r\n"
                                        "CPU serial no : P1234567\r\n"
                                        "No errors\r\n"
                                        ">?\r\n"
                                        "Software version PTU200 / 1.02\r\n"
                                        "Calibration date 1999-03-12\r\n"
                                        "Baud Parity Data Stop Dpx 9600 E 7 1 F\r\n"
                                        "Output interval 3 s\r\n"
                                        "Pressure unit hPa\r\n"
                                        "Temperature unit 'C\r\n"
                                        "Baud P D S    : 4800 E 7 1 FDX\r\n"
                                        "Pressure (hPa): 1013.25\r\n"
                                        " Ch1  ( Td ) lo   -40.00 'C\r\n"
                                        " Ch2  ( T  ) hi   160.00 'C\r\n"
                                        "Output units   : metric\r\n");
  EXPECT_EQ(d.stats.errors(), 0u);
  for (const auto& f : d.frames) {
    SCOPED_TRACE(f.text);
    EXPECT_FALSE(f.pressure_pa);
    EXPECT_FALSE(f.temperature_degc);
    EXPECT_FALSE(f.relative_humidity_pct);
    EXPECT_FALSE(f.dew_point_degc);
  }
}

using codec_test::strtod_shifted;

TEST(Ptu300Codec, PressuresInDecimalUnitsAreTheirPrintedDecimalsInPascalsBitForBit) {
  // 1024.4 hPa is 102440 Pa; 1024.4 x 100 (what the codec stored before) is 102440.00000000001.
  const auto d = codec_test::feed_whole(Ptu300Codec{}, "P= 1024.4 hPa T= 22.2 'C\r\n");
  ASSERT_EQ(d.frames.size(), 1u);
  EXPECT_EQ(*d.frames[0].pressure_pa, 102440.0);
  EXPECT_NE(1024.4 * 100.0, 102440.0);
  EXPECT_EQ(*d.frames[0].temperature_degc, 22.2);
  // Random readings in every unit that is a power of ten of the pascal, as FORM prints them.
  const std::pair<const char*, int> units[] = {{"hPa", 2}, {"mbar", 2}, {"kPa", 3},
                                               {"bar", 5}, {"bara", 5}, {"Pa", 0}};
  std::mt19937_64 rng(300);
  std::uniform_real_distribution<double> hpa(500.0, 1200.0);
  std::uniform_int_distribution<int> decimals(0, 3);
  std::size_t product_missed = 0, n = 0;
  char buf[32];
  for (int i = 0; i < 20'000; ++i) {
    for (const auto& [unit, shift] : units) {
      const int k = decimals(rng);
      std::snprintf(buf, sizeof buf, "%.*f", k + shift, hpa(rng) * 100.0 / std::pow(10.0, shift));
      const std::string line = std::string("P= ") + buf + " " + unit + "\r\n";
      SCOPED_TRACE(line);
      const auto f = codec_test::feed_whole(Ptu300Codec{}, line);
      ASSERT_EQ(f.frames.size(), 1u);
      const double want = strtod_shifted(buf, shift);
      ASSERT_EQ(std::bit_cast<std::uint64_t>(*f.frames[0].pressure_pa),
                std::bit_cast<std::uint64_t>(want));
      product_missed += std::strtod(buf, nullptr) * std::pow(10.0, shift) != want;
      ++n;
    }
  }
  EXPECT_GT(product_missed, n / 50);
}

}  // namespace
