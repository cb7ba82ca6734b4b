// Text checked and shown safely (see text.hpp).
#include "cal/analysis/text.hpp"

#include <fmt/format.h>

#include <array>
#include <cstdint>
#include <ctime>

#include "cal/analysis/error.hpp"

namespace cal::text {
namespace {

// The length of the well-formed UTF-8 sequence at s[i] and its code point, or 0.
std::size_t sequence_at(std::string_view s, std::size_t i, char32_t& cp) {
  const auto b = [&](std::size_t k) { return static_cast<unsigned char>(s[i + k]); };
  const auto cont = [&](std::size_t k) { return i + k < s.size() && (b(k) & 0xC0) == 0x80; };
  const unsigned char c = b(0);
  if (c < 0x80) return cp = c, 1;
  std::size_t n = 0;
  char32_t min = 0;
  if ((c & 0xE0) == 0xC0)
    n = 2, cp = c & 0x1F, min = 0x80;
  else if ((c & 0xF0) == 0xE0)
    n = 3, cp = c & 0x0F, min = 0x800;
  else if ((c & 0xF8) == 0xF0)
    n = 4, cp = c & 0x07, min = 0x10000;
  else
    return 0;
  for (std::size_t k = 1; k < n; ++k) {
    if (!cont(k)) return 0;
    cp = (cp << 6) | (b(k) & 0x3F);
  }
  if (cp < min || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF)) return 0;
  return n;
}

void append_utf8(std::string& out, char32_t cp) {
  if (cp < 0x80) {
    out += static_cast<char>(cp);
  } else if (cp < 0x800) {
    out += static_cast<char>(0xC0 | (cp >> 6));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  } else {
    out += static_cast<char>(0xE0 | (cp >> 12));
    out += static_cast<char>(0x80 | ((cp >> 6) & 0x3F));
    out += static_cast<char>(0x80 | (cp & 0x3F));
  }
}

bool is_bidi_control(char32_t cp) {
  return (cp >= 0x202A && cp <= 0x202E) || (cp >= 0x2066 && cp <= 0x2069);
}

}  // namespace

std::optional<std::size_t> invalid_utf8_at(std::string_view s) {
  char32_t cp = 0;
  for (std::size_t i = 0; i < s.size();) {
    const std::size_t n = sequence_at(s, i, cp);
    if (n == 0) return i;
    i += n;
  }
  return std::nullopt;
}

void require_utf8(std::string_view s, std::string_view where, std::size_t first_line,
                  std::size_t first_byte) {
  const auto at = invalid_utf8_at(s);
  if (!at) return;
  std::size_t line = first_line;
  for (std::size_t i = 0; i < *at; ++i) line += s[i] == '\n';
  throw InputError(fmt::format("{}: line {}, byte {}: not UTF-8 text (byte 0x{:02X})", where, line,
                               first_byte + *at, static_cast<unsigned char>(s[*at])));
}

std::string windows1252_to_utf8(std::string_view s) {
  // 0x80..0x9F; the rest of the upper half is Latin-1 (U+00A0..U+00FF).
  static constexpr std::array<char32_t, 32> kHigh{
      0x20AC, 0xFFFD, 0x201A, 0x0192, 0x201E, 0x2026, 0x2020, 0x2021, 0x02C6, 0x2030, 0x0160,
      0x2039, 0x0152, 0xFFFD, 0x017D, 0xFFFD, 0xFFFD, 0x2018, 0x2019, 0x201C, 0x201D, 0x2022,
      0x2013, 0x2014, 0x02DC, 0x2122, 0x0161, 0x203A, 0x0153, 0xFFFD, 0x017E, 0x0178};
  std::string out;
  out.reserve(s.size() + s.size() / 4);
  for (unsigned char c : s)
    append_utf8(out, c >= 0x80 && c < 0xA0 ? kHigh[c - 0x80] : static_cast<char32_t>(c));
  return out;
}

std::string terminal_safe(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  char32_t cp = 0;
  for (std::size_t i = 0; i < s.size();) {
    const std::size_t n = sequence_at(s, i, cp);
    if (n == 0) {
      out += fmt::format("\\x{:02X}", static_cast<unsigned char>(s[i]));
      ++i;
      continue;
    }
    if (cp == '\\')
      out += "\\\\";
    else if (cp == '\n')
      out += "\\n";
    else if (cp == '\t')
      out += "\\t";
    else if (cp < 0x20 || cp == 0x7F)
      out += fmt::format("\\x{:02X}", static_cast<unsigned>(cp));
    else if ((cp >= 0x80 && cp < 0xA0) || is_bidi_control(cp))
      out += fmt::format("\\u{{{:04X}}}", static_cast<unsigned>(cp));
    else
      out.append(s.substr(i, n));
    i += n;
  }
  return out;
}

std::string utc_text(std::int64_t unix_s, const char* strftime_format) {
  const auto t = static_cast<std::time_t>(unix_s);
  std::tm tm{};
  gmtime_r(&t, &tm);
  std::array<char, 32> buf{};
  const auto n = std::strftime(buf.data(), buf.size(), strftime_format, &tm);
  return std::string(buf.data(), n);
}

}  // namespace cal::text
