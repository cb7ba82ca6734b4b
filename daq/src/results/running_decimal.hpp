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
#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>

#include "shortest_number.hpp"

namespace daq {

inline constexpr bool kRunningDecimalFast = std::endian::native == std::endian::little;

class RunningDecimal {
 public:
  // `decimals` (8 - 15: pow10 of more overflows, and the callers learn at most 15): where
  // write_decimal places the point (9: nanoseconds as seconds).
  explicit RunningDecimal(int decimals = 9) : decimals_(decimals) {}
  int decimals() const { return decimals_; }
  // Places the point elsewhere from the next value on (the digits are made from scratch).
  void set_decimals(int decimals) {
    decimals_ = decimals;
    bound_ = 0;
  }

  // Makes the digits those of v (and the sign `negative`, which only write_decimal writes)
  // and returns true; false (nothing changed) for v outside [0, 10^16), or where this build
  // has no fast way (kRunningDecimalFast). The usual step, by the add: 0 <= v - previous <
  // 10^8, the same count of digits and the same sign; with Back also -10^8 < v - previous < 0
  // (a few instructions more: the time columns, which rise, do without).
  template <bool Back = false>
  [[gnu::always_inline]] bool set(std::int64_t v, bool negative = false) {
    if constexpr (!kRunningDecimalFast) return false;
    const auto up = static_cast<std::uint64_t>(v) - static_cast<std::uint64_t>(value_);
    std::uint64_t x = 0;
    if (!Back) {
      if (up < kMaxStep && v < bound_ && negative == negative_) {
        if (up != step_) set_step(up);
        if (!__builtin_add_overflow(low_, step_digits_ + kBytesF6, &x)) {
          low_ = x - ((x >> 7) & kBytes01) * 0xF6;
          value_ = v;
          return true;
        }
      }
    } else if (v < bound_ && v >= lower_ && negative == negative_) {
      if (up < kMaxStep) {
        if (up != step_) set_step(up);
        // A carry out of the eighth digit (once in 10^8 / step values): from scratch.
        if (!__builtin_add_overflow(low_, step_digits_ + kBytesF6, &x)) {
          // Each byte got a + b + carry + 246: a digit sum of 10 or more wrapped the byte and
          // carried into the next one through the add itself; a byte that did not wrap has
          // its top bit set (246 + its sum) and gets 246 taken back (bytes 0 or 1 times 246:
          // no carry or borrow between bytes).
          low_ = x - ((x >> 7) & kBytes01) * 0xF6;
          value_ = v;
          return true;
        }
      } else if (const std::uint64_t down = 0 - up; down < kMaxStep) {
        if (down != step_) set_step(down);
        // A borrow out of the eighth digit: from scratch.
        if (!__builtin_sub_overflow(low_, step_digits_, &x)) {
          // Each byte got a - b - borrow: where that is below 0 the byte wrapped to 256 + it
          // (246 - 255, top bit set) and borrowed from the next one through the subtraction
          // itself; taking 246 from it leaves 10 + it, the digit.
          low_ = x - ((x >> 7) & kBytes01) * 0xF6;
          value_ = v;
          return true;
        }
      }
    }
    if (v < 0 || v >= kLimit) return false;
    reset(v, negative);
    return true;
  }
  std::int64_t value() const { return value_; }

  // The integer as fmt's "{}" (write_integer) writes it, without the sign: its digits, and up
  // to 8 bytes of no meaning after them (16 bytes are written at p). Returns the end.
  [[gnu::always_inline]] char* write_integer(char* p) const {
    put(p, int_head_);
    put(p + int_head_size_, low_text() >> low_shift_);
    return p + size_;
  }

