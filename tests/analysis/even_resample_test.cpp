// cal::EvenResampler and cal::overlapping_segments against the interpolation written out for each
// time on its own (the pair found by std::lower_bound), bit for bit, and against values by hand.
#include "cal/analysis/even_resample.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

namespace {

struct Series {
  std::vector<double> t, v;
};

// The value at time a by the definition: the pair (j, j + 1) with j + 1 the first sample not
// before a (lower_bound), kept within [0, n - 2].
double direct(const Series& s, double a) {
  const std::size_t n = s.t.size();
  if (n == 1) return s.v[0];
  const auto first =
      static_cast<std::size_t>(std::lower_bound(s.t.begin(), s.t.end(), a) - s.t.begin());
  const std::size_t j = std::min(first == 0 ? 0 : first - 1, n - 2);
  const double ta = s.t[j], tb = s.t[j + 1];
  const double f = tb > ta ? std::clamp((a - ta) / (tb - ta), 0.0, 1.0) : 0.0;
  return s.v[j] + f * (s.v[j + 1] - s.v[j]);
}

auto resampler(const Series& s, double dt) {
  return cal::EvenResampler(
      s.t.size(), dt, [&s](std::size_t j) { return s.t[j]; },
      [&s](std::size_t j) { return s.v[j]; });
}

// Rising times with jittered steps, repeated times and a gap; random values.
Series uneven(std::size_t n, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> step(0.5, 1.5), value(-3.0, 3.0);
  Series s;
  double t = 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    s.t.push_back(t), s.v.push_back(value(rng));
    t += j % 97 == 5 ? 0.0 : j % 211 == 7 ? 40.0 : step(rng);
  }
  return s;
}

TEST(EvenResample, ValuesByHand) {
  const Series s{{0.0, 1.0, 3.0}, {0.0, 10.0, 20.0}};
  auto r = resampler(s, 0.5);
  std::vector<double> out(8);
  r.next(out.size(), out.data());
  // 0, 0.5, 1 on the first pair (10 a second); 1.5 .. 3 on the second (5 a second); past the
  // end, the last value
  EXPECT_EQ(out, (std::vector<double>{0, 5, 10, 12.5, 15, 17.5, 20, 20}));
  std::vector<double> more(3);
  r.next(more.size(), more.data());
  EXPECT_EQ(more, (std::vector<double>{20, 20, 20}));
  const Series one{{2.0}, {7.0}};  // one sample: its value everywhere
  auto r1 = resampler(one, 1.0);
  std::vector<double> o1(3);
  r1.next(o1.size(), o1.data());
  EXPECT_EQ(o1, (std::vector<double>{7, 7, 7}));
}

TEST(EvenResample, PiecesAreTheDefinitionBitForBit) {
  std::mt19937_64 rng(32);
  const Series s = uneven(5000, rng);
  const double dt = 0.73;
  const auto total = static_cast<std::size_t>(s.t.back() / dt) + 10;  // past the end too
  auto r = resampler(s, dt);
  std::uniform_int_distribution<std::size_t> piece(0, 300);
  std::vector<double> buf;
  for (std::size_t k = 0; k < total;) {
    const std::size_t c = std::min(piece(rng), total - k);
    buf.resize(c);
    r.next(c, buf.data());
    for (std::size_t i = 0; i < c; ++i)
      ASSERT_EQ(buf[i], direct(s, static_cast<double>(k + i) * dt)) << "step " << k + i;
    k += c;
  }
}

TEST(EvenResample, OverlappingSegmentsAreTheDefinitionBitForBit) {
  std::mt19937_64 rng(131072);
  const Series s = uneven(3000, rng);
  const double dt = 0.61;
  const std::vector<std::pair<std::size_t, std::size_t>> cases = {
      {64, 32}, {65, 32}, {100, 100}, {256, 1}};  // len, hop
  for (const auto& c : cases) {
    const std::size_t len = c.first, hop = c.second;  // (no structured binding: clang 14)
    const std::size_t count = 5000 / len;
    auto r = resampler(s, dt);
    std::vector<double> segment;
    std::size_t k = 0;
    cal::overlapping_segments(r, count, len, hop, segment, [&](const std::vector<double>& x) {
      ASSERT_EQ(x.size(), len);
      for (std::size_t i = 0; i < len; ++i)
        ASSERT_EQ(x[i], direct(s, static_cast<double>(k * hop + i) * dt))
            << "len " << len << ", hop " << hop << ", segment " << k << ", value " << i;
      ++k;
    });
    EXPECT_EQ(k, count);
  }
}

}  // namespace
