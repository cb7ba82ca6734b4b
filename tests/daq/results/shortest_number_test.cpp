// write_shortest (daq/src/results/shortest_number.hpp) writes every double character for
// character as fmt's "{}" does: the exports' bytes must not change with the faster writer.
#include "shortest_number.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <bit>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <string_view>
#include <vector>

namespace {

std::string shortest(double v) {
  char buf[64];
  return std::string(buf, daq::write_shortest(buf, v));
}

// The first value that differs, for the failure message; "" when all agree.
template <class Values>
std::string first_difference(const Values& values) {
  for (double v : values) {
    const std::string want = fmt::format("{}", v), got = shortest(v);
    if (got != want || got.size() > 24)
      return fmt::format("{:a}: fmt \"{}\", write_shortest \"{}\"", v, want, got);
  }
  return {};
}

TEST(ShortestNumber, EdgesAsFmtWritesThem) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  const std::vector<double> edges = {0.0,
                                     -0.0,
                                     1.0,
                                     -1.0,
                                     0.1,
                                     100653.0,
                                     20.59,
                                     1e-4,
                                     9.9999e-5,
                                     1e-5,
                                     0.00012345678901234567,
                                     1e15,
                                     1e16,
                                     9999999999999998.0,
                                     1234567890123456.7,
                                     12345678901234567.0,
                                     1e21,
                                     1e100,
                                     1e-100,
                                     123e-300,
                                     DBL_MAX,
                                     -DBL_MAX,
                                     DBL_MIN,
                                     DBL_TRUE_MIN,
                                     std::nextafter(DBL_MIN, 0.0),
                                     std::ldexp(1.0, 53),
                                     std::ldexp(1.0, 53) + 2,
                                     inf,
                                     -inf,
                                     std::numeric_limits<double>::quiet_NaN()};
  EXPECT_EQ(first_difference(edges), "");
  EXPECT_EQ(shortest(1e16), "1e+16");  // the notation switch: a check of the test's reference
  EXPECT_EQ(shortest(0.0001), "0.0001");
  EXPECT_EQ(shortest(-0.0), "-0");
}

TEST(ShortestNumber, EveryPowerOfTenAndItsNeighbours) {
  std::vector<double> values;
  for (int e = -324; e <= 308; ++e) {
    const double p = std::pow(10.0, e);
    for (double v :
         {p, std::nextafter(p, 0.0), std::nextafter(p, std::numeric_limits<double>::infinity()), -p,
          3 * p, 9.5 * p})
      if (std::isfinite(v)) values.push_back(v);
  }
  EXPECT_EQ(first_difference(values), "");
}

TEST(ShortestNumber, RandomBitPatterns) {
  std::mt19937_64 rng(32);
  std::vector<double> values(2'000'000);
  for (auto& v : values) v = std::bit_cast<double>(rng());
  EXPECT_EQ(first_difference(values), "");
}

// Random significands at every binary exponent (subnormals, the least and largest normal
// significands of each), both signs, as fmt's "{}" writes them.
TEST(ShortestNumber, EveryBinaryExponentAsFmtWritesIt) {
  std::mt19937_64 rng(2046);
  std::vector<double> values;
  for (std::uint64_t biased = 0; biased < 2047; ++biased)
    for (int i = 0; i < 150; ++i) {
      std::uint64_t fraction = rng() & ((std::uint64_t{1} << 52) - 1);
      if (i == 0) fraction = 0;
      if (i == 1) fraction = 1;
      if (i == 2) fraction = (std::uint64_t{1} << 52) - 1;
      const auto v = std::bit_cast<double>((biased << 52) | fraction);
      values.push_back(v);
      values.push_back(-v);
    }
  EXPECT_EQ(first_difference(values), "");
}

