// Machine position feeds: LinuxCNC halsampler and MTConnect SHDR lines written by hand from
// their documented formats (halsampler/codec.hpp, shdr/codec.hpp); expected values worked out
// beside them.
#include <gtest/gtest.h>

#include "cal/analysis/error.hpp"
#include "cal/drivers/registry.hpp"
#include "codec_test_util.hpp"
#include "halsampler/codec.hpp"
#include "shdr/codec.hpp"

namespace {

using namespace cal::drivers::codec;

TEST(HalsamplerCodec, SampleNumbersColumnsAndLostSamples) {
  // halsampler -t. Machine units mm: 12.5 mm = 0.0125 m, -3.25 mm = -0.00325 m. Sample 5
  // after 2: 3 and 4 lost.
  const auto d = codec_test::feed_whole(HalsamplerCodec({.sample_numbers = true}),
                                        "1 12.500000 -3.250000 0.000000\n"
                                        "2 12.600000 -3.250000 0.000000\n"
                                        "5 12.900000 -3.250000 0.100000\n");
  ASSERT_EQ(d.frames.size(), 3u);
  EXPECT_DOUBLE_EQ(*d.frames[0].position_m[0], 0.0125);
  EXPECT_DOUBLE_EQ(*d.frames[0].position_m[1], -0.00325);
  EXPECT_EQ(*d.frames[1].sample, 2u);
  EXPECT_EQ(d.frames[1].lost_before, 0u);
  EXPECT_EQ(d.frames[2].lost_before, 2u);
  EXPECT_DOUBLE_EQ(*d.frames[2].position_m[2], 0.0001);
  EXPECT_EQ(d.stats.errors(), 0u);
}

TEST(HalsamplerCodec, NoSampleNumbersOtherColumnsAndInches) {
  // halsampler without -t, pins in the order Z, spindle, X; inch machine: 1.25 in = 0.03175 m,
  // 0.5 in = 0.0127 m; Y not fed.
  const auto d = codec_test::feed_whole(
      HalsamplerCodec({.sample_numbers = false,
                       .column = {2, -1, 0},
                       .metres_per_unit = cal::drivers::codec::kInchesToMetres}),
      "0.5 7 1.25\n");
  ASSERT_EQ(d.frames.size(), 1u);
  EXPECT_DOUBLE_EQ(*d.frames[0].position_m[0], 0.03175);
  EXPECT_FALSE(d.frames[0].position_m[1]);
  EXPECT_DOUBLE_EQ(*d.frames[0].position_m[2], 0.0127);
  EXPECT_FALSE(d.frames[0].sample);
}

TEST(HalsamplerCodec, BadLinesAreCountedAndTheNextOneRead) {
  const auto d = codec_test::feed_whole(HalsamplerCodec({.sample_numbers = true}),
                                        "abc 1 2 3\n"        // no sample number
                                        "3 1.0\n"            // too few values
                                        "4 1.0 x 2.0\n"      // not a number
                                        "\x01\x02\x03\n"     // control bytes
                                        "6 1.0 2.0 3.0\n");  // good
  EXPECT_EQ(d.stats.malformed, 3u);
  EXPECT_EQ(d.stats.garbage, 1u);
  ASSERT_EQ(d.frames.size(), 1u);
  EXPECT_DOUBLE_EQ(*d.frames[0].position_m[2], 0.003);
  EXPECT_THROW(HalsamplerCodec({.metres_per_unit = {.multiplier = 0}}), cal::InputError);
}

TEST(HalsamplerCodec, UntaggedByDefaultAndOverrunIsAGapNotAnError) {
  // halsampler's default (no -t): no sample number, column 0 is a pin; a bit pin there ("1")
  // is a value. "overrun" lines (sampler_usr.c) say samples were lost: the next frame carries
  // it, and it is not a codec error. Column 1: 0.25 mm = 0.00025 m; 0.5 mm.
  const auto d = codec_test::feed_whole(HalsamplerCodec({.column = {1, 0, -1}}),
                                        "1 0.250000 \n"
                                        "overrun\n"
                                        "0 0.500000 \n");
  EXPECT_EQ(d.stats.errors(), 0u);
  ASSERT_EQ(d.frames.size(), 2u);
  EXPECT_FALSE(d.frames[0].sample);
  EXPECT_DOUBLE_EQ(*d.frames[0].position_m[0], 0.00025);
  EXPECT_DOUBLE_EQ(*d.frames[0].position_m[1], 0.001);  // the bit pin, as a value (1 mm)
  EXPECT_FALSE(d.frames[0].overrun);
  EXPECT_TRUE(d.frames[1].overrun);
  EXPECT_EQ(d.frames[1].lost_before, 0u);  // how many: only -t says
  // Tagged, the numbers say how many were lost across the overrun: 4 after 1, so 2 and 3.
  const auto t = codec_test::feed_whole(HalsamplerCodec({.sample_numbers = true}),
                                        "1 1.0 2.0 3.0 \noverrun\n4 1.0 2.0 3.0 \n");
  ASSERT_EQ(t.frames.size(), 2u);
  EXPECT_TRUE(t.frames[1].overrun);
  EXPECT_EQ(t.frames[1].lost_before, 2u);
  EXPECT_EQ(t.stats.errors(), 0u);
}

TEST(ShdrCodec, PositionsTimestampAndOtherItemsIgnored) {
  // 2024-01-01T00:00:00Z is Unix 1704067200 s; 12:00:00.123456 adds 43200.123456 s.
  const auto d = codec_test::feed_whole(
      ShdrCodec{}, "2024-01-01T12:00:00.123456Z|Xact|123.4567|Yact|-5.0000|mode|AUTOMATIC\n");
  ASSERT_EQ(d.frames.size(), 1u);
  EXPECT_DOUBLE_EQ(*d.frames[0].position_m[0], 0.1234567);
  EXPECT_DOUBLE_EQ(*d.frames[0].position_m[1], -0.005);
  EXPECT_FALSE(d.frames[0].position_m[2]);
  EXPECT_EQ(*d.frames[0].time_unix_ns, 1'704'110'400'123'456'000);
}

TEST(ShdrCodec, HeartbeatsUnavailableMultilineAndNoTimestamp) {
  ShdrCodec c;
  const auto frames = codec_test::frames_without_errors(
      c,
      "* PING\n* PONG 10000\n"
      "2024-01-01T12:00:01Z|Xact|UNAVAILABLE\n"
      "2024-01-01T12:00:02Z|@ASSET@|T1|CuttingTool|--multiline--AAAA\n"
      "<CuttingTool><Xact|5|Yact|6></CuttingTool>\n"
      "--multiline--AAAA\n"
      "|Xact|1\n");
  EXPECT_EQ(c.pings(), 1u);
  EXPECT_EQ(c.pongs(), 1u);
  EXPECT_EQ(c.pong_timeout_ms(), 10000);
  // UNAVAILABLE: a frame that says X is unknown (no position); then 1 mm, stamped by the agent
  // (no time here).
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_FALSE(frames[0].position_m[0]);
  EXPECT_TRUE(frames[0].unavailable[0]);
  EXPECT_FALSE(frames[0].unavailable[1]);
  EXPECT_DOUBLE_EQ(*frames[1].position_m[0], 0.001);
  EXPECT_FALSE(frames[1].unavailable[0]);
  EXPECT_FALSE(frames[1].time_unix_ns);
  EXPECT_EQ(ShdrCodec::ping(), "* PING\n");
}

TEST(ShdrCodec, BadTimestampsValuesAndRanges) {
  const auto d = codec_test::feed_whole(ShdrCodec{},
                                        "2024-13-01T00:00:00Z|Xact|1\n"  // month 13
                                        "2024-01-01T00:00:00Z|Xact|abc\n"
                                        "2024-01-01T00:00:00Z|Xact|1e9\n"  // 1e6 m
                                        "2024-01-01T00:00:00Z|Zact|-2.5\n");
  EXPECT_EQ(d.stats.malformed, 2u);
  EXPECT_EQ(d.stats.out_of_range, 1u);
  ASSERT_EQ(d.frames.size(), 1u);
  EXPECT_DOUBLE_EQ(*d.frames[0].position_m[2], -0.0025);
  EXPECT_THROW(ShdrCodec({.keys = {{"Aact", 3}}}), cal::InputError);
  EXPECT_EQ(parse_iso8601_utc_ns("1970-01-01T00:00:01.5Z"), 1'500'000'000);
  EXPECT_EQ(parse_iso8601_utc_ns("2000-02-29T00:00:00"), 951'782'400'000'000'000);
  EXPECT_FALSE(parse_iso8601_utc_ns("yesterday"));
  // Found by the fuzzer: a year whose nanoseconds overflow int64; a signed fraction.
  EXPECT_FALSE(parse_iso8601_utc_ns("1012-01-01T12:00:00Z"));
  EXPECT_FALSE(parse_iso8601_utc_ns("4909-01-01T12:00:00Z"));
  EXPECT_FALSE(parse_iso8601_utc_ns("2024-01-01T12:00:00.-5Z"));
}

TEST(ShdrCodec, TokensAsTheAgentsTokenizerMakesThem) {
  // cppagent's ShdrTokenizer: tokens trimmed, a terminal '|' gives an empty token, quoted
  // tokens may hold '|' escaped with a backslash; an unterminated quote is plain text.
  using V = std::vector<std::string>;
  EXPECT_EQ(shdr_tokens("  |x1 |  12.5 | "), (V{"", "x1", "12.5", ""}));
  EXPECT_EQ(shdr_tokens("a|b|"), (V{"a", "b", ""}));
  EXPECT_EQ(shdr_tokens(R"(t|msg|"left\|right"|Xact|1)"),
            (V{"t", "msg", "left|right", "Xact", "1"}));
  EXPECT_EQ(shdr_tokens(R"(t|"say \"hi\""|z)"), (V{"t", "say \"hi\"", "z"}));
  EXPECT_EQ(shdr_tokens(R"(t|"open|z)"), (V{"t", "\"open", "z"}));
}

