#include "cal/drivers/codec/common.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <string>
#include <vector>

namespace {

using cal::drivers::codec::LineSplitter;

struct Collected {
  std::vector<std::pair<std::string, std::uint64_t>> lines;
  std::vector<std::uint64_t> overlong;
};

Collected split(LineSplitter s, std::string_view stream, std::size_t chunk) {
  Collected c;
  for (std::size_t i = 0; i < stream.size(); i += chunk) {
    s.feed(
        cal::drivers::codec::as_bytes(stream.substr(i, chunk)),
        [&](std::string_view line, std::uint64_t off) { c.lines.emplace_back(line, off); },
        [&](std::uint64_t off) { c.overlong.push_back(off); });
  }
  return c;
}

TEST(CodecLineSplitter, AnyEolEndsALineAndEmptyLinesAreSkipped) {
  // Offsets by hand: "ab" starts at 0, "\r\n" at 2..3, "cd" at 4, "\n" at 6, "\r" at 7,
  // "ef" at 8, "\r" at 10; "gh" (8 + 3 = 11) has no terminator yet and stays pending.
  const std::string stream = "ab\r\ncd\n\ref\rgh";
  for (std::size_t chunk = 1; chunk <= stream.size(); ++chunk) {
    const auto c = split(LineSplitter{}, stream, chunk);
    ASSERT_EQ(c.lines.size(), 3u) << "chunk " << chunk;
    EXPECT_EQ(c.lines[0], (std::pair<std::string, std::uint64_t>{"ab", 0}));
    EXPECT_EQ(c.lines[1], (std::pair<std::string, std::uint64_t>{"cd", 4}));
    EXPECT_EQ(c.lines[2], (std::pair<std::string, std::uint64_t>{"ef", 8}));
    EXPECT_TRUE(c.overlong.empty());
  }
}

TEST(CodecLineSplitter, OverlongLineIsReportedOnceAndResyncsAtTheNextTerminator) {
  // Limit 4: "abcdefgh" (offset 0) is too long; "ok" starts after its '\n' at offset 9.
  const std::string stream = "abcdefgh\nok\n";
  for (std::size_t chunk = 1; chunk <= stream.size(); ++chunk) {
    const auto c = split(LineSplitter{4}, stream, chunk);
    ASSERT_EQ(c.overlong.size(), 1u) << "chunk " << chunk;
    EXPECT_EQ(c.overlong[0], 0u);
    ASSERT_EQ(c.lines.size(), 1u);
    EXPECT_EQ(c.lines[0], (std::pair<std::string, std::uint64_t>{"ok", 9}));
  }
  // Exactly at the limit is still a line.
  const auto c = split(LineSplitter{4}, "abcd\n", 5);
  ASSERT_EQ(c.lines.size(), 1u);
  EXPECT_TRUE(c.overlong.empty());
}

TEST(CodecCommon, ParseNumber) {
  using cal::drivers::codec::parse_number;
  EXPECT_DOUBLE_EQ(*parse_number("+012.3456"), 12.3456);
  EXPECT_DOUBLE_EQ(*parse_number("-1.17"), -1.17);
  EXPECT_FALSE(parse_number("+-1").has_value());
  EXPECT_FALSE(parse_number("1.5mm").has_value());
  EXPECT_FALSE(parse_number("").has_value());
  EXPECT_FALSE(parse_number("+").has_value());
}

TEST(CodecCommon, StatsCountEachKind) {
  using cal::drivers::codec::ErrorKind;
  cal::drivers::codec::CodecStats s;
  s.add(ErrorKind::garbage);
  s.add(ErrorKind::bad_checksum);
  s.add(ErrorKind::bad_checksum);
  EXPECT_EQ(s.count(ErrorKind::bad_checksum), 2u);
  EXPECT_EQ(s.count(ErrorKind::garbage), 1u);
  EXPECT_EQ(s.count(ErrorKind::malformed), 0u);
  EXPECT_EQ(s.errors(), 3u);
  EXPECT_EQ(cal::drivers::codec::to_string(ErrorKind::overlong_line), "overlong_line");
}

}  // namespace

