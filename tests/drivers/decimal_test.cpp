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
#include "codec_test_util.hpp"

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

// ---- Readings in SI: the printed decimal with its exponent moved (docs/codecs.md) ----

namespace {

using cal::drivers::codec::DecimalScale;
using cal::drivers::codec::parse_number_scaled;
using cal::drivers::codec::scaled_count;
using cal::drivers::codec::scaled_double;

constexpr DecimalScale kMm{1, -3}, kUm{1, -6}, kPm{1, -12}, kHpa{1, 2}, kM{1, 0};

TEST(ScaledDecimal, HandValuesAreTheDecimalsInSi) {
  // A gauge's 100.000123 mm is 0.100000123 m: the literal is the compiler's correctly rounded
  // double of that decimal; the product with 1e-3 is one ulp above it.
  EXPECT_EQ(parse_number_scaled("+100.000123", kMm), 0.100000123);
  EXPECT_NE(100.000123 * 1e-3, 0.100000123);  // what drivers stored before
  EXPECT_EQ(parse_number_scaled("-250.000001", kMm), -0.250000001);
  EXPECT_EQ(parse_number_scaled("33.333333", kMm), 0.033333333);
  EXPECT_EQ(parse_number_scaled("1033.7", kHpa), 103370.0);
  EXPECT_EQ(parse_number_scaled("1013.25", kHpa), 101325.0);
  EXPECT_EQ(parse_number_scaled("1.25", cal::drivers::codec::kInchesToMetres), 0.03175);
  EXPECT_EQ(parse_number_scaled("1.5e3", kPm), 1.5e-9);
  EXPECT_EQ(parse_number_scaled("0.123456", kUm), 1.23456e-7);
  EXPECT_EQ(scaled_count(100000123000, kPm), 0.100000123);
  EXPECT_EQ(scaled_count(-7, kPm), -7e-12);
  EXPECT_EQ(scaled_double(100.000123, kMm), 0.100000123);
  // Zeros keep their sign; non-numbers are what parse_number makes of them; out of range is
  // refused as parse_number refuses "1e400".
  const auto neg_zero = parse_number_scaled("-0.000", kMm);
  ASSERT_TRUE(neg_zero);
  EXPECT_TRUE(std::signbit(*neg_zero));
  EXPECT_EQ(*neg_zero, 0.0);
  EXPECT_TRUE(std::isinf(*parse_number_scaled("-inf", kMm)));
  EXPECT_TRUE(std::isnan(*parse_number_scaled("nan", kMm)));
  for (const char* bad : {"", "+", "-", ".", "+-1", "--1", "1..2", "1.2.3", "1e", "1e+", " 1", "1 ",
                          "1mm", "0x1p3", "1e400", "-1e400"}) {
    SCOPED_TRACE(bad);
    EXPECT_FALSE(parse_number_scaled(bad, kMm));
    EXPECT_EQ(parse_number_scaled(bad, kM).has_value(), parse_number(bad).has_value());
  }
}

TEST(ScaledDecimal, PrintedReadingsAreStrtodOfTheTextWithItsExponentMoved) {
  // Gauge-like prints (0 to 12 decimals, every magnitude), long digit strings beyond 2^53 and
  // 19 digits, and texts with exponents: each scale's result is strtod of the moved text,
  // bit for bit. The old arithmetic (the printed double x 1e-3) is counted: it must miss some,
  // or this test would not see the difference it is about.
  std::mt19937_64 rng(20261129);
  std::uniform_real_distribution<double> mantissa(-10.0, 10.0);
  std::uniform_int_distribution<int> exponent(-6, 9), decimals(0, 12), digits(1, 30), digit(0, 9),
      coin(0, 3), exp_shift(-30, 30);
  const std::pair<DecimalScale, int> scales[] = {
      {kMm, -3}, {kUm, -6}, {kPm, -12}, {kHpa, 2}, {kM, 0}};
  char buf[96];
  std::size_t product_missed = 0, cases = 0;
  for (int i = 0; i < 200'000; ++i) {
    std::string s;
    switch (coin(rng)) {
      case 0:
      case 1:
        std::snprintf(buf, sizeof buf, "%+.*f", decimals(rng),
                      mantissa(rng) * std::pow(10.0, exponent(rng)));
        s = buf;
        break;
      case 2: {  // a long digit string with a point somewhere
        const int n = digits(rng);
        for (int k = 0; k < n; ++k) s += static_cast<char>('0' + digit(rng));
        s.insert(s.begin() + std::uniform_int_distribution<int>(0, n)(rng), '.');
        if (coin(rng) == 0) s.insert(s.begin(), '-');
        break;
      }
      default:  // an exponent
        std::snprintf(buf, sizeof buf, "%.*e", decimals(rng), mantissa(rng));
        s = buf;
        s = s.substr(0, s.find('e')) + "e" + std::to_string(exp_shift(rng));
        break;
    }
    for (const auto& [scale, shift] : scales) {
      SCOPED_TRACE(s + " x 10^" + std::to_string(shift));
      const auto v = parse_number_scaled(s, scale);
      ASSERT_TRUE(v);
      ASSERT_EQ(bits(*v), bits(codec_test::strtod_shifted(s, shift)));
      if (shift < 0) {
        ++cases;
        product_missed += *v != *parse_number(s) * std::pow(10.0, shift);
      }
    }
  }
  EXPECT_GT(product_missed, cases / 20);
}

TEST(ScaledDecimal, InchesAreTheExactDecimalProductWith254) {
  // x in = x 0.0254 m exactly: the digits times 254 (integer arithmetic here), exponent - 4.
  std::mt19937_64 rng(7);
  std::uniform_int_distribution<std::int64_t> n(-9'999'999'999, 9'999'999'999);
  std::uniform_int_distribution<int> decimals(0, 8);
  for (int i = 0; i < 100'000; ++i) {
    const std::int64_t digits = n(rng);
    const int k = decimals(rng);
    std::string text = std::to_string(digits < 0 ? -digits : digits);
    while (static_cast<int>(text.size()) <= k) text.insert(text.begin(), '0');
    text.insert(text.end() - k, '.');
    if (digits < 0) text.insert(text.begin(), '-');
    const std::string product = std::to_string(digits * 254) + "e" + std::to_string(-k - 4);
    SCOPED_TRACE(text);
    const auto v = parse_number_scaled(text, cal::drivers::codec::kInchesToMetres);
    ASSERT_TRUE(v);
    ASSERT_EQ(bits(*v), bits(std::strtod(product.c_str(), nullptr)));
  }
  // Beyond the exact fast path (the digits x 254 over 2^53): the same, by the general reader.
  EXPECT_EQ(parse_number_scaled("123456789012345.678", cal::drivers::codec::kInchesToMetres),
            std::strtod("31358024409135802.212e-4", nullptr));
}

TEST(ScaledDecimal, CountsAreTheirDecimalsInSi) {
  // Picometre counts: n / 10^12 correctly rounded, within 2^53 and beyond (int64's ends).
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<std::int64_t> small(-10'000'000'000'000, 10'000'000'000'000);
  std::uniform_int_distribution<std::int64_t> any(INT64_MIN, INT64_MAX);
  std::size_t product_missed = 0;
  for (int i = 0; i < 200'000; ++i) {
    const std::int64_t n = i % 4 == 3 ? any(rng) : small(rng);
    SCOPED_TRACE(n);
    const double v = scaled_count(n, kPm);
    ASSERT_EQ(bits(v), bits(codec_test::strtod_shifted(std::to_string(n), -12)));
    product_missed += v != static_cast<double>(n) * 1e-12;
  }
  for (const std::int64_t n :
       {INT64_MIN, INT64_MAX, std::int64_t{0}, std::int64_t{1} << 53, -(std::int64_t{1} << 53) - 1})
    EXPECT_EQ(bits(scaled_count(n, kPm)), bits(codec_test::strtod_shifted(std::to_string(n), -12)))
        << n;
  EXPECT_GT(product_missed, 200'000u / 20);  // n x 1e-12 misses about 14 %
}

TEST(ScaledDecimal, DoublesThatStandForShortDecimalsGiveThoseDecimalsInSi) {
  // A float64 sample nearest to a 1 nm reading in mm (what a vendor's file would hold): its
  // shortest form is the decimal, so the result is the decimal in metres. x / 1e3 misses a
  // quarter of them (two roundings).
  std::mt19937_64 rng(11);
  std::uniform_int_distribution<std::int64_t> nm(-2'000'000'000, 2'000'000'000);
  std::size_t division_missed = 0;
  for (int i = 0; i < 200'000; ++i) {
    const std::string text = std::to_string(nm(rng)) + "e-6";  // mm
    const double sample = std::strtod(text.c_str(), nullptr);
    SCOPED_TRACE(text);
    const double v = scaled_double(sample, kMm);
    ASSERT_EQ(bits(v), bits(codec_test::strtod_shifted(text, -3)));
    division_missed += v != sample / 1e3;
  }
  EXPECT_GT(division_missed, 200'000u / 10);
  // No short decimal (17 digits): x's own value divided by the exact 1e3.
  const double third = 1.0 / 3.0;
  EXPECT_EQ(scaled_double(third, kMm), third / 1e3);
  EXPECT_EQ(scaled_double(0.1, kM), 0.1);
  EXPECT_TRUE(std::isinf(scaled_double(INFINITY, kMm)));
}

}  // namespace