TEST(ShdrCodec, EveryTimestampFormOfTheAgent) {
  // @duration suffixes are cut off (kept as the frame's duration); a number without 'T' is a
  // relative time in ms (from the first); empty: the agent's own time. Spaces are trimmed.
  ShdrCodec c({.keys = {{"Xact", 0}}});
  const auto frames = codec_test::frames_without_errors(c,
                                                        "2024-01-01T12:00:00.5Z@100.0|Xact| 1.5 \n"
                                                        "1000.5|Xact|2\n"
                                                        "1250.5@10|Xact|3\n"
                                                        "|Xact|4\n");
  ASSERT_EQ(frames.size(), 4u);
  EXPECT_EQ(*frames[0].time_unix_ns, 1'704'110'400'500'000'000);
  EXPECT_DOUBLE_EQ(*frames[0].duration_s, 100.0);
  EXPECT_DOUBLE_EQ(*frames[0].position_m[0], 0.0015);
  EXPECT_FALSE(frames[1].time_unix_ns);
  EXPECT_DOUBLE_EQ(*frames[1].relative_time_ms, 0.0);    // the first relative time
  EXPECT_DOUBLE_EQ(*frames[2].relative_time_ms, 250.0);  // 250 ms after it
  EXPECT_DOUBLE_EQ(*frames[2].duration_s, 10.0);
  EXPECT_FALSE(frames[3].time_unix_ns);
  EXPECT_FALSE(frames[3].relative_time_ms);
}

