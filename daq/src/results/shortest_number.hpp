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

#include <algorithm>
#include <bit>
#include <cmath>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
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

// The 8 digits of x < 10^8 as write8 writes them, as the bytes of a word (little-endian only).
inline std::uint64_t digits8(std::uint32_t x) {
  const std::uint64_t halves = (x / 10000) | (static_cast<std::uint64_t>(x % 10000) << 32);
  const std::uint64_t high_pairs = ((halves * 10486) >> 20) & 0x0000007F0000007FULL;
  const std::uint64_t low_pairs = halves - 100 * high_pairs;
  const std::uint64_t pairs = (low_pairs << 16) | high_pairs;  // 16-bit lanes, in order
  const std::uint64_t tens = ((pairs * 103) >> 10) & 0x000F000F000F000FULL;
  const std::uint64_t digits = tens | ((pairs - 10 * tens) << 8);
  return digits | 0x3030303030303030ULL;
}

// Exactly 8 digits of x < 10^8, leading zeros included, with no division chain: the two
// halves of four digits in the two 32-bit lanes of one word, each split into pairs (x 10486
// >> 20 is / 100 below 10^4), each pair into digits (x 103 >> 10 is / 10 below 100), all lanes
// at once; then the word's bytes are the digits in order (little-endian; elsewhere by pairs).
// Two divisions per pair were the largest cost of an export's digits (issue 32).
inline void write8(char* p, std::uint32_t x) {
  if constexpr (std::endian::native == std::endian::little) {
    const std::uint64_t text = digits8(x);
    std::memcpy(p, &text, 8);
  } else {
    const std::uint32_t hi = x / 10000, lo = x % 10000;
    write_pair(p, hi / 100);
    write_pair(p + 2, hi % 100);
    write_pair(p + 4, lo / 100);
    write_pair(p + 6, lo % 100);
  }
}

// The last `n` (1..8) digits of x < 10^8 at p, in one 8-byte store: the n characters, then
// 8 - n bytes of no meaning after them (kSpill: a caller leaves that room and writes over it).
inline void write_last(char* p, std::uint32_t x, int n) {
  if constexpr (std::endian::native == std::endian::little) {
    const std::uint64_t text = digits8(x) >> (8 * (8 - n));  // the first 8 - n digits out
    std::memcpy(p, &text, 8);
  } else {
    char all[8];
    write8(all, x);
    std::memcpy(p, all + 8 - n, static_cast<std::size_t>(n));
  }
}

#if defined(__SSE2__)
// Exactly 16 digits of v < 10^16, leading zeros included, in one 16-byte store: digits8's
// steps on both halves of 8 digits at once in the lanes of one SSE2 register (x86-64 always
// has SSE2). v / 10^4 is (v x ceil(2^45 / 10^4)) >> 45 below 10^8, / 100 is (x 5243) >> 19
// below 43,699 and / 10 is (x 103) >> 10 below 100. Half the instructions of two digits8 (the
// digit writing was a fifth of an export, issue 32); the test compares it with write8 on both
// halves over 2 x 10^8 values.
inline __m128i digits16(std::uint64_t v) {
  const auto high = static_cast<std::uint32_t>(v / 100'000'000);
  const auto low = static_cast<std::uint32_t>(v % 100'000'000);
  const __m128i x = _mm_set_epi64x(low, high);  // 64-bit lanes, the high half first
  const __m128i x_div_10k =
      _mm_srli_epi64(_mm_mul_epu32(x, _mm_set1_epi32(static_cast<int>(0xd1b71759))), 45);
  const __m128i x_mod_10k = _mm_sub_epi32(x, _mm_mul_epu32(x_div_10k, _mm_set1_epi32(10000)));
  // 32-bit lanes: the four groups of 4 digits in order, each < 10^4.
  const __m128i fours = _mm_or_si128(x_div_10k, _mm_slli_epi64(x_mod_10k, 32));
  const __m128i high_pairs = _mm_srli_epi16(_mm_mulhi_epu16(fours, _mm_set1_epi16(5243)), 3);
  const __m128i low_pairs = _mm_sub_epi16(fours, _mm_mullo_epi16(high_pairs, _mm_set1_epi16(100)));
  // 16-bit lanes: the eight pairs of digits in order, each < 100.
  const __m128i pairs = _mm_or_si128(high_pairs, _mm_slli_epi32(low_pairs, 16));
  const __m128i tens = _mm_srli_epi16(_mm_mullo_epi16(pairs, _mm_set1_epi16(103)), 10);
  const __m128i ones = _mm_sub_epi16(pairs, _mm_mullo_epi16(tens, _mm_set1_epi16(10)));
  return _mm_or_si128(_mm_or_si128(tens, _mm_slli_epi16(ones, 8)), _mm_set1_epi8('0'));
}

