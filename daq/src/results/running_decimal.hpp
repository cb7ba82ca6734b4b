#pragma once
// The decimal digits of a number that moves by small steps, each value's digits made from the
// previous value's by a decimal add of the difference (with its carries), not converted from
// the binary integer again: an export's time columns (`time_ns`, and `time_s`, the same digits
// with the point placed) rise by one sample period a row in each stream. Converting the two
// numbers from scratch was about 150 of an export's 540 own instructions a row (issue 32,
// docs/benchmarks.md "Exports, sixth pass").
//
// The text is the same as write_integer's and write_seconds_of_ns's (shortest_number.hpp) for
// every value: where the add cannot be used (the first value, a step back, a step of 10^8 or
// more, a value with more digits than the one before) the digits are made from scratch; out
// of range (negative, 10^16 or more) set() refuses and the caller converts as before.
// tests/daq/results/running_decimal_test.cpp checks both texts against those functions over
// sequences with carries through 9s, digit-count changes, zero, jitter and steps back.
#include <bit>
#include <cstdint>
#include <cstring>

#include "shortest_number.hpp"

namespace daq {

inline constexpr bool kRunningDecimalFast = std::endian::native == std::endian::little;

class RunningDecimal {
 public:
  // Makes the digits those of v and returns true; false (nothing changed) for v outside
  // [0, 10^16), or where this build has no fast way (kRunningDecimalFast).
  bool set(std::int64_t v) {
    if constexpr (!kRunningDecimalFast) return false;
    // The usual step: 0 <= v - previous < 10^8, the same count of digits.
    const auto step = static_cast<std::uint64_t>(v) - static_cast<std::uint64_t>(value_);
    if (step < kMaxStep && v < bound_) {
      if (step != step_) set_step(step);
      std::uint64_t x = 0;
      // A carry out of the eighth digit (once in 10^8 / step values): from scratch.
      if (!__builtin_add_overflow(low_, step_digits_, &x)) {
        // Each byte got a + b + carry + 246: a digit sum of 10 or more wrapped the byte and
        // carried into the next one through the add itself; a byte that did not wrap has its
        // top bit set (246 + its sum) and gets 246 taken back (bytes 0 or 1 times 246: no
        // carry or borrow between bytes).
        low_ = x - ((x >> 7) & kBytes01) * 0xF6;
        value_ = v;
        return true;
      }
    }
    if (v < 0 || v >= kLimit) return false;
    reset(v);
    return true;
  }
  std::int64_t value() const { return value_; }

  // The integer as fmt's "{}" (write_integer) writes it: its digits, and up to 8 bytes of no
  // meaning after them (16 bytes are written at p). Returns the end.
  char* write_integer(char* p) const {
    put(p, int_head_);
    put(p + int_head_size_, low_text() >> low_shift_);
    return p + size_;
  }

  // The value as nanoseconds written as seconds, the text of write_seconds_of_ns(p, value())
  // (the exact decimal, the point nine digits from the end, its trailing zeros cut), where
  // that is fixed notation: 10^5 <= value() < 10^15. nullptr (nothing written) otherwise.
  // Up to 8 bytes of no meaning after the text (16 bytes are written at p).
  char* write_seconds(char* p) const {
    if (!seconds_fixed_) return nullptr;
    put(p, seconds_head_);                    // the whole seconds, the point, the first decimal
    put(p + seconds_head_size_, low_text());  // the other eight decimals
    // The last decimal other than 0: digits are 0 - 9 a byte, so + 0x7F sets a byte's top bit
    // exactly where it is not 0, with no carry into the next byte (byte k is digit 10^k).
    const std::uint64_t nonzero = (low_ + kBytes7F) & kBytes80;
    if (nonzero == 0) return p + seconds_size_if_low_zero_;
    return p + seconds_head_size_ + 8 - std::countr_zero(nonzero) / 8;
  }

