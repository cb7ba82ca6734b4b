// The exact decimal fast path (cal/drivers/codec/decimal.hpp) against std::from_chars, the
// independent reference: wherever the fast path takes a string it must give the very same bits
// (stored readings must not change by one bit), and it must never take a string from_chars
// refuses.
#include "cal/drivers/codec/decimal.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <optional>
#include <random>
#include <string>

#include "cal/drivers/codec/common.hpp"

namespace {

using cal::drivers::codec::parse_number;
using cal::drivers::codec::parse_plain_decimal;

// from_chars over the whole string, with the leading '+' that gauges print allowed (from_chars
// itself refuses it); nullopt when it refuses the string or leaves something over.
std::optional<double> reference(std::string_view s) {
  if (!s.empty() && s.front() == '+') {
    s.remove_prefix(1);
    if (!s.empty() && (s.front() == '+' || s.front() == '-')) return std::nullopt;
  }
  double v = 0.0;
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc{} || p != s.data() + s.size()) return std::nullopt;
  return v;
}

std::uint64_t bits(double v) { return std::bit_cast<std::uint64_t>(v); }

// Checks one string; returns whether the fast path took it.
bool same_as_from_chars(const std::string& s) {
  double fast = 0.0;
  const bool taken = parse_plain_decimal(s, fast);
  const auto ref = reference(s);
  if (taken) {
    EXPECT_TRUE(ref.has_value()) << "'" << s << "' taken by the fast path, refused by from_chars";
    if (ref) {
      EXPECT_EQ(bits(fast), bits(*ref))
          << "'" << s << "': fast " << fast << ", from_chars " << *ref;
    }
  }
  // parse_number (fast path, else from_chars) must agree with from_chars in every case.
  const auto number = parse_number(s);
  EXPECT_EQ(number.has_value(), ref.has_value()) << "'" << s << "'";
  if (number && ref) {
    EXPECT_EQ(bits(*number), bits(*ref)) << "'" << s << "'";
  }
  return taken;
}

TEST(PlainDecimal, EdgeCasesMatchFromCharsOrFallBack) {
  // Taken: signs, zeros (the sign of -0 kept), a point at either end, the largest exact
  // mantissa (2^53 = 9007199254740992) and the most fraction digits (22).
  for (const char* s : {"0",
                        "+0",
                        "-0",
                        "-0.000",
                        "+000.000000",
                        "5.",
                        ".5",
                        "-.5",
                        "+.5",
                        "1",
                        "-1.17",
                        "+012.3456",
                        "+100.000123",
                        "-0.00125",
                        "1013.25",
                        "9007199254740992",
                        "-9007199254740992",
                        "0.9007199254740992",
                        "0.0000000000000000000001",
                        "000000000000000000000000001.5",
                        "0.1",
                        "0.2",
                        "0.3",
                        "123456789012345.6"})
    EXPECT_TRUE(same_as_from_chars(s)) << s;
  // Not taken (from_chars decides): past 2^53, more than 19 digits, more than 22 fraction
  // digits, exponents, inf/nan, hex, blanks, units, a second sign or point, no digit.
  for (const char* s : {"9007199254740993",
                        "9999999999999999999",
                        "12345678901234567890",
                        "4503599627370496.5",
                        "2.2250738585072014",
                        "1.7976931348623157",
                        "1234567890123456.0",
                        "0.00000000000000000000001",
                        "1e5",
                        "1.5E-3",
                        "-2e+2",
                        "inf",
                        "-nan",
                        "0x1p3",
                        " 1",
                        "1 ",
                        "1mm",
                        "+-1",
                        "-+1",
                        "--1",
                        "1..2",
                        "1.2.3",
                        ".",
                        "+",
                        "-",
                        "",
                        "+.",
                        "-."})
    EXPECT_FALSE(same_as_from_chars(s)) << s;
  // The values themselves, independently of from_chars.
  double v = 1.0;
  ASSERT_TRUE(parse_plain_decimal("-0.000", v));
  EXPECT_TRUE(std::signbit(v));
  EXPECT_EQ(v, 0.0);
  ASSERT_TRUE(parse_plain_decimal("+012.3456", v));
  EXPECT_EQ(v, 12.3456);  // the literal is the correctly rounded double of 12.3456
  ASSERT_TRUE(parse_plain_decimal("0.1", v));
  EXPECT_EQ(v, 0.1);
}

TEST(PlainDecimal, RandomDigitStringsGiveTheBitsOfFromChars) {
  // Random signs, integer digits (0 to 20, leading zeros included), with or without a point,
  // fraction digits (0 to 24): both sides of every limit of the fast path.
  std::mt19937_64 rng(20261123);
  std::uniform_int_distribution<int> digit(0, 9), sign(0, 2), int_len(0, 20), frac_len(0, 24),
      coin(0, 1);
  std::size_t taken = 0;
  constexpr int kCases = 400'000;
  std::string s;
  for (int i = 0; i < kCases; ++i) {
    s.clear();
    s += "\0+-"[sign(rng)];
    if (s.front() == '\0') s.clear();
    const int n_int = int_len(rng);
    for (int k = 0; k < n_int; ++k) s += static_cast<char>('0' + digit(rng));
    if (coin(rng)) {
      s += '.';
      const int n_frac = frac_len(rng);
      for (int k = 0; k < n_frac; ++k) s += static_cast<char>('0' + digit(rng));
    }
    taken += same_as_from_chars(s);
    if (::testing::Test::HasFailure()) break;
  }
  // Both paths are exercised (about half the strings are within the exact range).
  EXPECT_GT(taken, kCases / 5u);
  EXPECT_LT(taken, kCases * 4u / 5u);
}

TEST(PlainDecimal, PrintedDoublesInGaugeFormatsGiveTheBitsOfFromChars) {
  // What instruments print: random doubles (every magnitude from 1e-6 to 1e9) in fixed
  // notation with 0 to 12 decimals and a forced sign, as "%+0W.Pf" does; the longest strings of
  // the format (up to 19 digits) included.
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> mantissa(-10.0, 10.0);
  std::uniform_int_distribution<int> exponent(-6, 9), decimals(0, 12), width(0, 20);
  char buf[64];
  std::size_t taken = 0;
  constexpr int kCases = 300'000;
  for (int i = 0; i < kCases; ++i) {
    const double x = mantissa(rng) * std::pow(10.0, exponent(rng));
    std::snprintf(buf, sizeof buf, "%+0*.*f", width(rng), decimals(rng), x);
    taken += same_as_from_chars(buf);
    if (::testing::Test::HasFailure()) break;
  }
  // Most are taken; those with more than about 16 significant digits go to from_chars.
  EXPECT_GT(taken, kCases * 3u / 4u);
}

TEST(PlainDecimal, EveryValueOfTheBenchGaugeLine) {
  // The ingest benchmark's line "%+011.6f" around 100 mm: one million consecutive values.
  char buf[32];
  for (int k = 0; k < 1'000'000; ++k) {
    std::snprintf(buf, sizeof buf, "%+011.6f", 100.0 + 1e-6 * k);
    ASSERT_TRUE(same_as_from_chars(buf)) << buf;
    if (::testing::Test::HasFailure()) break;
  }
}

}  // namespace
