// Text checked and shown safely (cal/analysis/text.hpp).
#include "cal/analysis/text.hpp"

#include <gtest/gtest.h>

#include "cal/analysis/error.hpp"
#include "cal/analysis/json_scan.hpp"

namespace {

using namespace cal::text;

TEST(Text, Utf8AcceptsEveryScriptAndRefusesMalformedBytes) {
  EXPECT_FALSE(invalid_utf8_at("By: M\xC3\xBCller \xE6\xB8\xAC\xE5\xAE\x9A \xF0\x9F\x93\x8F"));
  EXPECT_EQ(invalid_utf8_at("By: M\xFCller"), 5u);      // Windows-1252 u-umlaut
  EXPECT_EQ(invalid_utf8_at("a\xC0\xAF"), 1u);          // overlong '/'
  EXPECT_EQ(invalid_utf8_at("a\xED\xA0\x80"), 1u);      // a surrogate
  EXPECT_EQ(invalid_utf8_at("a\xF4\x90\x80\x80"), 1u);  // above U+10FFFF
  EXPECT_EQ(invalid_utf8_at("ab\xE2\x82"), 2u);         // cut short at the end
}

TEST(Text, RequireUtf8NamesFileLineAndByte) {
  try {
    require_utf8("Owner: x\r\nBy: M\xFCller\r\n", "f.rtx", 2, 10);
    FAIL() << "accepted";
  } catch (const cal::InputError& e) {
    EXPECT_STREQ(e.what(), "f.rtx: line 3, byte 25: not UTF-8 text (byte 0xFC)");
  }
}

TEST(Text, Windows1252BecomesUtf8) {
  EXPECT_EQ(windows1252_to_utf8("M\xFCller \x80 \x93x\x94"),
            "M\xC3\xBCller \xE2\x82\xAC \xE2\x80\x9Cx\xE2\x80\x9D");
  EXPECT_EQ(windows1252_to_utf8("\x81"), "\xEF\xBF\xBD");  // undefined in the code page
  EXPECT_FALSE(invalid_utf8_at(windows1252_to_utf8(std::string(1, '\xFF') + "\x9F\x81")));
}

TEST(Text, TerminalSafeEscapesControlsAndKeepsText) {
  EXPECT_EQ(terminal_safe("laser\x1b]52;c;ZWNobyBoaQ==\x07"), "laser\\x1B]52;c;ZWNobyBoaQ==\\x07");
  EXPECT_EQ(terminal_safe("a\nb\tc\\x1B"), "a\\nb\\tc\\\\x1B");
  EXPECT_EQ(terminal_safe("\xC2\x9B"
                          "31m"),
            "\\u{009B}31m");                                  // C1 CSI
  EXPECT_EQ(terminal_safe("x\xE2\x80\xAEy"), "x\\u{202E}y");  // right-to-left override
  EXPECT_EQ(terminal_safe("M\xFCller"), "M\\xFCller");        // not UTF-8
  EXPECT_EQ(terminal_safe("M\xC3\xBCller 21 \xC2\xB0"
                          "C"),
            "M\xC3\xBCller 21 \xC2\xB0"
            "C");
  EXPECT_EQ(terminal_safe("\x7f"), "\\x7F");
}

TEST(Text, UtcTextFormatsWholeSecondsAsUtc) {
  EXPECT_EQ(utc_text(0, "%Y-%m-%dT%H:%M:%SZ"), "1970-01-01T00:00:00Z");
  // 2026-11-28 09:13:58 UTC, whatever the machine's time zone.
  EXPECT_EQ(utc_text(1795857238, "%Y-%m-%d %H:%M:%S UTC"), "2026-11-28 09:13:58 UTC");
  EXPECT_EQ(utc_text(-1, "%Y-%m-%dT%H:%M:%S"), "1969-12-31T23:59:59");  // before 1970
  EXPECT_EQ(utc_text(0, ""), "");
}

}  // namespace

// JSON structure without parsing (json_scan.hpp): brackets and quotes inside strings, escaped
// quotes included, are not structure.
TEST(JsonScan, FindsTheFirstStructuralCharacterOutsideStrings) {
  const std::string_view text = R"({"a": "}\"}", "b": [1]})";
  const auto first_close = [&](std::size_t from) {
    return cal::text::find_outside_json_strings(text, from, [](char c) { return c == '}'; });
  };
  EXPECT_EQ(first_close(0), text.size() - 1);
  EXPECT_EQ(cal::text::find_outside_json_strings(text, 0, [](char c) { return c == '['; }), 19u);
  EXPECT_EQ(cal::text::find_outside_json_strings(R"("[")", 0, [](char c) { return c == '['; }),
            std::string_view::npos);
  EXPECT_EQ(first_close(text.size()), std::string_view::npos);
}
