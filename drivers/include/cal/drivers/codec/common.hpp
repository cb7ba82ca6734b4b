#pragma once
// The common shape of every codec (see docs/codecs.md): a pure function object, bytes in,
// typed frames out; no I/O, no clock, no threads, no exceptions on bad bytes. Each bad input
// is counted in CodecStats and reported as a CodecError event (kind, stream offset, text) so
// the instrument layer can log it; the codec then resynchronises and carries on.
#include <algorithm>
#include <bit>
#include <charconv>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cal/drivers/codec/decimal.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

namespace cal::drivers::codec {

enum class ErrorKind {
  garbage,        // bytes that cannot belong to the protocol (control characters, ...)
  overlong_line,  // no terminator within the bounded line buffer: dropped up to the next one
  bad_checksum,   // the frame's checksum does not match its bytes
  out_of_range,   // a well-formed value outside its plausible range (or flagged invalid)
  malformed,      // well-formed bytes that do not parse as a frame of the protocol
};
std::string_view to_string(ErrorKind kind);

struct CodecError {
  ErrorKind kind = ErrorKind::malformed;
  std::uint64_t offset = 0;  // byte offset in the stream of the start of the offending frame
  std::string description;
};

struct CodecStats {
  std::uint64_t frames = 0;  // frames emitted
  std::uint64_t bytes = 0;   // bytes fed
  std::uint64_t garbage = 0;
  std::uint64_t overlong_line = 0;
  std::uint64_t bad_checksum = 0;
  std::uint64_t out_of_range = 0;
  std::uint64_t malformed = 0;

  std::uint64_t count(ErrorKind kind) const;
  std::uint64_t errors() const;
  void add(ErrorKind kind);
  bool operator==(const CodecStats&) const = default;
};

inline std::span<const std::byte> as_bytes(std::string_view s) {
  return std::as_bytes(std::span<const char>(s.data(), s.size()));
}
inline std::string_view as_chars(std::span<const std::byte> b) {
  return {reinterpret_cast<const char*>(b.data()), b.size()};
}

// Base of the codecs (CRTP): the overloads of feed() and the stats/error bookkeeping. The
// derived class implements do_feed(bytes, frames, errors).
template <class Derived, class FrameT>
class CodecBase {
 public:
  using Frame = FrameT;

  // Decodes `bytes` (any chunk of the stream: frames may be split at any byte), appending
  // complete frames to `frames` and one event per error to `errors`.
  void feed(std::span<const std::byte> bytes, std::vector<Frame>& frames,
            std::vector<CodecError>& errors) {
    stats_.bytes += bytes.size();
    static_cast<Derived*>(this)->do_feed(bytes, frames, errors);
  }
  void feed(std::string_view bytes, std::vector<Frame>& frames, std::vector<CodecError>& errors) {
    feed(as_bytes(bytes), frames, errors);
  }
  // The same, for callers that only want the counts of errors (in stats()).
  void feed(std::span<const std::byte> bytes, std::vector<Frame>& frames) {
    scratch_errors_.clear();
    feed(bytes, frames, scratch_errors_);
  }
  void feed(std::string_view bytes, std::vector<Frame>& frames) { feed(as_bytes(bytes), frames); }

  const CodecStats& stats() const { return stats_; }

 protected:
  void report(std::vector<CodecError>& errors, ErrorKind kind, std::uint64_t offset,
              std::string description) {
    stats_.add(kind);
    errors.push_back({kind, offset, std::move(description)});
  }
  void emit(std::vector<Frame>& frames, Frame&& frame) {
    ++stats_.frames;
    frames.push_back(std::move(frame));
  }
  // For a codec's own frame-less fast path (bytes in, values to a callback).
  void count_bytes(std::size_t n) { stats_.bytes += n; }
  void count_frame() { ++stats_.frames; }

 private:
  CodecStats stats_;
  std::vector<CodecError> scratch_errors_;
};

// Splits a byte stream into lines with a bounded buffer. Any CR or LF ends a line (so LF,
// CR-LF and CR-only devices all work) and empty lines are skipped. A line longer than
// max_line_bytes is reported once through on_overlong(start_offset) and discarded up to the
// next terminator, where the splitter resynchronises.
//
// Cost: the terminators (CR or LF) are found 16 bytes per compare (SSE2; a byte loop for a
// chunk's tail and without SSE2), each search starting after the last terminator; a CR-LF pair
// ends its line in one step; a line that lies wholly inside one chunk is handed to on_line in
// place; only a line split across chunks is copied into the buffer.
class LineSplitter {
 public:
  static constexpr std::size_t default_max_line_bytes = 4096;
  explicit LineSplitter(std::size_t max_line_bytes = default_max_line_bytes);