namespace {

// The splitter against a byte-at-a-time reference written from the rules (any CR or LF
// ends a line, empty lines skipped, a line over the limit reported once at its start and
// dropped to its terminator), on random streams rich in terminators cut at random places.
Collected reference_split(std::string_view stream, std::size_t max) {
  Collected c;
  std::string line;
  std::uint64_t start = 0;
  bool over = false;
  for (std::size_t i = 0; i < stream.size(); ++i) {
    const char ch = stream[i];
    if (ch == '\r' || ch == '\n') {
      if (!over && !line.empty()) c.lines.emplace_back(line, start);
      line.clear();
      over = false;
      start = i + 1;
      continue;
    }
    if (over) continue;
    if (line.size() + 1 > max) {
      over = true;
      line.clear();
      c.overlong.push_back(start);
      continue;
    }
    line += ch;
  }
  return c;
}

// The splitter's lines and overlong reports for `stream` fed in chunks of 1 to max_chunk bytes.
Collected split_in_random_chunks(std::string_view stream, std::size_t max, std::size_t max_chunk,
                                 std::mt19937& rng) {
  LineSplitter s(max);
  Collected got;
  for (std::size_t i = 0; i < stream.size();) {
    const std::size_t n = std::min<std::size_t>(1 + rng() % max_chunk, stream.size() - i);
    s.feed(
        cal::drivers::codec::as_bytes(stream.substr(i, n)),
        [&](std::string_view line, std::uint64_t off) { got.lines.emplace_back(line, off); },
        [&](std::uint64_t off) { got.overlong.push_back(off); });
    i += n;
  }
  return got;
}

TEST(CodecLineSplitter, EqualsAByteAtATimeReferenceOnRandomStreamsAndCuts) {
  std::mt19937 rng(42);
  const char alphabet[] = {'a', 'b', '\r', '\n', ' ', '\0', '\xff'};
  for (int trial = 0; trial < 2000; ++trial) {
    std::string stream(rng() % 200, 'x');
    for (auto& ch : stream) ch = alphabet[rng() % sizeof alphabet];
    const std::size_t max = 1 + rng() % 12;
    const auto got = split_in_random_chunks(stream, max, 40, rng);
    // The reference ends lines only at terminators; a pending last line is not handed out.
    const auto want = reference_split(stream, max);
    ASSERT_EQ(got.lines, want.lines) << trial;
    ASSERT_EQ(got.overlong, want.overlong) << trial;
  }
}

TEST(CodecLineSplitter, EqualsTheReferenceWithLongLinesAcrossTheSixteenByteBlocks) {
  // The terminators are searched 16 bytes at a time: lines of 0 to 70 bytes (so a terminator
  // falls at every position of a block, and in the byte loop of a chunk's tail), every kind of
  // terminator (CR, LF, CR-LF, LF-CR, CR-CR), chunks of 1 to 300 bytes (a CR-LF pair cut
  // between two chunks included), limits below and above the line lengths.
  std::mt19937 rng(20261127);
  const char* const terminators[] = {"\r", "\n", "\r\n", "\n\r", "\r\r"};
  std::size_t lines_seen = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    std::string stream;
    while (stream.size() < 600) {
      const std::size_t len = rng() % 71;
      for (std::size_t k = 0; k < len; ++k) stream += static_cast<char>('0' + rng() % 10);
      stream += terminators[rng() % 5];
    }
    const std::size_t max = 20 + rng() % 60;
    const auto got = split_in_random_chunks(stream, max, 300, rng);
    const auto want = reference_split(stream, max);
    ASSERT_EQ(got.lines, want.lines) << trial;
    ASSERT_EQ(got.overlong, want.overlong) << trial;
    lines_seen += want.lines.size();
  }
  EXPECT_GT(lines_seen, 3000u * 10);  // the streams did hold lines
}

}  // namespace