  // The signed decimal value() x 10^-decimals() as fmt's "{}" writes a double whose shortest
  // digits it is (the point placed, trailing zeros cut: write_shortest_scaled's layout), where
  // that is fixed notation (the first digit's exponent at least -4), there are at most 15
  // digits and the whole part, sign and point take at most 8 - (decimals() - 8) characters.
  // nullptr (nothing written) otherwise. With decimals() 9 that is write_seconds_of_ns's text
  // for 10^5 <= value() < 10^15. Up to 8 bytes of no meaning after the text (16 bytes are
  // written at p).
  [[gnu::always_inline]] char* write_decimal(char* p) const {
    if (!fixed_) return nullptr;
    put(p, head_);  // the sign, the whole part, the point, the decimals before the last 8
    put(p + head_size_, low_text());  // the last eight decimals
    // The last decimal other than 0: digits are 0 - 9 a byte, so + 0x7F sets a byte's top bit
    // exactly where it is not 0, with no carry into the next byte (byte k is digit 10^k).
    const std::uint64_t nonzero = (low_ + kBytes7F) & kBytes80;
    if (nonzero == 0) return p + size_if_low_zero_;
    return p + head_size_ + 8 - std::countr_zero(nonzero) / 8;
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
    step_digits_ = digit_bytes(static_cast<std::uint32_t>(step));
    step_ = step;
  }
  // v's digits from scratch (the first value, a long step, a carry or borrow beyond the eighth
  // digit, another count of digits, another sign): the low eight as bytes, and the text before
  // them, as an integer and as a decimal, which the steps leave as they are.
  [[gnu::noinline]] void reset(std::int64_t v, bool negative) {
    const auto u = static_cast<std::uint64_t>(v);
    const auto high = static_cast<std::uint32_t>(u / kMaxStep);  // < 10^8: v < 10^16
    low_ = digit_bytes(static_cast<std::uint32_t>(u % kMaxStep));
    value_ = v;
    negative_ = negative;
    size_ = fmt::detail::count_digits(u);
    bound_ = size_ >= 16 ? kLimit : static_cast<std::int64_t>(pow10(size_));
    lower_ = size_ <= 1 ? 0 : static_cast<std::int64_t>(pow10(size_ - 1));
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
    // As a decimal: the sign, the whole part ("0" if none), the point, the decimals before the
    // last eight (decimals_ - 8 of them, leading zeros included), then the eight, cut after
    // their last digit other than 0. Fixed notation (fmt's from a first digit of 10^-4 on),
    // at most 15 digits (the callers' proofs), the text before the eight in one word.
    const int high_decimals = decimals_ - 8;
    const std::uint64_t whole = u / pow10(decimals_);
    const int whole_size = fmt::detail::count_digits(whole);
    head_size_ = (negative ? 1 : 0) + whole_size + 1 + high_decimals;
    fixed_ = v > 0 && high_decimals >= 0 && size_ - 1 - decimals_ >= -4 && size_ <= 15 &&
             head_size_ <= 8;
    if (!fixed_) return;
    char head[16]{};  // zeroed: head_ takes 8 bytes of it whatever head_size_ is
    char* h = head;
    if (negative) *h++ = '-';
    shortest_detail::write_last(h, static_cast<std::uint32_t>(whole), whole_size);
    h += whole_size;
    *h++ = '.';
    std::uint32_t rest = high % static_cast<std::uint32_t>(pow10(high_decimals));
    for (int i = high_decimals - 1; i >= 0; --i, rest /= 10)
      h[i] = static_cast<char>('0' + rest % 10);
    std::memcpy(&head_, head, 8);
    // Where the eight are all 0: the head with its decimals' trailing zeros cut, and its
    // point too if none is left.
    int end = head_size_;
    while (end > head_size_ - high_decimals && head[end - 1] == '0') --end;
    size_if_low_zero_ = head[end - 1] == '.' ? end - 1 : end;
  }
  static constexpr std::uint64_t pow10(int n) {
    std::uint64_t p = 1;
    for (int i = 0; i < n; ++i) p *= 10;
    return p;
  }

  std::uint64_t low_ = 0;          // the last eight digits, digit 10^k in byte k
  std::uint64_t step_digits_ = 0;  // step_'s digits so
  std::uint64_t step_ = kMaxStep;  // (none yet)
  std::int64_t value_ = 0;
  std::int64_t bound_ = 0, lower_ = 0;  // 10^size_, 10^(size_ - 1) (0 before the first value)
  int size_ = 0;                        // digits
  int decimals_ = 9;
  bool negative_ = false;
  std::uint64_t int_head_ = 0, head_ = 0;
  int int_head_size_ = 0, low_shift_ = 0;
  int head_size_ = 0, size_if_low_zero_ = 0;
  bool fixed_ = false;
};

// One stream's readings as write_shortest_quantised writes them (fmt's "{}"), each from the
// previous one's digits where it can be: a stored reading is the double of a decimal at its
// instrument's resolution (a gauge's nanometres, an interferometer's picometres, in metres),
// and from one sample to the next it moves by a few units of that resolution. The stream's
// decimals k are learnt from a reading written the full way (at least 8; none while the
// stream's readings have more than 15); then a reading v is m x 10^-k with m = |v| 10^k
// rounded, proven as write_shortest_quantised proves its guess (|v| 10^k < 2^51, and m / 10^k,
// one correctly rounded division, == |v|: that decimal is Dragonbox's shortest), and m's
// digits are the last reading's with the difference added or taken away (RunningDecimal).
// Anything else is written by write_shortest_quantised: the same text for every double.
class RunningReading {
 public:
  [[gnu::always_inline]] char* write(char* p, double v) {
    if (decimals_ != 0) {
      const double a = std::abs(v);
      const double scale = shortest_detail::kPow10[decimals_];
      const double x = a * scale;  // rounded: below 2^51 only if |v| 10^k is (false for nan)
      if (x < 0x1p51) {
        const auto m = static_cast<std::int64_t>(x + 0.5);
        if (static_cast<double>(m) / scale == a && digits_.set<true>(m, std::signbit(v)))
          if (char* const end = digits_.write_decimal(p)) return end;
      }
    }
    // A stream whose readings have more than 15 digits skips write_shortest_quantised's guess,
    // which would fail for most of them (86 % of the bench's): its division and check, then
    // write_shortest anyway.
    char* const end = long_ ? write_shortest(p, v) : write_shortest_quantised(p, v);
    // Learn the decimals from this text (while the stream has none, from one reading in 256).
    if (decimals_ != 0 || ++skipped_ >= 256) learn(p, end);
    return end;
  }

 private:
  [[gnu::noinline]] void learn(const char* p, const char* end) {
    skipped_ = 0;
    const char* point = std::find(p, end, '.');
    const bool exponent = std::find(p, end, 'e') != end;
    const auto written = point == end ? 0 : static_cast<int>(end - point - 1);
    const int decimals = exponent || written > 15 ? 0 : std::max(8, written);
    if (decimals != decimals_ && decimals != 0) digits_.set_decimals(decimals);
    decimals_ = decimals;
    long_ = written > 15;
  }
  RunningDecimal digits_{8};
  int decimals_ = 0;   // k (0: none yet, or the stream's readings have more than 15)
  int skipped_ = 255;  // (the first reading is learnt from)
  bool long_ = false;  // the last reading learnt from had more than 15 decimals
};

}  // namespace daq
