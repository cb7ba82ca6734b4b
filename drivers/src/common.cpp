#include "cal/drivers/codec/common.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>

#include "cal/analysis/enum_names.hpp"
#include "cal/drivers/codec/decimal.hpp"

namespace cal::drivers::codec {

std::string_view to_string(ErrorKind kind) {
  using enum ErrorKind;
  // clang-format off
  static constexpr EnumName<ErrorKind> kNames[] = {
      {garbage, "garbage"}, {overlong_line, "overlong_line"}, {bad_checksum, "bad_checksum"},
      {out_of_range, "out_of_range"}, {malformed, "malformed"}};
  // clang-format on
  static_assert(cal::names_every_value(kNames));
  return name_of(kNames, kind, "unknown");
}

std::uint64_t CodecStats::count(ErrorKind kind) const {
  switch (kind) {
    case ErrorKind::garbage:
      return garbage;
    case ErrorKind::overlong_line:
      return overlong_line;
    case ErrorKind::bad_checksum:
      return bad_checksum;
    case ErrorKind::out_of_range:
      return out_of_range;
    case ErrorKind::malformed:
      return malformed;
  }
  return 0;
}

std::uint64_t CodecStats::errors() const {
  return garbage + overlong_line + bad_checksum + out_of_range + malformed;
}

void CodecStats::add(ErrorKind kind) {
  switch (kind) {
    case ErrorKind::garbage:
      ++garbage;
      break;
    case ErrorKind::overlong_line:
      ++overlong_line;
      break;
    case ErrorKind::bad_checksum:
      ++bad_checksum;
      break;
    case ErrorKind::out_of_range:
      ++out_of_range;
      break;
    case ErrorKind::malformed:
      ++malformed;
      break;
  }
}

LineSplitter::LineSplitter(std::size_t max_line_bytes) : max_line_bytes_(max_line_bytes) {}

bool is_printable_ascii(std::string_view line) {
  return std::all_of(line.begin(), line.end(), [](char c) {
    const auto u = static_cast<unsigned char>(c);
    return u == '\t' || (u >= 0x20 && u < 0x7f);
  });
}

std::optional<double> parse_number(std::string_view s) {
  // The exact fast path (decimal.hpp) for the plain numbers instruments print: the same double
  // as from_chars, at a fraction of its cost on a 10 kHz stream.
  if (double v; parse_plain_decimal(s, v)) return v;
  // from_chars refuses a leading '+'; a second sign after it ("+-1") must stay an error.
  if (!s.empty() && s.front() == '+') {
    s.remove_prefix(1);
    if (!s.empty() && (s.front() == '-' || s.front() == '+')) return std::nullopt;
  }
  if (s.empty()) return std::nullopt;
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc() || ptr != s.data() + s.size()) return std::nullopt;
  return v;
}

namespace {

// "digits" x multiplier, as decimal digits (schoolbook, the last digit first).
// The carry stays below the multiplier: 9 x 2^32 + 2^32 fits in 64 bits.
std::string times(std::string digits, std::uint32_t multiplier) {
  if (multiplier == 1) return digits;
  std::uint64_t carry = 0;
  for (auto it = digits.rbegin(); it != digits.rend(); ++it) {
    carry += static_cast<std::uint64_t>(*it - '0') * multiplier;
    *it = static_cast<char>('0' + static_cast<unsigned>(carry % 10));
    carry /= 10;
  }
  std::string head;
  for (; carry != 0; carry /= 10) head.insert(head.begin(), static_cast<char>('0' + carry % 10));
  return head + digits;
}

// 10^n, exact for 0 <= n <= 22.
double power_of_ten(int n) { return n >= 0 && n <= 22 ? detail::kPow10[n] : std::pow(10.0, n); }

}  // namespace