TEST(ShdrCodec, ConditionsMessagesAssetsAndCommandsDoNotHidePositions) {
  // Items are walked key|value by position as cppagent's ShdrTokenMapper does (a key it does not
  // know skips one value). A condition (five values) stands on its own line, as SHDR has it:
  // with an even count of values the pairs after it stay aligned. Commands with or without a
  // space after '*' are not data; an asset's body is skipped up to a line equal to its
  // terminator.
  ShdrCodec c({.keys = {{"Xact", 0}, {"Zact", 2}}});
  const auto frames = codec_test::frames_without_errors(
      c,
      "2024-01-01T00:00:00.5Z|Xact|10\n"
      "2024-01-01T00:00:01Z|Xcond|WARNING|42|HIGH||too close\n"
      "2024-01-01T00:00:01.5Z|Zact|-5\n"
      "*adapterVersion:1.0\n"
      "* shdrVersion: 2\n"
      "2024-01-01T00:00:02Z|@ASSET@|T1|CuttingTool|--multiline--0FF1CE\n"
      "<CuttingTool>|Xact|99|</CuttingTool>\n"
      "--multiline--0FF1CE\r\n"
      "2024-01-01T00:00:03Z|Xact|UNAVAILABLE|Zact|7\n");
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_DOUBLE_EQ(*frames[0].position_m[0], 0.010);
  EXPECT_DOUBLE_EQ(*frames[1].position_m[2], -0.005);
  EXPECT_FALSE(frames[2].position_m[0]);
  EXPECT_TRUE(frames[2].unavailable[0]);
  EXPECT_DOUBLE_EQ(*frames[2].position_m[2], 0.007);
  EXPECT_EQ(c.commands(), 2u);
  EXPECT_EQ(c.assets(), 1u);
}