  template <class OnLine, class OnOverlong>
  void feed(std::span<const std::byte> bytes, OnLine&& on_line, OnOverlong&& on_overlong) {
    const std::string_view chars = as_chars(bytes);
    const std::size_t n = chars.size();
    std::size_t i = 0;
    while (i < n) {
      const std::size_t eol = next_terminator(chars.data(), i, n);
      if (eol == n) {  // no terminator: the line continues in the next chunk
        append(chars.substr(i), on_overlong);
        offset_ += n - i;
        break;
      }
      const std::string_view piece = chars.substr(i, eol - i);
      if (buffer_.empty() && !discarding_) {
        if (piece.size() > max_line_bytes_)
          on_overlong(line_start_);
        else if (!piece.empty())
          on_line(piece, line_start_);
      } else {
        append(piece, on_overlong);
        if (!discarding_ && !buffer_.empty()) on_line(std::string_view(buffer_), line_start_);
      }
      buffer_.clear();
      discarding_ = false;
      // The LF of a CR-LF pair goes with its CR: alone it would end an empty line, skipped.
      std::size_t next = eol + 1;
      if (chars[eol] == '\r' && next < n && chars[next] == '\n') ++next;
      offset_ += next - i;
      line_start_ = offset_;
      i = next;
    }
  }

 private:
  // The first CR or LF in s[from, n), or n.
  static std::size_t next_terminator(const char* s, std::size_t from, std::size_t n) {
#if defined(__SSE2__)
    const __m128i cr = _mm_set1_epi8('\r'), lf = _mm_set1_epi8('\n');
    for (; from + 16 <= n; from += 16) {
      const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(s + from));
      const int hits =
          _mm_movemask_epi8(_mm_or_si128(_mm_cmpeq_epi8(v, cr), _mm_cmpeq_epi8(v, lf)));
      if (hits != 0)
        return from + static_cast<std::size_t>(std::countr_zero(static_cast<unsigned>(hits)));
    }
#endif
    for (; from < n; ++from)
      if (s[from] == '\r' || s[from] == '\n') return from;
    return n;
  }
  template <class OnOverlong>
  void append(std::string_view piece, OnOverlong& on_overlong) {
    if (discarding_) return;
    if (buffer_.size() + piece.size() > max_line_bytes_) {
      discarding_ = true;
      buffer_.clear();
      on_overlong(line_start_);
      return;
    }
    buffer_.append(piece);
  }

  std::size_t max_line_bytes_;
  std::string buffer_;
  bool discarding_ = false;
  std::uint64_t offset_ = 0;      // stream offset of the next byte fed
  std::uint64_t line_start_ = 0;  // stream offset of the first byte of the current line
};

// True if every byte is printable ASCII or a tab: the line can belong to a text protocol.
bool is_printable_ascii(std::string_view line);

// Parses the whole of `s` as a decimal number (a leading '+' is allowed, as gauges print it);
// nullopt if anything is left over or nothing is a number.
std::optional<double> parse_number(std::string_view s);

// The same number in another unit by an exact factor (docs/codecs.md, "Readings in SI"):
// the correctly rounded double of the printed decimal times `scale`, as strtod reads the decimal
// with its exponent moved ("100.000123" in mm to m is strtod("100.000123e-3")), never the
// printed value times an inexact 1e-3. inf and nan are returned as parse_number reads them;
// nullopt where parse_number gives nullopt, and for a result beyond the double's range.
std::optional<double> parse_number_scaled(std::string_view s, DecimalScale scale);

// A double that stands for a decimal (a float64 sample a vendor's software wrote, a JSON number
// already parsed) in another unit: when its shortest round-trip decimal (std::to_chars) has at
// most 15 significant digits, that decimal times `scale`, correctly rounded. A double nearest
// to a decimal of at most 15 significant digits has that decimal as its shortest form, so the
// result is the decimal's own value in SI (x / 1e3 rounds twice and misses it for about a
// quarter of 1 nm readings in mm). A double with no such decimal (16-17 digits: binary data)
// is x x multiplier, then divided (or multiplied) by the exact power of ten.
double scaled_double(double x, DecimalScale scale);

// Parses the whole of `s` as an integer of type Int (no leading '+'); nullopt if anything is
// left over, nothing is a number, or it does not fit.
template <class Int>
std::optional<Int> parse_integer(std::string_view s) {
  Int v{};
  const auto [p, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (ec != std::errc{} || p != s.data() + s.size()) return std::nullopt;
  return v;
}

// Splits at runs of spaces and tabs; no empty tokens.
std::vector<std::string_view> split_whitespace(std::string_view s);
// The same without allocating: the first out.size() tokens go to `out`; returns how many
// tokens there are in all (more than out.size() when some did not fit).
std::size_t split_whitespace(std::string_view s, std::span<std::string_view> out);

}  // namespace cal::drivers::codec