std::optional<double> parse_number_scaled(std::string_view s, DecimalScale scale) {
  if (double v; parse_plain_decimal_scaled(s, scale, v)) return v;
  // General: [+-]digits[.digits][(e|E)[+-]digits] as its digits and a power of ten, the
  // multiplier applied to the digits exactly, the exponent moved, and the result read by
  // from_chars (correctly rounded, whatever the length).
  std::string_view t = s;
  bool negative = false;
  if (!t.empty() && (t.front() == '+' || t.front() == '-')) {
    negative = t.front() == '-';
    t.remove_prefix(1);
  }
  std::string digits;
  std::int64_t exponent = scale.exponent;
  bool point = false;
  std::size_t i = 0;
  for (; i < t.size(); ++i) {
    const char c = t[i];
    if (c >= '0' && c <= '9') {
      if (!(digits.empty() && c == '0')) digits += c;  // leading zeros add nothing
      if (point) --exponent;
    } else if (c == '.' && !point) {
      point = true;
    } else {
      break;
    }
  }
  const std::string_view mantissa = t.substr(0, i);
  const bool any_digit = mantissa.find_first_of("0123456789") != std::string_view::npos;
  if (any_digit && i < t.size() && (t[i] == 'e' || t[i] == 'E')) {
    std::size_t j = i + 1;
    bool exp_negative = false;
    if (j < t.size() && (t[j] == '+' || t[j] == '-')) exp_negative = t[j++] == '-';
    std::int64_t e = 0;
    const std::size_t exp_digits = j;
    for (; j < t.size() && t[j] >= '0' && t[j] <= '9'; ++j)
      e = std::min<std::int64_t>(e * 10 + (t[j] - '0'), 1'000'000);  // saturated: out of range
    if (j == exp_digits) return std::nullopt;  // "1e": what from_chars leaves over
    exponent += exp_negative ? -e : e;
    i = j;
  }
  if (!any_digit || i != t.size()) {
    // Not a decimal: inf, nan (or nothing at all): as parse_number reads it, unscaled (a
    // positive factor leaves them as they are).
    const auto v = parse_number(s);
    if (v && std::isfinite(*v)) return std::nullopt;  // unreachable: every finite form is above
    return v;
  }
  if (digits.empty()) return negative ? -0.0 : 0.0;
  const std::string text = fmt::format("{}{}e{}", negative ? "-" : "",
                                       times(std::move(digits), scale.multiplier), exponent);
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (ec != std::errc{} || ptr != text.data() + text.size()) return std::nullopt;
  return v;
}

double scaled_count(std::int64_t n, DecimalScale scale) {
  if (double v; n > -static_cast<std::int64_t>(detail::kMaxExact) &&
                n < static_cast<std::int64_t>(detail::kMaxExact) &&
                detail::scale_exact(static_cast<std::uint64_t>(n < 0 ? -n : n), 0, n < 0, scale, v))
    return v;
  char buf[24];
  const auto end = std::to_chars(buf, buf + sizeof buf, n).ptr;
  return parse_number_scaled(std::string_view(buf, static_cast<std::size_t>(end - buf)), scale)
      .value_or(static_cast<double>(n) * static_cast<double>(scale.multiplier) *
                power_of_ten(scale.exponent));  // only beyond the double's range
}

double scaled_double(double x, DecimalScale scale) {
  if (scale == kUnitScale || !std::isfinite(x)) return x;
  char buf[32];
  const auto end = std::to_chars(buf, buf + sizeof buf, x).ptr;  // shortest round trip
  const std::string_view shortest(buf, static_cast<std::size_t>(end - buf));
  std::size_t significant = 0;
  bool leading = true;
  for (const char c : shortest) {
    if (c == 'e') break;
    if (c < '0' || c > '9' || (leading && c == '0')) continue;
    leading = false;
    ++significant;
  }
  if (significant <= 15)
    if (const auto v = parse_number_scaled(shortest, scale)) return *v;
  // No short decimal (binary data, 16-17 digits): x's own value times the factor, the power
  // of ten applied by one correctly rounded division or product.
  const double m = x * static_cast<double>(scale.multiplier);
  return scale.exponent < 0 ? m / power_of_ten(-scale.exponent) : m * power_of_ten(scale.exponent);
}

namespace {
// A plain test per byte: string_view::find_first_of with a set calls memchr on the set for
// every byte of the line, which costs more than the parsing on a 10 kHz stream.
bool blank(char c) { return c == ' ' || c == '\t'; }
}  // namespace

std::size_t split_whitespace(std::string_view s, std::span<std::string_view> out) {
  std::size_t count = 0, i = 0;
  const std::size_t n = s.size();
  while (true) {
    while (i < n && blank(s[i])) ++i;
    if (i == n) break;
    const std::size_t start = i;
    while (i < n && !blank(s[i])) ++i;
    if (count < out.size()) out[count] = s.substr(start, i - start);
    ++count;
  }
  return count;
}

std::vector<std::string_view> split_whitespace(std::string_view s) {
  std::vector<std::string_view> out(split_whitespace(s, {}));
  split_whitespace(s, out);
  return out;
}

}  // namespace cal::drivers::codec
