// RunningDecimal (daq/src/results/running_decimal.hpp) makes each value's digits from the
// previous value's by a decimal add: its text must be, for every sequence of values, what the
// full conversions write (write_integer, write_seconds_of_ns) and what the integer's own
// decimal is (fmt's "{}" of the integer; the seconds built from that text by hand).
#include "running_decimal.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

namespace {

// The seconds of v nanoseconds by hand from the integer's text: nine digits after the point
// (zeros put in front as needed), the trailing zeros and then a lone point cut.
std::string seconds_by_hand(std::int64_t v) {
  std::string digits = fmt::format("{}", v);
  if (digits.size() < 10) digits.insert(0, 10 - digits.size(), '0');
  std::string text = digits.substr(0, digits.size() - 9) + "." + digits.substr(digits.size() - 9);
  while (text.back() == '0') text.pop_back();
  if (text.back() == '.') text.pop_back();
  return text;
}

// The first value of `values`, set in turn on one RunningDecimal (steps back by the
// subtraction with Back, else from scratch), whose text differs from the full conversions' or
// the by-hand decimal's; "" when every one agrees.
template <bool Back>
std::string first_difference_of(const std::vector<std::int64_t>& values) {
  daq::RunningDecimal d;
  char got[64], want[64];
  for (std::size_t i = 0; i < values.size(); ++i) {
    const std::int64_t v = values[i];
    const bool in_range = v >= 0 && v < 10'000'000'000'000'000;
    if (d.template set<Back>(v) != in_range)
      return fmt::format("#{} {}: set() gave {}", i, v, !in_range);
    if (!in_range) continue;
    const std::string integer(got, d.write_integer(got));
    if (integer != std::string(want, daq::write_integer(want, v)) ||
        integer != fmt::format("{}", v))
      return fmt::format("#{} {} (after {}): integer \"{}\"", i, v, i ? values[i - 1] : -1,
                         integer);
    char* const end = d.write_decimal(got);
    const bool fixed = v >= 100'000 && v < 1'000'000'000'000'000;
    if ((end != nullptr) != fixed)
      return fmt::format("#{} {}: write_decimal {}", i, v, end ? "wrote" : "refused");
    if (!fixed) continue;
    const std::string seconds(got, end);
    if (seconds != std::string(want, daq::write_seconds_of_ns(want, v)) ||
        seconds != seconds_by_hand(v))
      return fmt::format("#{} {} (after {}): seconds \"{}\", by hand \"{}\"", i, v,
                         i ? values[i - 1] : -1, seconds, seconds_by_hand(v));
  }
  return {};
}

// Both ways.
std::string first_difference(const std::vector<std::int64_t>& values) {
  return first_difference_of<false>(values) + first_difference_of<true>(values);
}

TEST(RunningDecimal, ByHand) {
  // The by-hand reference itself: 1.5 s, 0.0003 s, 12.78 s, a whole second.
  EXPECT_EQ(seconds_by_hand(1'500'000'000), "1.5");
  EXPECT_EQ(seconds_by_hand(300'000), "0.0003");
  EXPECT_EQ(seconds_by_hand(12'780'000'000), "12.78");
  EXPECT_EQ(seconds_by_hand(2'000'000'000), "2");
  daq::RunningDecimal d;
  char text[64];
  ASSERT_TRUE(d.set(999'999'900));
  ASSERT_TRUE(d.set(1'000'000'000));  // a tenth digit
  EXPECT_EQ(std::string(text, d.write_integer(text)), "1000000000");
  EXPECT_EQ(std::string(text, d.write_decimal(text)), "1");
  ASSERT_TRUE(d.set(1'000'100'000));  // + 100 us, by the add
  EXPECT_EQ(std::string(text, d.write_decimal(text)), "1.0001");
  ASSERT_TRUE(d.set(1'999'999'999));  // a carry through eight 9s next
  ASSERT_TRUE(d.set(2'000'000'001));
  EXPECT_EQ(std::string(text, d.write_decimal(text)), "2.000000001");
  EXPECT_EQ(std::string(text, d.write_integer(text)), "2000000001");
}

TEST(RunningDecimal, CarriesThroughNinesAndNewDigits) {
  std::vector<std::int64_t> values;
  // Around every power of ten up to 10^16 (where set() starts refusing), by steps of 1, 7,
  // 99,999 and 100,000 (the bench's 100 us), each sequence through the digit count's change.
  std::int64_t p = 1;
  for (int e = 0; e <= 16; ++e, p *= 10) {
    for (std::int64_t step : {1, 7, 99'999, 100'000, 99'999'999}) {
      for (std::int64_t v = std::max<std::int64_t>(0, p - 40 * step); v <= p + 40 * step; v += step)
        values.push_back(v);
    }
    // Runs of 9s in the middle: ...x999999y + small steps carrying through them.
    for (std::int64_t nines = 9; nines < p && nines < 1'000'000'000'000'000; nines = nines * 10 + 9)
      for (std::int64_t v = p + nines - 20; v <= p + nines + 20; v += 3) values.push_back(v);
  }
  values.push_back(9'999'999'999'999'999);  // the last value of 16 digits: by the add
  values.push_back(9'999'999'999'999'990);
  values.push_back(9'999'999'999'999'999);
  values.push_back(10'000'000'000'000'000);  // 10^16: refused
  values.push_back(9'999'999'999'999'999);
  EXPECT_EQ(first_difference(values), "");
}

TEST(RunningDecimal, AStreamsGridFromZero) {
  // The bench's stream: 0, then every 100 us for 200 s (2 M values, every count of trailing
  // zeros of the seconds), and the same grid offset as a session clock's nanoseconds.
  std::vector<std::int64_t> values;
  for (std::int64_t k = 0; k < 2'000'000; ++k) values.push_back(k * 100'000);
  EXPECT_EQ(first_difference(values), "");
  values.clear();
  for (std::int64_t k = 0; k < 1'000'000; ++k) values.push_back(86'399'123'456'789 + k * 100'000);
  EXPECT_EQ(first_difference(values), "");
}

TEST(RunningDecimal, JitterStepsBackZeroStepsAndLongSteps) {
  std::mt19937_64 rng(32);
  std::vector<std::int64_t> values;
  std::int64_t v = 0;
  for (int i = 0; i < 2'000'000; ++i) {
    const auto kind = rng() % 100;
    if (kind < 70) {
      v += 100'000 + static_cast<std::int64_t>(rng() % 2001) - 1000;  // jitter of +-1 us
    } else if (kind < 80) {
      // unchanged (a group's readings share their time)
    } else if (kind < 85) {
      v -= static_cast<std::int64_t>(rng() % 1'000'000);  // a step back
    } else if (kind < 90) {
      v += 99'999'990 + static_cast<std::int64_t>(rng() % 20);  // about 10^8: either way
    } else if (kind < 93) {
      v += static_cast<std::int64_t>(rng() % 100'000'000'000);  // long steps
    } else if (kind < 95) {
      v = -static_cast<std::int64_t>(rng() % 1000);  // refused: the next starts again
    } else if (kind < 96) {
      v = static_cast<std::int64_t>(rng() % 10'000'000'000'000'000);  // anywhere
    } else {
      v += static_cast<std::int64_t>(rng() % 10);
    }
    if (v >= 10'000'000'000'000'000) v = 0;
    values.push_back(v);
  }
  EXPECT_EQ(first_difference(values), "");
}

TEST(RunningDecimal, RandomStartsAndStepsEveryDigitCount) {
  // From random values of every digit count, 2,000 steps each of a random size of 1 to 8
  // digits, so carries run through random digits.
  std::mt19937_64 rng(7);
  std::vector<std::int64_t> values;
  std::int64_t p = 1;
  for (int e = 0; e < 16; ++e, p *= 10) {
    for (int start = 0; start < 20; ++start) {
      std::int64_t v = p + static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(9 * p));
      std::int64_t step = 1;
      for (int k = static_cast<int>(rng() % 8); k > 0; --k) step *= 10;
      step += static_cast<std::int64_t>(rng() % static_cast<std::uint64_t>(step));
      for (int i = 0; i < 2'000; ++i) {
        values.push_back(v);
        v += step;
        if (v >= 10'000'000'000'000'000) break;
      }
    }
  }
  EXPECT_EQ(first_difference(values), "");
}

// The first reading of `values`, written in turn by one RunningReading, whose text differs
// from fmt's "{}"; "" when every one agrees.
std::string first_reading_difference(const std::vector<double>& values) {
  daq::RunningReading stream;
  char got[64];
  for (std::size_t i = 0; i < values.size(); ++i) {
    const std::string text(got, stream.write(got, values[i]));
    if (text != fmt::format("{}", values[i]))
      return fmt::format("#{} {:a} (after {}): \"{}\", fmt \"{}\"", i, values[i],
                         i ? fmt::format("{}", values[i - 1]) : "-", text,
                         fmt::format("{}", values[i]));
  }
  return {};
}

// A reading as a driver stores it: its printed count over the exact power of ten, one correctly
// rounded division (the decimal's own double, docs/codecs.md "Readings in SI").
double stored(std::int64_t count, int decimals) {
  return static_cast<double>(count) / std::pow(10.0, decimals);
}

TEST(RunningReading, ByHand) {
  daq::RunningReading stream;
  char text[64];
  const auto write = [&](double v) { return std::string(text, stream.write(text, v)); };
  EXPECT_EQ(write(0.100000123), "0.100000123");  // a 1 nm gauge's 100.000123 mm, in metres
  EXPECT_EQ(write(0.100000124), "0.100000124");  // by the add
  EXPECT_EQ(write(0.10000012), "0.10000012");    // by the subtraction, a trailing zero cut
  EXPECT_EQ(write(0.0999999), "0.0999999");      // a digit fewer
  EXPECT_EQ(write(-0.0999999), "-0.0999999");    // the sign
  EXPECT_EQ(write(0.1), "0.1");
  EXPECT_EQ(write(0.10000000000000002), "0.10000000000000002");  // not a 1 nm decimal
}

TEST(RunningReading, GaugesAndInterferometersAsStored) {
  std::mt19937_64 rng(230);
  std::vector<double> values;
  // Random walks at 1 nm, 0.1 um, 1 pm and 10 pm in metres around 0.1 m (crossing it: a digit
  // fewer), around 0 (the sign), around 1 m and 12.3 m, with steps of -3..3 units, now and
  // then a jump of up to 10^9 units.
  for (int decimals : {6, 7, 9, 11, 12}) {
    for (std::int64_t start : {100'000'000LL, 0LL, 1'000'000'000LL, 12'300'000'000LL}) {
      std::int64_t count = start * static_cast<std::int64_t>(std::pow(10.0, decimals - 9));
      if (decimals < 9) count = start / static_cast<std::int64_t>(std::pow(10.0, 9 - decimals));
      for (int i = 0; i < 100'000; ++i) {
        values.push_back(stored(count, decimals));
        count += static_cast<std::int64_t>(rng() % 7) - 3;
        if (rng() % 1000 == 0)
          count += static_cast<std::int64_t>(rng() % 2'000'000'001) - 1'000'000'000;
      }
    }
  }
  EXPECT_EQ(first_reading_difference(values), "");
}

TEST(RunningReading, TheBenchsValuesAndTheAir) {
  std::vector<double> values;
  for (std::int64_t i = 0; i < 600'000; ++i) {
    const double length_m =
        0.1 + 1e-6 * std::sin(1e-4 * static_cast<double>(i)) + 1e-9 * static_cast<double>(i % 977);
    values.push_back(stored(std::llround(length_m * 1e9), 9));  // quantised, as stored
  }
  for (std::int64_t i = 0; i < 100'000; ++i)  // unquantised: 16 - 17 digits
    values.push_back(0.1 + 1e-6 * std::sin(1e-4 * static_cast<double>(i)) +
                     1e-9 * static_cast<double>(i % 977));
  for (std::int64_t s = 0; s < 20'000; ++s) {  // a PTU300's air
    values.push_back(stored(2000 + s / 10, 2));
    values.push_back(stored(10132500 - 10 * s, 2) * 100);  // hPa in Pa
    values.push_back(stored(450 + s / 100, 1));
  }
  EXPECT_EQ(first_reading_difference(values), "");
}

TEST(RunningReading, EveryDecimalCountEdgesAndNonNumbers) {
  std::mt19937_64 rng(17);
  std::vector<double> values;
  // Walks at every count of decimals 0..20 from random starts of every size.
  for (int decimals = 0; decimals <= 20; ++decimals)
    for (int digits = 1; digits <= 17; ++digits)
      for (int start = 0; start < 3; ++start) {
        std::int64_t count = static_cast<std::int64_t>(
            rng() % static_cast<std::uint64_t>(std::pow(10.0, std::min(digits, 17))));
        for (int i = 0; i < 300; ++i) {
          values.push_back((i & 64) ? -stored(count, decimals) : stored(count, decimals));
          count += static_cast<std::int64_t>(rng() % 2001) - 1000;
          if (count < 0) count = -count;
        }
      }
  // Every power of ten from 1e-25 to 1e25 and its neighbours, zero, -0, subnormals, inf, nan,
  // 10^-4 and below it (exponent notation), random bit patterns, each after a stream's usual
  // reading and before it again.
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> edges = {0.0,
                               -0.0,
                               1e-4,
                               9.9999e-5,
                               1e-5,
                               0.00012345678,
                               inf,
                               -inf,
                               std::numeric_limits<double>::quiet_NaN(),
                               4.9e-324,
                               2.2250738585072014e-308,
                               1e15,
                               999999999999999.0,
                               1e16,
                               123456789012345.6,
                               0.1 + 0.2};
  for (int e = -25; e <= 25; ++e) {
    const double p = std::pow(10.0, e);
    edges.push_back(p);
    edges.push_back(std::nextafter(p, 0.0));
    edges.push_back(std::nextafter(p, inf));
  }
  for (int i = 0; i < 20'000; ++i) {
    const auto bits = rng();
    double v = 0;
    std::memcpy(&v, &bits, 8);
    edges.push_back(v);
  }
  for (double edge : edges) {
    values.push_back(0.100000123);
    values.push_back(edge);
    values.push_back(0.100000124);
  }
  EXPECT_EQ(first_reading_difference(values), "");
}

}  // namespace