// The 16 digits of digits16, stored at p.
inline void write16(char* p, std::uint64_t v) {
  _mm_storeu_si128(reinterpret_cast<__m128i*>(p), digits16(v));
}

// 10^k as integers, for moving a number's digits to the front of write16's 16.
inline constexpr std::uint64_t kPow10Int[] = {1,
                                              10,
                                              100,
                                              1000,
                                              10000,
                                              100000,
                                              1000000,
                                              10000000,
                                              100000000,
                                              1000000000,
                                              10000000000,
                                              100000000000,
                                              1000000000000,
                                              10000000000000,
                                              100000000000000,
                                              1000000000000000,
                                              10000000000000000};
#endif

// The `size` decimal digits of v (size = count_digits(v)), written to [p, p + size), left to
// right: the leading group of 1..8 digits in one store, then whole groups of 8, each written
// over the spill of the one before. Up to kSpill bytes after p + size are written too (no
// meaning: the caller's room, written over by what follows). The leading group's pairs
// divided by 100 one at a time (a multiplication and a table look-up each) were the larger
// part of an export's digit writing (issue 32).
inline constexpr int kSpill = 8;
inline void write_digits(char* p, std::uint64_t v, int size) {
  if (size <= 8) return write_last(p, static_cast<std::uint32_t>(v), size);
#if defined(__SSE2__)
  // 9 to 17 digits (a double's shortest form has at most 17): v x 10^(16 - size) puts them at
  // the front of 16, its zeros after them the spill (at most 7).
  if (size <= 16) return write16(p, v * kPow10Int[16 - size]);
  if (size == 17) {
    *p = static_cast<char>('0' + v / kPow10Int[16]);
    return write16(p + 1, v % kPow10Int[16]);
  }
#endif
  if (size <= 16) {
    const int lead = size - 8;
    write_last(p, static_cast<std::uint32_t>(v / 100'000'000), lead);
    return write8(p + lead, static_cast<std::uint32_t>(v % 100'000'000));
  }
  const int lead = size - 16;  // 1..4 (v < 2^64 < 10^20)
  const std::uint64_t low16 = v % 10'000'000'000'000'000ULL;
  write_last(p, static_cast<std::uint32_t>(v / 10'000'000'000'000'000ULL), lead);
  write8(p + lead, static_cast<std::uint32_t>(low16 / 100'000'000));
  write8(p + lead + 8, static_cast<std::uint32_t>(low16 % 100'000'000));
}

// sig x 10^exponent (sig without trailing zeros, as Dragonbox gives it; {0, 0} for zero) laid
// out as fmt's "{}" lays out a double's shortest digits: fixed for a decimal exponent of the
// first digit in [-4, 16), else d[.ddd]e[+-]XX. Returns the end.
inline char* write_decimal(char* p, std::uint64_t sig, int exponent) {
  const int size = fmt::detail::count_digits(sig);  // branch-free (a table by bit length)
  const int out_exp = exponent + size - 1;          // of the first digit
  if (out_exp < -4 || out_exp >= 16) {              // d[.ddd]e[+-]XX
    char digits[20 + kSpill];
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

// Exact powers of ten as doubles (10^22 is the last one a double holds exactly).
inline constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                    1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                    1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};

#if defined(__SSE2__) && defined(__SIZEOF_INT128__)
// The decimal m x 10^-k (0 < m < 10^16, k >= 0) as fmt's "{}" lays out a double whose shortest
// digits it is, where that layout is fixed notation (its first digit's exponent at least -4);
// nullptr (nothing written) where it is exponent notation. All 16 digits of m (leading zeros
// included) in one register; where its first and last digits other than 0 are comes from one
// comparison (no loop cutting zeros, no second pass writing the digits). Digit i weighs
// 10^(15 - i - k): the point goes before digit 16 - k. The digits are moved to their places as
// one 128-bit integer shifted by whole bytes (byte i is digit i), never stored and read back
// at another offset: that read spans the store and cannot take its data from it (store
// forwarding fails, a stall of some 15 cycles each time), which made this a third of an
// export's time while it was a fifth of its instructions (issue 32). The text in two or
// three stores of 16 bytes: at most 24 characters and up to 16 bytes of no meaning after them.
__extension__ typedef unsigned __int128 u128;  // (GCC and Clang; __extension__: not ISO C++)
[[gnu::always_inline]] inline char* write_fixed16(char* p, std::uint64_t m, int k) {
  const __m128i text = digits16(m);
  const auto nonzero = static_cast<unsigned>(
      ~_mm_movemask_epi8(_mm_cmpeq_epi8(text, _mm_set1_epi8('0'))) & 0xFFFF);  // m > 0: not 0
  const int first = std::countr_zero(nonzero), last = 31 - std::countl_zero(nonzero);
  const int point = 16 - k;  // digits [0, point) are the whole part
  if (point - 1 - first < -4) return nullptr;
  const auto low = static_cast<std::uint64_t>(_mm_cvtsi128_si64(text));
  const auto high = static_cast<std::uint64_t>(_mm_cvtsi128_si64(_mm_unpackhi_epi64(text, text)));
  const u128 all = (static_cast<u128>(high) << 64) | low;  // little-endian: byte i, digit i
  const auto put = [](char* at, u128 bytes) { std::memcpy(at, &bytes, 16); };
  const u128 from_first = all >> (8 * first);
  if (last < point) {  // a whole number: its digits up to the point
    put(p, from_first);
    return p + point - first;
  }
  if (first < point) {  // digits, the point, the decimals up to the last one not 0
    const int whole = point - first;
    put(p, from_first);
    p[whole] = '.';
    put(p + whole + 1, all >> (8 * point));
    return p + whole + 1 + (last + 1 - point);
  }
  const int zeros = first - point;  // 0..3 after "0."
  std::memcpy(p, "0.000000", 8);
  put(p + 2 + zeros, from_first);
  return p + 2 + zeros + (last + 1 - first);
}
#endif

}  // namespace shortest_detail

// An integer as fmt's "{}" writes it (at most 20 characters, and up to kSpill bytes of no
// meaning after them: room for 28); returns the end.
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

// Writes v at p (at most 24 characters, and up to kSpill bytes of no meaning after them: room
// for 32) and returns the end.
inline char* write_shortest(char* p, double v) {
  if (!std::isfinite(v)) return fmt::format_to(p, "{}", v);  // inf, nan as fmt writes them
  if (std::signbit(v)) {
    *p++ = '-';
    v = -v;
  }
  const auto dec = fmt::detail::dragonbox::to_decimal(v);  // {0, 0} for zero
  return shortest_detail::write_decimal(p, dec.significand, dec.exponent);
}

// The same text as write_shortest(p, v), for a stored reading: where v is the double of a
// decimal with at most about 15 significant digits (an instrument's reading at its resolution,
// as its driver stores it: a gauge's printed millimetres, an IDS3010's integer picometres, in
// metres; docs/benchmarks.md, "Exports, fourth pass"), that decimal is written without the
// shortest-digit search (Dragonbox, 150 instructions a value, issue 32); otherwise
// write_shortest. The decimal is proven, not assumed, so any v gives fmt's "{}" text.
//
// The guess: k, the most decimals that keep |v| 10^k below 2^51 (from v's binary exponent e:
// |v| < 2^(e+1), so 10^k <= 2^(50 - e); floor((50 - e) log10 2) by x 78913 >> 18), and
// m = |v| 10^k rounded to the nearest integer. The proof is write_shortest_scaled's with that
// m and k: m < 2^51 and 10^k (k <= 22) are exact doubles, so m / 10^k is one correctly rounded
// division, what strtod makes of the decimal m x 10^-k; it must equal |v|. With the trailing
// zeros cut (m = q 10^z, d = k - z decimals, the same rational, so the same double), |v| 10^d
// <= |v| 10^k < 2^51, so v's rounding interval is under half of 10^-d wide and that decimal
// is the only one in it with d or fewer decimals, hence Dragonbox's shortest: significand q,
// exponent -d. A value the guess misses (16 - 17 significant digits, or a reading whose unit
// conversion rounded it off its decimal's own double: a quarter of a gauge's, docs) costs
// the guess (a multiplication, a division, a comparison) and then Dragonbox as before.
// At most 24 characters, and up to 16 bytes of no meaning after them: room for 40.
inline char* write_shortest_scaled(char* p, double v, std::int64_t m, int k);  // below

inline char* write_shortest_quantised(char* p, double v) {
  using namespace shortest_detail;
  const double a = std::abs(v);
  const int e = static_cast<int>(std::bit_cast<std::uint64_t>(a) >> 52) - 1023;
  // Zero and subnormals (e = -1023), inf and nan (1024), |v| >= 2^51 (no decimals left): the
  // general way. A normal v keeps the rounding interval's bound used above.
  if (e < -1022 || e > 50) return write_shortest(p, v);
  const int k = std::min(22, ((50 - e) * 78913) >> 18);
  const double x = a * kPow10[k];                     // < 2^51: its ulp <= 1/4, x + 0.5 exact
  const auto m = static_cast<std::int64_t>(x + 0.5);  // the nearest integer (a guess)
  if (m == 0 || static_cast<double>(m) / kPow10[k] != a) return write_shortest(p, v);
  char* const start = p;
  if (std::signbit(v)) *p++ = '-';
#if defined(__SSE2__) && defined(__SIZEOF_INT128__)
  // m < 2^51 has at most 16 digits; fmt's fixed notation in a few stores (write_fixed16).
  if (char* const end = write_fixed16(p, static_cast<std::uint64_t>(m), k)) return end;
#endif
  // Exponent notation (or no SSE2): m x 10^-k is v's decimal, written as write_shortest_scaled
  // writes one (its trailing zeros cut, then write_decimal).
  return write_shortest_scaled(start, v, std::signbit(v) ? -m : m, k);
}

// The same text as write_shortest(p, v), for a v the caller knows to be near the decimal
// m x 10^-k (write_shortest_quantised's proven guess): where that decimal is v's shortest round
// trip, it is written without the shortest-digit search (Dragonbox, a quarter of an export's
// time, issue 32); otherwise write_shortest. m is only a guess: the decimal is taken only where
// it is proven to be what Dragonbox gives, so any m gives the same text.
//
// The proof: strip m's trailing zeros, m = q x 10^z, d = k - z decimals, c = q x 10^-d.
//  1. c reads back as v: q < 2^53 and 10^d (d <= 22) are exact doubles, so q / 10^d is one
//     correctly rounded division, what strtod makes of c's text; it must equal v.
//  2. c is the only shortest: the decimals that read back as v lie in v's rounding interval,
//     no wider than ulp(v) <= |v| 2^-52. Two distinct numbers with at most d decimals differ
//     by 10^-d or more, so with |v| 10^d < 2^51 (the interval under half of 10^-d) c is the
//     only one in it with at most d decimals; one with more decimals and fewer significant
//     digits would be below c's leading power of ten with the same d decimals (so again at
//     least 10^-d away). Dragonbox gives the shortest, so it gives c: significand q,
//     exponent -d (its trailing zeros removed, as here).
inline char* write_shortest_scaled(char* p, double v, std::int64_t m, int k) {
  using namespace shortest_detail;
  constexpr std::int64_t kExact = std::int64_t{1} << 53;
  // Normal, finite, nonzero v of m's sign; q < 2^53; 0 <= k <= 22 (else the general way).
  if (m == 0 || m <= -kExact || m >= kExact || k < 0 || k > 22 || (m < 0) != std::signbit(v) ||
      !(std::abs(v) >= 0x1p-1022) || !(std::abs(v) < 0x1p53))
    return write_shortest(p, v);
  std::uint64_t q = static_cast<std::uint64_t>(m < 0 ? -m : m);
  int d = k;
  while (d >= 4 && q % 10000 == 0) {  // four zeros a step (a 100 us grid has five)
    q /= 10000;
    d -= 4;
  }
  while (d > 0 && q % 10 == 0) {
    q /= 10;
    --d;
  }
  const double a = std::abs(v);
  if (static_cast<double>(q) / kPow10[d] != a || !(a * kPow10[d] < 0x1p51))
    return write_shortest(p, v);
  int exponent = -d;
  while (q % 10 == 0) {  // a whole number's zeros: Dragonbox leaves none in its significand
    q /= 10;
    ++exponent;
  }
  if (m < 0) *p++ = '-';
  return write_decimal(p, q, exponent);
}

// Seconds from integer nanoseconds, as the exports' time_s column writes them: the same text as
// write_shortest(p, static_cast<double>(ns) / 1e9), the correctly rounded quotient's shortest
// round trip, for every ns; below 10^15 ns (11.5 days) that text is the exact decimal of ns
// 10^-9, written here from the integer's digits (the point placed, trailing zeros cut, fmt's
// layout: fixed from 1e-4 s, 99,999 ns and less as d.ddde-XX) with no digit search and no
// proof. The exports once wrote ns x 1e-9, whose second rounding gave 41 % of a 100 us grid's
// times as 17-digit neighbours of their decimals (0.00030000000000000003): issue 32.
//
// Why the decimal is the shortest round trip: c = |ns| / 10^9 is a decimal of at most 15
// significant digits (|ns| < 10^15), in the decade [10^e, 10^(e+1)), so a multiple of
// 10^(e-14). v, the double nearest c (one correctly rounded division: ns and 10^9 are exact
// doubles), lies in [2^b, 2^(b+1)) with 2^b <= v <= 10^(e+1) (1 + 2^-53), so ulp(v) = 2^(b-52)
// < 10^(e+1) 2^-52 (1 + 2^-53) < 0.23 x 10^(e-14). The decimals that read back as v lie in v's
// rounding interval, at most ulp(v) wide, and c is one of them; any other x in it is within
// 0.23 x 10^(e-14) of c. In c's decade, x of at most 15 significant digits is a multiple of
// 10^(e-14): not that close. Above it, x >= 10^(e+1) >= c + 10^(e-14): neither. Below it,
// x < 10^e <= c, so c - x < 0.23 x 10^(e-14) leaves only c = 10^e, a single digit. So no
// decimal shorter than c, and none other as short, reads back as v: Dragonbox's shortest is
// c (significand and exponent with trailing zeros cut), and fmt lays it out as here. (This is
// why DBL_DIG is 15.) From 10^15 ns on, a 16-digit decimal need not be the shortest text of
// its double (ulp(v) reaches 10^(e-15)): those go to write_shortest of the quotient, whose
// text reads back as the same double but may differ from the exact decimal in its last digit
// (the time_ns column keeps the integer).
inline char* write_seconds_of_ns(char* p, std::int64_t ns) {
  using namespace shortest_detail;
  std::uint64_t u = static_cast<std::uint64_t>(ns);
  if (ns < 0) u = 0 - u;
  if (u >= 1'000'000'000'000'000ULL) return write_shortest(p, static_cast<double>(ns) / 1e9);
  if (u == 0) {
    *p = '0';
    return p + 1;
  }
  if (ns < 0) *p++ = '-';
#if defined(__SSE2__) && defined(__SIZEOF_INT128__)
  if (u >= 100'000) return shortest_detail::write_fixed16(p, u, 9);  // from 1e-4 s: fixed
#endif
  // Under 1e-4 s (fmt's exponent notation), or no SSE2: the decimal's significand without its
  // trailing zeros, laid out as write_shortest lays out Dragonbox's.
  int exponent = -9;
  while (u % 10 == 0) {
    u /= 10;
    ++exponent;
  }
  return shortest_detail::write_decimal(p, u, exponent);
}

}  // namespace daq
