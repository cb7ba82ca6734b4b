#pragma once
// An exact fast path for the plain decimal numbers that gauges and environmental stations
// print ("+012.3456", "-0.00125", "1013.25"): the digits are read into an integer m and the
// value is m / 10^k with k the number of fraction digits, computed as ONE IEEE division.
//
// Why that is exact (Clinger's fast path, W. D. Clinger, "How to read floating point numbers
// accurately", PLDI 1990; the same test opens fast_float, which libstdc++'s from_chars uses):
// when m <= 2^53 and k <= 22 both m and 10^k are exactly representable doubles, and IEEE 754
// division returns the correctly rounded (round to nearest, ties to even) quotient of two exact
// operands, i.e. the correctly rounded value of the decimal string itself, which is also what
// std::from_chars must return. So the result is bit for bit the one from_chars gives, -0.0
// included. Anything outside that (more than 19 significant digits, m > 2^53, more than 22 fraction
// digits, an exponent, inf/nan, a second sign, no digit) is not taken: the caller falls back to
// from_chars. tests/drivers/decimal_test.cpp compares the two over random and edge inputs.
//
// The same argument gives a printed reading straight in SI (parse_plain_decimal_scaled): a
// gauge's "100.000123" mm is 100000123 / 10^9 m, one division of exact operands, so the stored
// double is the correctly rounded value of 0.100000123 itself, what strtod("100.000123e-3")
// gives. Reading the mm first and then multiplying by 1e-3 rounds twice (1e-3 is not a double)
// and leaves 14-33 % of readings one ulp off (0.10000012300000001).
#include <cstdint>
#include <string_view>

namespace cal::drivers::codec {

namespace detail {

// 10^0 .. 10^22: every one an exact double (10^22 = 2^22 * 5^22 and 5^22 < 2^53).
inline constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                    1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                    1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
inline constexpr std::uint64_t kMaxExact = std::uint64_t{1} << 53;

inline bool is_digit(char c) { return static_cast<unsigned>(c) - '0' < 10; }

}  // namespace detail

// An exact factor to SI: multiplier x 10^exponent, both exact (mm {1, -3}, inch {254, -4}
// (25.4 mm by the 1959 definition), hPa {1, 2}). A reading x the factor is a decimal again, so
// it has one correctly rounded double: the scaled readers below give that double.
struct DecimalScale {
  std::uint32_t multiplier = 1;
  int exponent = 0;
  bool operator==(const DecimalScale&) const = default;
};
inline constexpr DecimalScale kUnitScale{1, 0};
inline constexpr DecimalScale kMillimetresToMetres{1, -3};
inline constexpr DecimalScale kMicrometresToMetres{1, -6};
inline constexpr DecimalScale kPicometresToMetres{1, -12};
inline constexpr DecimalScale kInchesToMetres{254, -4};
inline constexpr DecimalScale kHectopascalsToPascals{1, 2};

namespace detail {

// m x multiplier x 10^(exponent - fraction) as one correctly rounded IEEE operation of exact
// operands (m x multiplier <= 2^53; the power of ten 10^0 .. 10^22); false when not exact.
inline bool scale_exact(std::uint64_t m, int fraction, bool negative, DecimalScale scale,
                        double& out) {
  if (scale.multiplier != 1) {
    if (scale.multiplier == 0 || m > kMaxExact / scale.multiplier) return false;
    m *= scale.multiplier;
  }
  if (m > kMaxExact) return false;
  const int p = fraction - scale.exponent;  // the value is m / 10^p
  double v;
  if (p >= 0 && p <= 22)
    v = static_cast<double>(m) / kPow10[p];
  else if (p < 0 && p >= -22)
    v = static_cast<double>(m) * kPow10[-p];  // one rounding of an exact product
  else
    return false;
  out = negative ? -v : v;
  return true;
}

// The digits of [+-]digits[.digits] as m (at most 19 significant digits) and the count of
// fraction digits; false when `s` is not of that form. Up to 19 characters there are at most 19
// digits, which always fit in 64 bits: two plain loops (integer digits, fraction digits) with one
// multiply-add each; a longer string a digit at a time, counting significant digits (leading
// zeros add nothing to m).
inline bool plain_decimal_digits(std::string_view s, std::uint64_t& m, int& fraction,
                                 bool& negative) {
  const char* p = s.data();
  const char* const end = p + s.size();
  negative = false;
  if (p != end && (*p == '+' || *p == '-')) negative = *p++ == '-';
  m = 0;
  fraction = 0;
  if (end - p <= 19) {
    const char* const int_begin = p;
    for (; p != end && is_digit(*p); ++p) m = m * 10 + static_cast<unsigned>(*p - '0');
    const auto n_int = p - int_begin;
    if (p != end) {
      if (*p != '.') return false;
      const char* const frac_begin = ++p;
      for (; p != end && is_digit(*p); ++p) m = m * 10 + static_cast<unsigned>(*p - '0');
      if (p != end) return false;
      fraction = static_cast<int>(p - frac_begin);
    }
    return n_int + fraction > 0;
  }
  int significant = 0;
  bool any_digit = false, point = false;
  for (; p != end; ++p) {
    const unsigned d = static_cast<unsigned>(*p) - '0';
    if (d < 10) {
      any_digit = true;
      if ((m != 0 || d != 0) && ++significant > 19) return false;
      m = m * 10 + d;
      if (point && ++fraction > 400) return false;
    } else if (*p == '.' && !point) {
      point = true;
    } else {
      return false;
    }
  }
  return any_digit;
}

}  // namespace detail

// parse_plain_decimal's form and fast path, the value times `scale`: the correctly rounded
// double of the printed decimal in SI ("100.000123" with kMillimetresToMetres is
// strtod("100.000123e-3")); false (out untouched) outside the exact range, for
// parse_number_scaled's general reader.
inline bool parse_plain_decimal_scaled(std::string_view s, DecimalScale scale, double& out) {
  std::uint64_t m = 0;
  int fraction = 0;
  bool negative = false;
  if (!detail::plain_decimal_digits(s, m, fraction, negative)) return false;
  return detail::scale_exact(m, fraction, negative, scale, out);
}

// Parses the whole of `s` as [+-]digits[.digits] (at least one digit, either side of the point
// may be empty) into `out`; false (out untouched) when `s` is not of that form or outside the
// exact range above (m <= 2^53, at most 22 fraction digits), in which case the caller must use
// the general parser. The same reader as parse_plain_decimal_scaled with no scale.
inline bool parse_plain_decimal(std::string_view s, double& out) {
  return parse_plain_decimal_scaled(s, kUnitScale, out);
}

// An integer count (picometres) in SI: n x scale correctly rounded (n / 10^12 for pm: one
// division of exact operands for |n| <= 2^53; beyond, the decimal's digits read by from_chars).
double scaled_count(std::int64_t n, DecimalScale scale);

}  // namespace cal::drivers::codec
