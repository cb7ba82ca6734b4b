// cal::moving_median against the naive definition (every window gathered, sorted, its element of
// rank size / 2 taken) on random data: continuous values, and values with many ties.
#include "cal/analysis/moving_median.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

namespace {

std::vector<double> naive(const std::vector<double>& x, std::size_t m, std::size_t stride) {
  const std::size_t n = x.size();
  std::vector<double> out(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<double> win;
    for (std::size_t k = i > m ? i - m : 0; k < std::min(n, i + m + 1); k += stride)
      win.push_back(x[k]);
    std::sort(win.begin(), win.end());
    out[i] = win[win.size() / 2];
  }
  return out;
}

std::vector<double> sliding(const std::vector<double>& x, std::size_t m, std::size_t stride) {
  std::vector<double> out(x.size(), -1.0);
  std::vector<int> written(x.size(), 0);
  cal::moving_median(
      x.size(), m, stride, [&](std::size_t k) { return x[k]; },
      [&](std::size_t i, double median) { out[i] = median, ++written[i]; });
  for (std::size_t i = 0; i < x.size(); ++i) EXPECT_EQ(written[i], 1) << "position " << i;
  return out;
}

TEST(MovingMedian, EqualsTheNaiveMedianOfEveryWindowOnRandomData) {
  std::mt19937_64 rng(32);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::uniform_int_distribution<int> few(-3, 3);  // many ties
  int cases = 0;
  for (const std::size_t n : {1u, 2u, 3u, 7u, 40u, 41u, 42u, 500u, 5000u})
    for (const std::size_t m : {1u, 2u, 5u, 20u, 200u})
      for (const std::size_t stride : {1u, 2u, 3u, 7u, 41u})
        for (const bool ties : {false, true}) {
          std::vector<double> x(n);
          for (auto& v : x) v = ties ? few(rng) : normal(rng);
          ASSERT_EQ(sliding(x, m, stride), naive(x, m, stride))
              << "n " << n << ", m " << m << ", stride " << stride << ", ties " << ties;
          ++cases;
        }
  EXPECT_EQ(cases, 9 * 5 * 5 * 2);
}

TEST(MovingMedian, FollowsASortedAndAReversedRamp) {
  // Every window of a monotone series has its middle element as median: x[i] inside, and
  // the clipped windows' element of rank size / 2 at the ends.
  std::vector<double> up(100), down(100);
  for (std::size_t i = 0; i < 100; ++i)
    up[i] = static_cast<double>(i), down[i] = 99.0 - static_cast<double>(i);
  const auto a = sliding(up, 10, 1), b = sliding(down, 10, 1);
  for (std::size_t i = 10; i < 90; ++i) {
    EXPECT_EQ(a[i], static_cast<double>(i));
    EXPECT_EQ(b[i], 99.0 - static_cast<double>(i));
  }
  EXPECT_EQ(a[0], 5.0);   // window 0..10, rank 5
  EXPECT_EQ(b[0], 94.0);  // window 99..89, sorted 89..99, rank 5
}

}  // namespace

namespace {

// The branch-free bisection gives std::lower_bound's place in every case: each length up to 90,
// keys below, above, between and equal to the values, with many ties.
TEST(MovingMedian, LowerPlaceIsStdLowerBound) {
  std::mt19937_64 rng(33);
  std::uniform_int_distribution<int> few(-6, 6);
  int checked = 0;
  for (std::size_t n = 1; n <= 90; ++n)
    for (int round = 0; round < 20; ++round) {
      std::vector<double> v(n);
      for (auto& x : v) x = few(rng) / 2.0;
      std::sort(v.begin(), v.end());
      for (int key = -15; key <= 15; ++key) {
        const double x = key / 4.0;
        const auto want =
            static_cast<std::size_t>(std::lower_bound(v.begin(), v.end(), x) - v.begin());
        ASSERT_EQ(cal::lower_place(v.data(), n, x), want) << "n " << n << " key " << x;
        ++checked;
      }
    }
  EXPECT_EQ(checked, 90 * 20 * 31);
}

}  // namespace