// Unquantised readings as an export holds them (16 - 17 significant digits, 1e-6 to 1e3),
// every power of two with its neighbours (the narrower lower half-interval at 2^e), whole
// numbers around 2^53 - 2^56 (spacings of 2 and 4), and the notation switches at 1e-4 (fixed
// from there) and 1e16 (exponent from there) with 16 and 17 digits.
TEST(ShortestNumber, UnquantisedReadingsAndEdgesAsFmtWritesThem) {
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> decade(-6.0, 3.0);
  std::vector<double> values;
  for (int i = 0; i < 1'500'000; ++i) {
    const double v = std::pow(10.0, decade(rng));
    values.push_back(i % 2 == 0 ? v : -v);
  }
  const auto with_neighbours = [&](double v, int n) {
    double up = v, down = v;
    for (int i = 0; i <= n; ++i) {
      values.push_back(up);
      values.push_back(down);
      up = std::nextafter(up, std::numeric_limits<double>::infinity());
      down = std::nextafter(down, 0.0);
    }
  };
  for (int e = -1074; e <= 1023; ++e) with_neighbours(std::ldexp(1.0, e), 3);
  for (int e = 52; e <= 57; ++e) with_neighbours(std::ldexp(1.0, e), 2000);
  for (double edge : {1e-5, 1e-4, 1e-3, 1.0, 10.0, 1e15, 1e16, 1e17}) with_neighbours(edge, 3000);
  for (double v :
       {0.000099999999999999991, 0.00010000000000000002, 1234567890123456.8, 9999999999999998.0,
        12345678901234568.0, 0.12345678901234568, 5e-324, 2.2250738585072009e-308})
    with_neighbours(v, 2);
  EXPECT_EQ(first_difference(values), "");
  EXPECT_EQ(shortest(0.12345678901234568), "0.12345678901234568");  // 17 digits, fixed
  EXPECT_EQ(shortest(1234567890123456.8), "1234567890123456.8");
  EXPECT_EQ(shortest(0.00012345678901234567), "0.00012345678901234567");
  EXPECT_EQ(shortest(1.2345678901234568e-05), "1.2345678901234568e-05");
  EXPECT_EQ(shortest(12345678901234568.0), "1.2345678901234568e+16");
}

// What exports hold: times in seconds at ns resolution, lengths in m, air values, integers.
TEST(ShortestNumber, ValuesLikeAnExportsNumbers) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<double> values;
  for (int i = 0; i < 500'000; ++i) {
    values.push_back(static_cast<double>(rng() % 36'000'000'000'000ULL) * 1e-9);  // 10 h in s
    values.push_back(0.1 + 1e-6 * std::sin(1e-4 * i) + 1e-9 * (i % 977));
    values.push_back(std::round(unit(rng) * 1e6) / 100.0);  // 20.59, 1013.25
    values.push_back(static_cast<double>(rng() >> 11));     // whole numbers below 2^53
    values.push_back((unit(rng) - 0.5) * std::pow(10.0, static_cast<int>(rng() % 40) - 20));
  }
  EXPECT_EQ(first_difference(values), "");
}

// write_shortest_scaled(v, m, k) skips the digit search where the decimal m x 10^-k is v's
// shortest form: its text must be fmt's "{}" of v whatever m and k are, and read back as v.
std::string scaled_difference(double v, std::int64_t m, int k) {
  char buf[64];
  const std::string got(buf, daq::write_shortest_scaled(buf, v, m, k));
  const std::string want = fmt::format("{}", v);
  if (got != want || got.size() > 24)
    return fmt::format("{:a} from {} x 10^-{}: fmt \"{}\", write_shortest_scaled \"{}\"", v, m, k,
                       want, got);
  if (std::isfinite(v) && std::strtod(got.c_str(), nullptr) != v)
    return fmt::format("{:a}: \"{}\" reads back as {:a}", v, got,
                       std::strtod(got.c_str(), nullptr));
  return {};
}