 private:
  static constexpr std::int64_t kLimit = 10'000'000'000'000'000;  // 10^16
  static constexpr std::uint64_t kMaxStep = 100'000'000;          // 10^8: eight digits
  static constexpr std::uint64_t kBytes01 = 0x0101010101010101ULL;
  static constexpr std::uint64_t kBytes0F = 0x0F0F0F0F0F0F0F0FULL;
  static constexpr std::uint64_t kBytes7F = 0x7F7F7F7F7F7F7F7FULL;
  static constexpr std::uint64_t kBytes80 = 0x8080808080808080ULL;
  static constexpr std::uint64_t kBytesF6 = 0xF6F6F6F6F6F6F6F6ULL;  // 256 - 10 in each byte
  static constexpr std::uint64_t kZeros = 0x3030303030303030ULL;    // '0' in each byte

  static void put(char* p, std::uint64_t text) { std::memcpy(p, &text, 8); }
  // The eight digits of x < 10^8, digit 10^k in byte k, values 0 - 9 (write8's text turned
  // round: its byte 0 is digit 10^7).
  static std::uint64_t digit_bytes(std::uint32_t x) {
    return __builtin_bswap64(shortest_detail::digits8(x)) & kBytes0F;
  }
  // The text of the low eight digits in order (byte 0 the first, digit 10^7).
  std::uint64_t low_text() const { return __builtin_bswap64(low_) | kZeros; }
  void set_step(std::uint64_t step) {
    step_digits_ = digit_bytes(static_cast<std::uint32_t>(step)) + kBytesF6;  // bytes <= 255
    step_ = step;
  }
  // v's digits from scratch (the first value, a step back or a long one, a carry out of the
  // eighth digit, a new digit): the low eight as bytes, and the text before them, as an
  // integer and as seconds, which the adds leave as they are.
  void reset(std::int64_t v) {
    const auto u = static_cast<std::uint64_t>(v);
    const auto high = static_cast<std::uint32_t>(u / kMaxStep);  // < 10^8: v < 10^16
    low_ = digit_bytes(static_cast<std::uint32_t>(u % kMaxStep));
    value_ = v;
    size_ = fmt::detail::count_digits(u);
    bound_ = size_ >= 16 ? kLimit : static_cast<std::int64_t>(pow10(size_));
    // As an integer: the high digits' text, then the eight low digits (all of them, or only
    // the last size_ where there are no high digits).
    if (high != 0) {
      int_head_size_ = fmt::detail::count_digits(high);
      int_head_ = shortest_detail::digits8(high) >> (8 * (8 - int_head_size_));
      low_shift_ = 0;
    } else {
      int_head_size_ = 0;
      low_shift_ = 8 * (8 - size_);
    }
    // As seconds (fixed notation from 10^5 ns, 16 significant digits from 10^15: the full
    // conversion's): the whole seconds (1 - 6 digits), the point, the first decimal; then the
    // eight other decimals, cut after their last digit other than 0.
    seconds_fixed_ = size_ >= 6 && size_ <= 15;
    if (seconds_fixed_) {
      const std::uint32_t whole = high / 10, first_decimal = high % 10;
      const int whole_size = fmt::detail::count_digits(whole);
      seconds_head_ = (shortest_detail::digits8(whole) >> (8 * (8 - whole_size))) |
                      (std::uint64_t{'.'} << (8 * whole_size)) |
                      (std::uint64_t{'0' + first_decimal} << (8 * (whole_size + 1)));
      seconds_head_size_ = whole_size + 2;
      seconds_size_if_low_zero_ = first_decimal != 0 ? whole_size + 2 : whole_size;
    }
  }
  static constexpr std::uint64_t pow10(int n) {
    std::uint64_t p = 1;
    for (int i = 0; i < n; ++i) p *= 10;
    return p;
  }

  std::uint64_t low_ = 0;          // the last eight digits, digit 10^k in byte k
  std::uint64_t step_digits_ = 0;  // step_'s digits so, plus 246 in each byte
  std::uint64_t step_ = kMaxStep;  // (none yet)
  std::int64_t value_ = 0;
  std::int64_t bound_ = 0;  // 10^size_ (0 before the first value: no step is taken)
  int size_ = 0;            // digits
  std::uint64_t int_head_ = 0, seconds_head_ = 0;
  int int_head_size_ = 0, low_shift_ = 0;
  int seconds_head_size_ = 0, seconds_size_if_low_zero_ = 0;
  bool seconds_fixed_ = false;
};

}  // namespace daq
