#pragma once
// The shortest decimal that reads back as a double (its "shortest round trip"), for the exports'
// unquantised readings (16 - 17 significant digits), where fmt's Dragonbox digit search was
// about 128 instructions a value (issue 32, docs/benchmarks.md "Exports, seventh pass").
//
// The method is Schubfach's: R. Giulietti, "The Schubfach way to render doubles" (2020, revised
// 2021). Written here from the paper's description, not from any implementation; the table of
// powers of ten is generated below by this file's own constexpr code from exact integers.
//
// v = c 2^q (c the integer significand, q the exponent). The decimals that read back as v are
// those in its rounding interval R = [(c - 1/2) 2^q, (c + 1/2) 2^q], closed for an even c
// (round half to even reads the bounds back as v), open for an odd one. With k = floor(q
// log10 2), 10^k <= 2^q < 10^(k+1): R (2^q wide) holds at most one multiple of 10^(k+1) and at
// least one of 10^k. So the shortest is the multiple of 10^(k+1) in R if there is one, else
// the multiple of 10^k in R (s or s + 1 with s = floor(v 10^-k)), the one nearer v if both are,
// the even one on a tie. That is what Dragonbox, Ryu and Schubfach all give (fmt's "{}" uses
// Dragonbox); the tests compare every result with fmt's.
//
// v 10^-k and the interval's ends are needed only to their floor and whether they are whole
// numbers, at 2 bits below the unit (the ends are quarter-units of 2^q): with c' in {4c - 2,
// 4c, 4c + 2}, X = c' 2^q 10^-k, computed as c' g >> S with g the top 128 bits of 10^-k, and
// rounded to odd (the lowest bit set if any bit shifted out is): floor and wholeness survive
// the rounding, so comparisons with multiples of 4 are exact. Here only k <= 0 (v < 2^56, all
// an export's lengths, angles and times): 10^-k = 10^j, j = -k in [0, 324], an integer. For
// j <= 55 (5^j < 2^128) g is exact, so X is exact. For j > 55, g is rounded up by one, X is
// never a whole number (X = c' 5^j 2^(q + j) with q + j < -126 and c' < 2^56), and the
// paper's bound on how close such an X comes to a whole number (proven for a 126-bit g; this
// g has 128) keeps floor and wholeness. Values of 2^56 and above (k >= 1, where 10^-k is not
// an integer and X can be a whole number while g is not exact), the powers of two with
// their narrower lower half-interval, zero, inf and nan go to fmt's Dragonbox.
#include <fmt/format.h>

#include <array>
#include <bit>
#include <cstdint>

