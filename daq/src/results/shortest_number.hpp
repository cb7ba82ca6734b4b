#pragma once
// A double in the shortest form that reads back to the same double, character for character as
// fmt's "{}" writes it (fmt 9: Dragonbox's shortest digits; fixed notation for a decimal
// exponent in [-4, 16), else d.ddde+XX; no ".0" on whole numbers), written through a plain
// pointer. The exports write two of these per reading; fmt's general float writer (padding,
// grouping, precision and locale handled on every call) took about a sixth of an export's
// time (issue 32, docs/benchmarks.md). Digits come from fmt's own Dragonbox, so only the
// layout is ours; tests/daq/results/shortest_number_test.cpp compares it with fmt's "{}"
// over millions of values and every edge (zero, subnormals, powers of ten, the notation
// switch), so a change of fmt's layout fails there rather than changing an export.
#include <fmt/format.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace daq {

namespace shortest_detail {

// "00".."99": two digits per table look-up.
inline constexpr char kPairs[] =
    "0001020304050607080910111213141516171819202122232425262728293031323334353637383940414243444546"
    "4748495051525354555657585960616263646566676869707172737475767778798081828384858687888990919293"
    "949596979899";

inline void write_pair(char* p, std::uint32_t x) {  // x < 100
  p[0] = kPairs[x * 2];
  p[1] = kPairs[x * 2 + 1];
}

// Exactly 8 digits of x < 10^8, leading zeros included, with no division chain: the two
// halves of four digits in the two 32-bit lanes of one word, each split into pairs (x 10486
// >> 20 is / 100 below 10^4), each pair into digits (x 103 >> 10 is / 10 below 100), all lanes
// at once; then the word's bytes are the digits in order (little-endian; elsewhere by pairs).
// Two divisions per pair were the largest cost of an export's digits (issue 32).
inline void write8(char* p, std::uint32_t x) {
  if constexpr (std::endian::native == std::endian::little) {
    const std::uint64_t halves = (x / 10000) | (static_cast<std::uint64_t>(x % 10000) << 32);
    const std::uint64_t high_pairs = ((halves * 10486) >> 20) & 0x0000007F0000007FULL;
    const std::uint64_t low_pairs = halves - 100 * high_pairs;
    const std::uint64_t pairs = (low_pairs << 16) | high_pairs;  // 16-bit lanes, in order
    const std::uint64_t tens = ((pairs * 103) >> 10) & 0x000F000F000F000FULL;
    const std::uint64_t digits = tens | ((pairs - 10 * tens) << 8);
    const std::uint64_t text = digits | 0x3030303030303030ULL;
    std::memcpy(p, &text, 8);
  } else {
    const std::uint32_t hi = x / 10000, lo = x % 10000;
    write_pair(p, hi / 100);
    write_pair(p + 2, hi % 100);
    write_pair(p + 4, lo / 100);
    write_pair(p + 6, lo % 100);
  }
}

// The `size` decimal digits of v (size = count_digits(v)), written to [p, p + size).
inline void write_digits(char* p, std::uint64_t v, int size) {
  char* end = p + size;
  while (v >= 100'000'000) {
    end -= 8;
    write8(end, static_cast<std::uint32_t>(v % 100'000'000));
    v /= 100'000'000;
  }
  auto x = static_cast<std::uint32_t>(v);
  while (x >= 100) {
    end -= 2;
    write_pair(end, x % 100);
    x /= 100;
  }
  if (x >= 10)
    write_pair(end - 2, x);
  else
    end[-1] = static_cast<char>('0' + x);
}

}  // namespace shortest_detail

// An integer as fmt's "{}" writes it (at most 20 characters); returns the end.
inline char* write_integer(char* p, std::int64_t v) {
  std::uint64_t u = static_cast<std::uint64_t>(v);
  if (v < 0) {
    *p++ = '-';
    u = 0 - u;
  }
  const int size = fmt::detail::count_digits(u);
  shortest_detail::write_digits(p, u, size);
  return p + size;
}

// Writes v at p (at most 24 characters) and returns the end.
inline char* write_shortest(char* p, double v) {
  using namespace shortest_detail;
  if (!std::isfinite(v)) return fmt::format_to(p, "{}", v);  // inf, nan as fmt writes them
  if (std::signbit(v)) {
    *p++ = '-';
    v = -v;
  }
  const auto dec = fmt::detail::dragonbox::to_decimal(v);  // {0, 0} for zero
  const std::uint64_t sig = dec.significand;
  const int exponent = dec.exponent;                // v = sig x 10^exponent
  const int size = fmt::detail::count_digits(sig);  // branch-free (a table by bit length)
  const int out_exp = exponent + size - 1;          // of the first digit
  if (out_exp < -4 || out_exp >= 16) {              // d[.ddd]e[+-]XX
    char digits[20];
    write_digits(digits, sig, size);
    *p++ = digits[0];
    if (size > 1) {
      *p++ = '.';
      for (int i = 1; i < size; ++i) *p++ = digits[i];
    }
    *p++ = 'e';
    int e = out_exp;
    if (e < 0) {
      *p++ = '-';
      e = -e;
    } else {
      *p++ = '+';
    }
    if (e >= 100) {
      *p++ = static_cast<char>('0' + e / 100);
      e %= 100;
    }
    *p++ = kPairs[e * 2];
    *p++ = kPairs[e * 2 + 1];
    return p;
  }
  if (exponent >= 0) {  // a whole number: its digits and the zeros after them
    write_digits(p, sig, size);
    p += size;
    for (int i = 0; i < exponent; ++i) *p++ = '0';
    return p;
  }
  const int whole = size + exponent;  // digits before the point
  if (whole > 0) {
    // Written one place on, then the few digits before the point moved back for it (fewer
    // than after it in the export's values: times of seconds, lengths of a metre or less).
    write_digits(p + 1, sig, size);
    for (int i = 0; i < whole; ++i) p[i] = p[i + 1];
    p[whole] = '.';
    return p + size + 1;
  }
  *p++ = '0';
  *p++ = '.';
  for (int i = 0; i < -whole; ++i) *p++ = '0';
  write_digits(p, sig, size);
  return p + size;
}

}  // namespace daq