TEST(ShdrCodec, AValueEqualToAKeyNameIsAValue) {
  // Pairs by position (cppagent's ShdrTokenMapper): "msg|Xact" is the item msg with the value
  // "Xact", so the 12.5 after it is no X position; "program|Xact" likewise, then X = 3 mm.
  const auto d = codec_test::feed_whole(ShdrCodec{},
                                        "2024-01-01T00:00:00Z|Yact|1|msg|Xact|12.5\n"
                                        "2024-01-01T00:00:01Z|program|Xact|Xact|3\n");
  EXPECT_EQ(d.stats.errors(), 0u);  // before: "program|Xact|Xact" made X = "Xact", an error
  ASSERT_EQ(d.frames.size(), 2u);
  EXPECT_DOUBLE_EQ(*d.frames[0].position_m[1], 0.001);
  EXPECT_FALSE(d.frames[0].position_m[0]);
  EXPECT_DOUBLE_EQ(*d.frames[1].position_m[0], 0.003);
}

TEST(ShdrCodec, TheCensusOfNumericKeysIsForDecodeOnlyAndBounded) {
  const std::string lines = "2024-01-01T00:00:00Z|X1actw|1.5|mode|AUTO|Xact|2|S1load|0\n";
  EXPECT_TRUE(codec_test::feed_whole(ShdrCodec{}, lines).frames.size() == 1u);
  ShdrCodec off;
  std::vector<PositionFrame> frames;
  std::vector<CodecError> errors;
  off.feed(lines, frames, errors);
  EXPECT_TRUE(off.numeric_keys_seen().empty());  // runs keep no census
  ShdrCodec on({.census = true});
  on.feed(lines + lines, frames, errors);
  // The configured Xact is not listed, nor mode (AUTO is no number); each key once.
  EXPECT_EQ(on.numeric_keys_seen(), (std::vector<std::string>{"X1actw", "S1load"}));
  std::string many;
  for (int k = 0; k < 1000; ++k) many += "|k" + std::to_string(k) + "|1\n";
  on.feed(many, frames, errors);
  EXPECT_EQ(on.numeric_keys_seen().size(), ShdrCodec::census_limit);
}

TEST(PositionFeeds, SplitAtAnyByteGivesTheSameFrames) {
  const std::string hal = "1 12.5 -3.25 0\n2 12.6 -3.25 0\n5 x\n6 1 2 3\n";
  const std::string shdr =
      "* PING\n2024-01-01T12:00:00Z|Xact|1.5|Yact|2\n2024-01-01T12:00:00Z|Xact|bad\n";
  const auto hw = codec_test::feed_whole(HalsamplerCodec({.sample_numbers = true}), hal);
  const auto hb = codec_test::feed_bytewise(HalsamplerCodec({.sample_numbers = true}), hal);
  EXPECT_EQ(hw.stats, hb.stats);
  ASSERT_EQ(hb.frames.size(), 3u);
  // Sample 6 after 2: 3 and 4 were skipped by halsampler (lost); 5 came but is malformed.
  EXPECT_EQ(hb.frames[2].lost_before, 2u);
  EXPECT_EQ(hb.stats.malformed, 1u);
  const auto sw = codec_test::feed_whole(ShdrCodec{}, shdr);
  const auto sb = codec_test::feed_bytewise(ShdrCodec{}, shdr);
  EXPECT_EQ(sw.stats, sb.stats);
  ASSERT_EQ(sb.frames.size(), 1u);
  EXPECT_DOUBLE_EQ(*sb.frames[0].position_m[0], 0.0015);
}

TEST(ShdrDecoder, AnUnavailablePositionIsANoteNotAReading) {
  // daq decode shdr: "Xposition|UNAVAILABLE" says the control has no position; the decoder
  // says so (one note naming the item) and gives no reading for it.
  const auto& shdr = cal::drivers::driver("shdr");
  const std::vector<std::pair<std::string, std::string>> set{{"keys", "Xposition,Yposition,"}};
  auto decoder = shdr.make_decoder(cal::drivers::options_from_text(shdr, set));
  const std::string text =
      "2015-10-27T17:38:06.715274Z|Xposition|16.50304\n"
      "2015-10-27T17:38:07Z|Xposition|UNAVAILABLE|Yposition|-22.06068\n";
  std::vector<cal::drivers::DecodedItem> items;
  decoder->feed(std::as_bytes(std::span(text.data(), text.size())), items);
  decoder->finish(items);
  std::vector<std::string> notes;
  std::size_t readings = 0;
  for (const auto& i : items) {
    if (i.kind == cal::drivers::DecodedItem::Kind::note) notes.push_back(i.text);
    if (i.kind == cal::drivers::DecodedItem::Kind::reading) ++readings;
    EXPECT_NE(i.kind, cal::drivers::DecodedItem::Kind::error) << i.text;
  }
  EXPECT_EQ(readings, 2u);  // X 16.50304 mm, Y -22.06068 mm
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_EQ(notes[0], "Xposition: UNAVAILABLE (no position)");
}

}  // namespace
