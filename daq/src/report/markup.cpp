#include "report/markup.hpp"

#include <fmt/format.h>

#include <cstdint>

namespace cal::daq::report {
namespace {

constexpr char32_t replacement = 0xFFFD;

// The next code point of UTF-8 text at `at` (advanced past it); a byte that does not start a
// well-formed sequence (overlong, surrogate, beyond U+10FFFF, truncated) gives U+FFFD and is
// skipped alone.
char32_t next_code_point(std::string_view s, std::size_t& at) {
  const auto byte = [&](std::size_t i) { return static_cast<std::uint8_t>(s[i]); };
  const std::uint8_t b0 = byte(at);
  if (b0 < 0x80) return ++at, b0;
  const int length = b0 >= 0xF0 ? 4 : b0 >= 0xE0 ? 3 : b0 >= 0xC0 ? 2 : 0;
  if (length == 0 || b0 > 0xF4 || at + static_cast<std::size_t>(length) > s.size())
    return ++at, replacement;
  char32_t cp = b0 & (0x7F >> length);
  for (int k = 1; k < length; ++k) {
    const std::uint8_t b = byte(at + static_cast<std::size_t>(k));
    if ((b & 0xC0) != 0x80) return ++at, replacement;
    cp = (cp << 6) | (b & 0x3F);
  }
  constexpr char32_t least[] = {0, 0, 0x80, 0x800, 0x10000};
  if (cp < least[length] || cp > 0x10FFFF || (cp >= 0xD800 && cp <= 0xDFFF))
    return ++at, replacement;
  at += static_cast<std::size_t>(length);
  return cp;
}

bool plain(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == ' ';
}

}  // namespace

std::string html_text(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    switch (c) {
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '&':
        out += "&amp;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string html_attribute(std::string_view s) { return html_text(s); }

std::string css_string(std::string_view s) {
  std::string out = "\"";
  bool after_escape = false;
  for (std::size_t at = 0; at < s.size();) {
    // CSS takes one white space after a hex escape as the escape's end (even after six
    // digits), so a space there is escaped too, or it would vanish.
    if (plain(s[at]) && !(after_escape && s[at] == ' ')) {
      out += s[at++];
      after_escape = false;
      continue;
    }
    after_escape = true;
    char32_t cp = next_code_point(s, at);
    if (cp == 0) cp = replacement;  // CSS reads \0 as U+FFFD too; say so
    // Six digits: the escape ends there, whatever follows (no terminating space needed).
    out += fmt::format("\\{:06X}", static_cast<std::uint32_t>(cp));
  }
  return out + "\"";
}

std::string plot_text(std::string_view s) {
  std::string out;
  out.reserve(s.size());
  for (char c : s) {
    if (c == '#') {
      out += "##";
    } else if (static_cast<unsigned char>(c) >= 0x20 && c != 0x7F) {
      out += c;
    }
  }
  return out;
}

std::string csp_meta() {
  // A constant of this file, not data: its single quotes need no escaping in a "..." value.
  return fmt::format("<meta http-equiv=\"Content-Security-Policy\" content=\"{}\">",
                     content_security_policy);
}

}  // namespace cal::daq::report
