#include "cal/drivers/codec/common.hpp"

#include <algorithm>
#include <charconv>

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