TEST(ShortestNumber, ScaledTimesAsFmtWritesThem) {
  std::mt19937_64 rng(11);
  std::size_t checked = 0;
  const auto check = [&](double v, std::int64_t m, int k) {
    ++checked;
    const auto d = scaled_difference(v, m, k);
    ASSERT_EQ(d, "");
  };
  // An export's times: nanoseconds of every magnitude up to 10 days, as the export scales
  // them (x 1e-9, not always the double nearest the decimal), on grids of 100 us to 1 ns.
  for (int i = 0; i < 1'000'000; ++i) {
    const std::int64_t grid = std::int64_t{1} << (rng() % 4) * 6;  // 1, 64, 4096, 262144
    const std::int64_t ns =
        static_cast<std::int64_t>(rng() % (864'000'000'000'000ULL >> (rng() % 40))) / grid * grid *
        (i % 7 == 0 ? -1 : 1);
    check(static_cast<double>(ns) * 1e-9, ns, 9);
    check(static_cast<double>(ns) / 1e9, ns, 9);
    check(static_cast<double>(ns / 100'000 * 100'000) * 1e-9, ns / 100'000 * 100'000, 9);
  }
  // Every k a double's power of ten holds, m of every length, v the decimal and its
  // neighbours (the decimal is then not v's shortest form or not v at all).
  for (int i = 0; i < 1'000'000; ++i) {
    const int k = static_cast<int>(rng() % 25) - 1;  // -1 and 23: outside the fast path
    const auto m = static_cast<std::int64_t>(rng() >> (1 + rng() % 63)) * (i % 5 == 0 ? -1 : 1);
    const double v = k >= 0 ? static_cast<double>(m) / std::pow(10.0, k) : static_cast<double>(m);
    check(v, m, k);
    check(std::nextafter(v, 0.0), m, k);
    check(std::nextafter(v, std::numeric_limits<double>::infinity()), m, k);
    check(-v, m, k);
  }
  // Whole numbers and their zeros, zero itself, powers of ten, the limits of the fast path
  // (2^53, 2^51 x 10^-k), and guesses that are wrong.
  for (int k = 0; k <= 22; ++k)
    for (std::int64_t m :
         {std::int64_t{1}, std::int64_t{10}, std::int64_t{1000000000}, std::int64_t{120000},
          (std::int64_t{1} << 53) - 1, std::int64_t{1} << 53, (std::int64_t{1} << 51) + 7,
          std::int64_t{9007199254740990}, std::int64_t{0}}) {
      const double v = static_cast<double>(m) / std::pow(10.0, k);
      check(v, m, k);
      check(v, m + 1, k);
      check(v * 10, m, k);
      check(std::ldexp(1.0, 51 - 4 * k), m, k);
    }
  check(0.0, 0, 9);
  check(-0.0, 0, 9);
  check(DBL_TRUE_MIN, 1, 9);
  check(std::numeric_limits<double>::infinity(), 1, 9);
  check(std::numeric_limits<double>::quiet_NaN(), 1, 9);
  EXPECT_GT(checked, 6'000'000U);
}

