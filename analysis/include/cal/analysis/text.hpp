#pragma once
// Text from outside (files, devices, stored runs) checked and shown safely. Like crc32c.hpp,
// not metrology, but analysis/ is the library everything depends on. No I/O.
//
// - UTF-8: every text input is UTF-8; where it is not, the reader says where (file, line, byte),
//   or converts from the code page a format states (windows1252_to_utf8).
// - Terminal output: a stored name could hold ESC sequences that rewrite the operator's screen
//   (or a title bar, or the clipboard through OSC 52); terminal_safe() is applied to every
//   stored or foreign string a command prints as text.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace cal::text {

// The offset of the first byte of `s` that is not part of well-formed UTF-8 (RFC 3629: no
// overlong forms, no surrogates, nothing above U+10FFFF), or nullopt if all of it is.
std::optional<std::size_t> invalid_utf8_at(std::string_view s);

// Throws InputError "WHERE: line L, byte B: not UTF-8 text (byte 0xNN)" if `s` is not UTF-8;
// B counts from the start of `s` plus `first_byte` (where `s` starts in its file), L from
// `first_line`.
void require_utf8(std::string_view s, std::string_view where, std::size_t first_line = 1,
                  std::size_t first_byte = 0);

// Windows-1252 (the Western code page of Windows) as UTF-8; the five bytes it leaves undefined
// (0x81, 0x8D, 0x8F, 0x90, 0x9D) become U+FFFD.
std::string windows1252_to_utf8(std::string_view s);

// `s` for a terminal: control characters (C0, DEL, C1), the bidirectional overrides and
// isolates (U+202A..U+202E, U+2066..U+2069) and bytes that are not UTF-8 escaped as \n, \t,
// \xNN or \u{NNNN}, and the backslash as \\ so that an escape cannot be forged; printable
// text (any script) unchanged.
std::string terminal_safe(std::string_view s);

// A Unix time in whole seconds as UTC text by a strftime(3) format, e.g. "%Y-%m-%dT%H:%M:%SZ"
// (at most 31 characters of text).
std::string utc_text(std::int64_t unix_s, const char* strftime_format);

}  // namespace cal::text