namespace daq::shortest_detail {

#if defined(__SIZEOF_INT128__)
__extension__ typedef unsigned __int128 u128_t;  // (GCC and Clang; __extension__: not ISO C++)

// 10^j's top 128 bits (rounded up by one where bits below them are dropped: j > 55) and its
// bit length: 10^j is about g 2^(bits - 128).
struct Pow10Top128 {
  std::uint64_t hi = 0, lo = 0;
  int bits = 0;
};
inline constexpr int kMaxPow10 = 324;  // the least double, 2^-1074, has k = -324

// Generated from 10^j as an exact integer (64-bit limbs, multiplied by 10 each step).
consteval std::array<Pow10Top128, kMaxPow10 + 1> make_pow10_top128() {
  constexpr int kLimbs = 18;              // 10^324 < 2^1077 < 2^(64 x 17)
  std::array<std::uint64_t, kLimbs> n{};  // limb 0 lowest
  n[0] = 1;
  std::array<Pow10Top128, kMaxPow10 + 1> table{};
  for (int j = 0; j <= kMaxPow10; ++j) {
    if (j > 0) {
      u128_t carry = 0;
      for (auto& limb : n) {
        const u128_t x = static_cast<u128_t>(limb) * 10 + carry;
        limb = static_cast<std::uint64_t>(x);
        carry = x >> 64;
      }
    }
    int top = kLimbs - 1;
    while (n[top] == 0) --top;
    const int bits = 64 * top + (64 - std::countl_zero(n[top]));
    // Bit i of n, 0 beyond its ends.
    const auto bit = [&](int i) -> std::uint64_t {
      return i < 0 ? 0 : (n[i / 64] >> (i % 64)) & 1;
    };
    u128_t g = 0;
    for (int i = bits - 1; i >= bits - 128; --i) g = (g << 1) | bit(i);
    bool dropped = false;  // a bit other than 0 below the 128
    for (int i = bits - 129; i >= 0; --i) dropped = dropped || bit(i) != 0;
    if (dropped) ++g;
    table[j] = {static_cast<std::uint64_t>(g >> 64), static_cast<std::uint64_t>(g), bits};
  }
  return table;
}
inline constexpr auto kPow10Top128 = make_pow10_top128();

// X = c' 2^q 10^j rounded to odd (see above), for q + bits(10^j) in [1, 4]: c' g >> S with
// S = 128 - q - bits in [124, 127]. The caller passes c' shifted left by 128 - S (at most 4:
// c' 2^4 < 2^60), so X is the product's bits from 128 on, and any bit below them makes it odd:
// two 64 x 64 -> 128 multiplications, no shift by a varying count.
[[gnu::always_inline]] inline std::uint64_t round_to_odd(const Pow10Top128& g,
                                                         std::uint64_t cp_shifted) {
  const u128_t a = static_cast<u128_t>(cp_shifted) * g.hi;
  const u128_t b = static_cast<u128_t>(cp_shifted) * g.lo;
  const u128_t high = a + (b >> 64);  // the product's bits from 64 on (< 2^188: no carry out)
  const bool sticky = (static_cast<std::uint64_t>(high) | static_cast<std::uint64_t>(b)) != 0;
  return static_cast<std::uint64_t>(high >> 64) | static_cast<std::uint64_t>(sticky);
}

// A positive double's shortest decimal: significand (possibly with trailing zeros) times
// 10^exponent.
struct ShortestDecimal {
  std::uint64_t significand = 0;
  int exponent = 0;
};

// v's shortest decimal (Schubfach's choice, above) for a finite v with 0 < |v| < 2^56 that is
// not a power of two other than the least normal's (bits: v's bit pattern, sign ignored);
// {0, 0} for any other v (the caller's to send elsewhere).
[[gnu::always_inline]] inline ShortestDecimal shortest_decimal(std::uint64_t bits) {
  constexpr std::uint64_t kFraction = (std::uint64_t{1} << 52) - 1;
  const std::uint64_t magnitude = bits & ~(std::uint64_t{1} << 63);
  // Zero, and 2^56 and above (a biased exponent of 1079 on: q >= 4, inf and nan included).
  if (magnitude - 1 >= (std::uint64_t{1079} << 52) - 1) return {};
  // A power of two from 2^-1021 on (its lower half-interval is half as wide).
  if ((magnitude & kFraction) == 0 && magnitude >= (std::uint64_t{2} << 52)) return {};
  // Normal: c = 2^52 + fraction, q = biased - 1075; subnormal: c = fraction, q = -1074.
  const auto biased = static_cast<int>(magnitude >> 52);
  const std::uint64_t c = (magnitude & kFraction) | (std::uint64_t{biased != 0} << 52);
  const int q = (biased != 0 ? biased : 1) - 1075;
  // k = floor(q log10 2) <= 0, j = -k: floor(q x 315653 / 2^20) for |q| <= 2620 (log10 2 =
  // 0.30102999566..., 315653 / 2^20 = 0.30103015899...; checked by the tests at every q).
  const int j = -((q * 315653) >> 20);
  const Pow10Top128& g = kPow10Top128[static_cast<unsigned>(j)];
  const int h = q + g.bits;         // 128 - S, in [1, 4]
  const std::uint64_t out = c & 1;  // an odd c: R open, its ends excluded
  // X for c' = 4c as a 192-bit product, hi (bits 64 - 191) and lo (bits 0 - 63); the ends'
  // products, (4c -+ 2) 2^h g, are it -+ 2^(h+1) g: a 192-bit add and subtract, no more
  // multiplications (two thirds of them were: the three products had the port for them busy).
  const std::uint64_t cp = (c << 2) << h;
  const u128_t a = static_cast<u128_t>(cp) * g.hi, b = static_cast<u128_t>(cp) * g.lo;
  const u128_t hi = a + (b >> 64);
  const auto lo = static_cast<std::uint64_t>(b);
  const std::uint64_t d_lo = g.lo << (h + 1);  // 2^(h+1) g: bits 0 - 63, then 64 - 191
  const u128_t d_hi =
      (static_cast<u128_t>(g.hi >> (63 - h)) << 64) | ((g.hi << (h + 1)) | (g.lo >> (63 - h)));
  const std::uint64_t lo_l = lo - d_lo, lo_r = lo + d_lo;
  const u128_t hi_l = hi - d_hi - (lo < d_lo), hi_r = hi + d_hi + (lo_r < lo);
  const auto odd = [](u128_t high, std::uint64_t low) {  // X rounded to odd
    const bool sticky = (static_cast<std::uint64_t>(high) | low) != 0;
    return static_cast<std::uint64_t>(high >> 64) | static_cast<std::uint64_t>(sticky);
  };
  const std::uint64_t vb = odd(hi, lo), vbl = odd(hi_l, lo_l), vbr = odd(hi_r, lo_r);
  const std::uint64_t s = vb >> 2;  // floor(v 10^-k)
  // The multiple of 10^(k+1) in R, if any (at most one: R is under 10^(k+1) wide).
  const std::uint64_t down10 = s / 10 * 10;
  const bool down10_in = vbl + out <= down10 << 2, up10_in = ((down10 + 10) << 2) + out <= vbr;
  // Else the multiples of 10^k next to v (one at least is in R): the one in R, or the nearer
  // one, or on a tie the even one.
  const bool down_in = vbl + out <= s << 2, up_in = ((s + 1) << 2) + out <= vbr;
  const auto cmp = static_cast<std::int64_t>(vb - (s << 2) - 2);  // v against s + 1/2
  const bool down = down_in && (!up_in || cmp < 0 || (cmp == 0 && (s & 1) == 0));
  // Chosen without branches: which way each goes is as good as random for readings of 16 - 17
  // digits, and mispredicted branches cost more than computing every case.
  const std::uint64_t by10 = down10 + (down10_in ? 0 : 10);
  const std::uint64_t by1 = s + (down ? 0 : 1);
  const std::uint64_t pick = std::uint64_t{0} - static_cast<std::uint64_t>(down10_in | up10_in);
  return {by1 ^ ((by1 ^ by10) & pick), -j};
}
#endif

}  // namespace daq::shortest_detail