// The nanoseconds' own way (k = 9): the edges of its conditions, each against fmt and strtod.
// fmt's fixed notation starts at 1e-4 s (10^5 ns; 99,999 ns is 9.9999e-05); a whole second
// has no point; a fraction whose only nonzero decimal is the first has one (its other eight
// digits are the word the trailing zeros are counted in); 2^51 / 10^d is where a decimal with
// d decimals stops being the only one that close to v.
TEST(ShortestNumber, ScaledNanosecondsAtTheEdgesOfTheirOwnWay) {
  std::vector<std::int64_t> ns = {1,
                                  99'999,
                                  100'000,
                                  100'001,
                                  999'999'999,
                                  1'000'000'000,
                                  1'000'000'001,
                                  1'500'000'000,
                                  1'050'000'000,
                                  1'000'000'010,
                                  600'000'000'000,
                                  (std::int64_t{1} << 53) - 1,
                                  std::int64_t{1} << 53};
  for (int d = 0; d <= 9; ++d) {  // about 2^51 / 10^d seconds, a decimal of d decimals
    const double limit_s = std::ldexp(1.0, 51) / std::pow(10.0, d);
    const auto at = static_cast<std::int64_t>(limit_s) * 1'000'000'000;
    for (std::int64_t step : {std::int64_t{-1}, std::int64_t{0}, std::int64_t{1}})
      for (std::int64_t fraction : {std::int64_t{0}, std::int64_t{100'000'000}, std::int64_t{1}})
        if (at + step * 1'000'000'000 + fraction < (std::int64_t{1} << 53))
          ns.push_back(at + step * 1'000'000'000 + fraction);
  }
  std::mt19937_64 rng(5);
  for (int i = 0; i < 200'000; ++i)  // every count of trailing zeros in the fraction
    ns.push_back(static_cast<std::int64_t>(rng() % 100'000'000'000'000ULL) /
                 static_cast<std::int64_t>(std::pow(10.0, rng() % 10)) *
                 static_cast<std::int64_t>(std::pow(10.0, rng() % 10)));
  for (const auto n : ns) {
    for (const double v : {static_cast<double>(n) * 1e-9, static_cast<double>(n) / 1e9}) {
      ASSERT_EQ(scaled_difference(v, n, 9), "") << n;
      ASSERT_EQ(scaled_difference(std::nextafter(v, 0.0), n, 9), "") << n;
      ASSERT_EQ(scaled_difference(std::nextafter(v, 1e300), n, 9), "") << n;
    }
  }
  char buf[64];
  EXPECT_EQ(std::string(buf, daq::write_shortest_scaled(buf, 1.5, 1'500'000'000, 9)), "1.5");
  EXPECT_EQ(std::string(buf, daq::write_shortest_scaled(buf, 1e-4, 100'000, 9)), "0.0001");
  EXPECT_EQ(std::string(buf, daq::write_shortest_scaled(buf, 1.000000001, 1'000'000'001, 9)),
            "1.000000001");
}

// Values whose shortest form is known by hand: times on a 100 us grid, a whole number, a guess
// with its decimal point outside the fast path (k < 0).
TEST(ShortestNumber, ScaledTimesOfAFineGridAreTheirDecimals) {
  char buf[64];
  EXPECT_EQ(std::string(buf, daq::write_shortest_scaled(buf, 12.3456, 12'345'600'000, 9)),
            "12.3456");
  EXPECT_EQ(std::string(buf, daq::write_shortest_scaled(buf, -0.0001, -100'000, 9)), "-0.0001");
  EXPECT_EQ(std::string(buf, daq::write_shortest_scaled(buf, 600.0, 600'000'000'000, 9)), "600");
  EXPECT_EQ(std::string(buf, daq::write_shortest_scaled(buf, 1e15, 1, -15)), "1000000000000000");
}

// write_shortest_quantised skips the digit search where a reading is its decimal's own double:
// its text must be fmt's "{}" for every double, and read back as it. Readings as drivers store
// them (a gauge's printed mm with 0 - 6 decimals x 1e-3, an IDS3010's integer pm x 1e-12, um x
// 1e-6, a PTU300's hPa x 100: about a quarter of them rounded off their decimal's double by the
// conversion, so both ways are taken), decimals m / 10^d of every d and length, each with its
// neighbours (not the decimal's double: the digit search), and unquantised values (random bit
// patterns, the bench's 16 - 17 digit lengths, values around 2^51 where the guess stops).
std::string quantised_difference(double v) {
  char buf[64];
  const std::string got(buf, daq::write_shortest_quantised(buf, v));
  const std::string want = fmt::format("{}", v);
  if (got != want || got.size() > 24)
    return fmt::format("{:a}: fmt \"{}\", write_shortest_quantised \"{}\"", v, want, got);
  if (std::isfinite(v) && std::strtod(got.c_str(), nullptr) != v)
    return fmt::format("{:a}: \"{}\" reads back as {:a}", v, got,
                       std::strtod(got.c_str(), nullptr));
  return {};
}

TEST(ShortestNumber, QuantisedReadingsAsFmtWritesThem) {
  std::mt19937_64 rng(32);
  std::size_t checked = 0;
  const auto check = [&](double v) {
    for (const double w : {v, -v, std::nextafter(v, 0.0), std::nextafter(v, 1e300)}) {
      ++checked;
      ASSERT_EQ(quantised_difference(w), "");
    }
  };
  const auto below = [&](std::uint64_t n) { return static_cast<double>(rng() % n); };
  for (int i = 0; i < 300'000; ++i) {
    const int mm_decimals = static_cast<int>(rng() % 7);
    check(below(2'000'000'000) / std::pow(10.0, mm_decimals) * 1e-3);  // a gauge, mm
    check(below(5'000'000'000'000) * 1e-12);                           // an IDS3010, pm
    check(below(100'000'000) / 10.0 * 1e-6);                           // um, 0.1 um
    check(below(120'000) / 100.0 * 100.0);                             // a PTU300, hPa
    check(below(1'000'000) / 100.0);                                   // degC, %RH
    const int d = static_cast<int>(rng() % 23);                        // every d, any length
    check(static_cast<double>(rng() >> (11 + rng() % 53)) / std::pow(10.0, d));
    check(std::bit_cast<double>(rng()));                        // unquantised
    check(0.1 + 1e-6 * std::sin(1e-4 * i) + 1e-9 * (i % 977));  // the bench's lengths
    check(std::ldexp(1.0 + below(1'000'000) * 1e-6, static_cast<int>(rng() % 120) - 60));
  }
  // Where the guess's conditions change: around 2^51 (no decimals left) and 2^50, powers of
  // ten of every size, the smallest normal and subnormals, zero, inf and nan.
  for (int e = -80; e <= 60; ++e) check(std::ldexp(1.0, e));
  for (int e = -30; e <= 30; ++e) check(std::pow(10.0, e));
  for (double v :
       {0.0, DBL_MIN, DBL_TRUE_MIN, DBL_MAX, 0x1p51 - 0.25, 0x1p51 + 1.0, 2251.8,
        std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()})
    check(v);
  EXPECT_GT(checked, 10'000'000U);
}

// Readings whose text is known by hand: the bench's gauge at 100.000124 mm (1 nm) in metres;
// at 100.000123 mm the driver's x 1e-3 lands one ulp off 0.100000123's double (above it:
// 0.100000123 reads back as the next double down), so its shortest has 17 digits; an IDS3010's
// 123,456,789,012 pm, a pressure of 1013.25 hPa, a length of 123 nm (fmt's exponent form
// below 1e-4), and the bench's unquantised length of row 5 (17 digits: the digit search).
TEST(ShortestNumber, QuantisedReadingsAreTheirDecimals) {
  char buf[64];
  const auto text = [&](double v) {
    return std::string(buf, daq::write_shortest_quantised(buf, v));
  };
  EXPECT_EQ(text(100000124.0 / 1e6 * 1e-3), "0.100000124");
  EXPECT_EQ(text(100000123.0 / 1e6 * 1e-3), "0.10000012300000001");
  EXPECT_GT(100000123.0 / 1e6 * 1e-3, 0.100000123);
  EXPECT_EQ(text(123456789012.0 * 1e-12), "0.123456789012");
  EXPECT_EQ(text(1013.25 * 100.0), "101325");
  EXPECT_EQ(text(-123e-9), "-1.23e-07");
  EXPECT_EQ(text(0.1 + 1e-6 * std::sin(5e-4) + 5e-9), "0.10000000549999999");
  EXPECT_EQ(text(20.5), "20.5");
}

#if defined(__SSE2__)
// write16 (both halves of 8 digits in one SSE2 register) against write8 on each half (the
// scalar way, itself checked against fmt above): every seventh low half with a high half
// running the other way, random values, and the edges of its divisions (10^4, 10^8 and their
// neighbours, 9...9).
TEST(ShortestNumber, SixteenDigitsAtOnceAsEightAndEight) {
  const auto difference = [](std::uint64_t v) -> std::string {
    char got[16], want[16];
    daq::shortest_detail::write16(got, v);
    daq::shortest_detail::write8(want, static_cast<std::uint32_t>(v / 100'000'000));
    daq::shortest_detail::write8(want + 8, static_cast<std::uint32_t>(v % 100'000'000));
    if (std::memcmp(got, want, 16) == 0) return {};
    return fmt::format("{}: \"{}\" for \"{}\"", v, std::string_view(got, 16),
                       std::string_view(want, 16));
  };
  for (std::uint64_t low = 0; low < 100'000'000; low += 7)
    ASSERT_EQ(difference((99'999'999 - low) * 100'000'000 + low), "");
  std::mt19937_64 rng(17);
  for (int i = 0; i < 1'000'000; ++i) ASSERT_EQ(difference(rng() % 10'000'000'000'000'000ULL), "");
  for (std::uint64_t v : {0ULL, 9'999ULL, 10'000ULL, 10'001ULL, 99'999'999ULL, 100'000'000ULL,
                          100'000'001ULL, 999'999'999'999ULL, 9'999'999'999'999'999ULL})
    EXPECT_EQ(difference(v), "");
  char buf[16];
  daq::shortest_detail::write16(buf, 1'234'567'890'123'456ULL);
  EXPECT_EQ(std::string_view(buf, 16), "1234567890123456");
}
#endif

TEST(ShortestNumber, IntegersAsFmtWritesThem) {
  std::vector<std::int64_t> values = {0,
                                      1,
                                      -1,
                                      9,
                                      10,
                                      99,
                                      100,
                                      99'999'999,
                                      100'000'000,
                                      std::numeric_limits<std::int64_t>::max(),
                                      std::numeric_limits<std::int64_t>::min()};
  std::mt19937_64 rng(3);
  for (int i = 0; i < 1'000'000; ++i) {
    const auto v = static_cast<std::int64_t>(rng());
    values.push_back(v >> (rng() % 64));  // every length of digits, both signs
  }
  for (std::int64_t v : values) {
    char buf[32];
    const std::string got(buf, daq::write_integer(buf, v));
    ASSERT_EQ(got, fmt::format("{}", v));
  }
}

// write_seconds_of_ns, the exports' time_s column: fmt's "{}" of ns / 1e9 (the correctly rounded
// quotient) for every ns, read back by strtod as that double; below 10^15 ns also the exact
// decimal of ns x 10^-9, built here with strings (the integer's digits, the point put nine
// from the end, trailing zeros cut), independent of fmt and of the code.
std::string seconds_difference(std::int64_t ns) {
  char buf[64];
  const std::string got(buf, daq::write_seconds_of_ns(buf, ns));
  const double v = static_cast<double>(ns) / 1e9;
  const std::string want = fmt::format("{}", v);
  if (got != want || got.size() > 24)
    return fmt::format("{} ns: fmt \"{}\", write_seconds_of_ns \"{}\"", ns, want, got);
  if (std::strtod(got.c_str(), nullptr) != v) return fmt::format("{} ns: \"{}\" misread", ns, got);
  const std::uint64_t u =
      ns < 0 ? 0 - static_cast<std::uint64_t>(ns) : static_cast<std::uint64_t>(ns);
  if (u >= 1'000'000'000'000'000ULL || u < 100'000) return {};  // beyond 15 digits; d.ddde-XX
  std::string digits = std::to_string(u);
  digits.insert(0, std::string(digits.size() < 10 ? 10 - digits.size() : 0, '0'));
  std::string exact = digits.substr(0, digits.size() - 9) + "." + digits.substr(digits.size() - 9);
  while (exact.back() == '0') exact.pop_back();
  if (exact.back() == '.') exact.pop_back();
  if (ns < 0) exact.insert(0, "-");
  if (got != exact) return fmt::format("{} ns: \"{}\", the exact decimal \"{}\"", ns, got, exact);
  return {};
}

TEST(ShortestNumber, SecondsOfNanosecondsAreTheirExactDecimal) {
  std::vector<std::int64_t> ns = {0,
                                  1,
                                  -1,
                                  10,
                                  99'999,
                                  100'000,
                                  100'001,
                                  300'000,
                                  999'999'999,
                                  1'000'000'000,
                                  1'000'000'001,
                                  1'100'000'000,
                                  -1'500'000'000,
                                  999'999'999'999'999,
                                  1'000'000'000'000'000,
                                  1'000'000'000'000'001,
                                  (std::int64_t{1} << 53) - 1,
                                  std::int64_t{1} << 53,
                                  (std::int64_t{1} << 53) + 1,
                                  std::numeric_limits<std::int64_t>::max(),
                                  std::numeric_limits<std::int64_t>::min()};
  std::mt19937_64 rng(9);
  for (int i = 0; i < 2'000'000; ++i) {  // every length and count of trailing zeros, both signs
    const auto grid = static_cast<std::int64_t>(std::pow(10.0, rng() % 10));
    const auto n = static_cast<std::int64_t>(rng() >> (1 + rng() % 63)) / grid * grid;
    ns.push_back(i % 5 == 0 ? -n : n);
  }
  for (std::int64_t t = 0; t < 36'000'000'000'000; t += 3'600'000'017)  // 10 h on odd steps
    for (std::int64_t step : {0, 100'000, 1})  // the bench's 100 us grid, 1 ns off it
      ns.push_back(t / 100'000 * 100'000 + step);
  for (int e = 0; e <= 17; ++e) {  // every power of ten and its neighbours
    const auto p = static_cast<std::int64_t>(std::pow(10.0, e));
    for (std::int64_t n : {p - 1, p, p + 1, 3 * p, 9 * p + p - 1}) ns.push_back(n);
  }
  for (const auto n : ns) ASSERT_EQ(seconds_difference(n), "");
  char buf[64];
  const auto text = [&](std::int64_t n) {
    return std::string(buf, daq::write_seconds_of_ns(buf, n));
  };
  // By hand: 300 us, which ns x 1e-9 made 0.00030000000000000003; fmt's exponent notation
  // below 1e-4 s; a whole second; the last 15-digit time.
  EXPECT_EQ(text(300'000), "0.0003");
  EXPECT_NE(fmt::format("{}", 300'000.0 * 1e-9), "0.0003");  // why the column changed
  EXPECT_EQ(text(99'999), "9.9999e-05");
  EXPECT_EQ(text(5), "5e-09");
  EXPECT_EQ(text(-1'500'000'000), "-1.5");
  EXPECT_EQ(text(600'000'000'000), "600");
  EXPECT_EQ(text(999'999'999'999'999), "999999.999999999");
}

}  // namespace
