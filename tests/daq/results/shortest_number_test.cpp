// write_shortest (daq/src/results/shortest_number.hpp) writes every double character for
// character as fmt's "{}" does: the exports' bytes must not change with the faster writer.
#include "shortest_number.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <bit>
#include <cfloat>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <string>
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

}  // namespace
