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

// The general loop, a digit at a time, counting significant digits (long strings).
inline bool parse_plain_decimal_long(const char* p, const char* end, bool negative, double& out) {
  std::uint64_t m = 0;
  int significant = 0, fraction = 0;
  bool any_digit = false, point = false;
  for (; p != end; ++p) {
    const unsigned d = static_cast<unsigned>(*p) - '0';
    if (d < 10) {
      any_digit = true;
      // Leading zeros add nothing to m; 19 significant digits always fit in 64 bits.
      if ((m != 0 || d != 0) && ++significant > 19) return false;
      m = m * 10 + d;
      if (point) ++fraction;
    } else if (*p == '.' && !point) {
      point = true;
    } else {
      return false;
    }
  }
  if (!any_digit || m > kMaxExact || fraction > 22) return false;
  const double v = static_cast<double>(m) / kPow10[fraction];
  out = negative ? -v : v;
  return true;
}

}  // namespace detail

// Parses the whole of `s` as [+-]digits[.digits] (at least one digit, either side of the point
// may be empty) into `out`; false (out untouched) when `s` is not of that form or outside the
// exact range above, in which case the caller must use the general parser.
inline bool parse_plain_decimal(std::string_view s, double& out) {
  const char* p = s.data();
  const char* const end = p + s.size();
  bool negative = false;
  if (p != end && (*p == '+' || *p == '-')) negative = *p++ == '-';
  // At most 19 characters: at most 19 digits, which always fit in 64 bits, so the digits need
  // no counting; two plain loops (integer digits, fraction digits) with one multiply-add each.
  if (end - p > 19) return detail::parse_plain_decimal_long(p, end, negative, out);
  const char* const int_begin = p;
  std::uint64_t m = 0;
  for (; p != end && detail::is_digit(*p); ++p) m = m * 10 + static_cast<unsigned>(*p - '0');
  const auto n_int = p - int_begin;
  std::ptrdiff_t n_frac = 0;
  if (p != end) {
    if (*p != '.') return false;
    const char* const frac_begin = ++p;
    for (; p != end && detail::is_digit(*p); ++p) m = m * 10 + static_cast<unsigned>(*p - '0');
    if (p != end) return false;
    n_frac = p - frac_begin;
  }
  if (n_int + n_frac == 0 || m > detail::kMaxExact) return false;
  const double v = static_cast<double>(m) / detail::kPow10[n_frac];
  out = negative ? -v : v;
  return true;
}

}  // namespace cal::drivers::codec
