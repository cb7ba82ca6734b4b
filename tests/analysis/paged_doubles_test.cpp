// PagedDoubles (issue 32): the values read are the values written, bit for bit, whatever the
// access pattern, against a plain vector given the same writes.
#include "cal/analysis/paged_doubles.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <limits>
#include <random>
#include <vector>

namespace {

using cal::PagedDoubles;
using cal::PageOptions;

constexpr PageOptions kSmall{.page_values = 8, .pages_held = 3};

TEST(PagedDoubles, RandomWritesAndReadsMatchAVectorThroughTheFile) {
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> value(-1e6, 1e6);
  const std::size_t n = 1000;  // 125 pages of 8, 3 held
  PagedDoubles p(n, kSmall);
  std::vector<double> v(n, 0.0);
  const auto spilled = PagedDoubles::pages_spilled();
  for (int round = 0; round < 20000; ++round) {
    const std::size_t i = rng() % n;
    if (rng() % 2) {
      const double x = value(rng);
      p.set(i, x);
      v[i] = x;
    } else {
      ASSERT_EQ(p[i], v[i]) << "at " << i << ", round " << round;
    }
  }
  EXPECT_GT(PagedDoubles::pages_spilled(), spilled);                      // went through the file
  for (std::size_t i = n; i-- > 0;) ASSERT_EQ(p[i], v[i]) << "at " << i;  // backwards
  // Special values survive the file bit for bit.
  p.set(3, -0.0);
  p.set(500, std::numeric_limits<double>::denorm_min());
  for (std::size_t i = 8; i < 1000; i += 8) (void)p[i];  // evicts page 0 and 62
  EXPECT_TRUE(std::signbit(p[3]));
  EXPECT_EQ(p[500], std::numeric_limits<double>::denorm_min());
}

TEST(PagedDoubles, PushBackTwoStreamsCopyAndMove) {
  PagedDoubles p(0, kSmall);
  for (int i = 0; i < 300; ++i) p.push_back(i * 0.5);
  ASSERT_EQ(p.size(), 300u);
  // Two sequential readers in opposite directions at once (a ccw and a cw trace).
  for (std::size_t i = 0; i < 300; ++i) {
    ASSERT_EQ(p[i], static_cast<double>(i) * 0.5);
    ASSERT_EQ(p[299 - i], static_cast<double>(299 - i) * 0.5);
  }
  PagedDoubles c = p.copy();
  c.set(10, -1.0);
  EXPECT_EQ(p[10], 5.0);  // the copy is its own
  EXPECT_EQ(c[10], -1.0);
  EXPECT_EQ(c[299], 149.5);
  PagedDoubles m = std::move(c);
  EXPECT_EQ(m[10], -1.0);
  EXPECT_EQ(m[298], 149.0);
  EXPECT_EQ(c.size(), 0u);  // NOLINT(bugprone-use-after-move): moved-from is empty
  // Never-written values read as zeros, in and beyond written pages.
  PagedDoubles z(100, kSmall);
  z.set(50, 1.0);
  for (std::size_t i = 0; i < 100; ++i) ASSERT_EQ(z[i], i == 50 ? 1.0 : 0.0);
}

TEST(PagedDoubles, ABadPageSizeIsRefused) {
  EXPECT_THROW(PagedDoubles(1, PageOptions{.page_values = 6, .pages_held = 2}),
               std::invalid_argument);
  EXPECT_THROW(PagedDoubles(1, PageOptions{.page_values = 8, .pages_held = 0}),
               std::invalid_argument);
}

TEST(PagedDoubles, AnUnwritableTemporaryDirectoryIsAClearError) {
  const char* old = std::getenv("TMPDIR");
  const std::string saved = old ? old : "";
  setenv("TMPDIR", "/nonexistent-caldaq-dir", 1);
  PagedDoubles p(100, kSmall);
  bool threw = false;
  try {
    for (std::size_t i = 0; i < 100; ++i) p.set(i, 1.0);  // the fourth page evicts a dirty one
  } catch (const std::runtime_error& e) {
    threw = true;
    EXPECT_NE(std::string(e.what()).find("/nonexistent-caldaq-dir"), std::string::npos) << e.what();
  }
  if (old)
    setenv("TMPDIR", saved.c_str(), 1);
  else
    unsetenv("TMPDIR");
  EXPECT_TRUE(threw);
}

}  // namespace
