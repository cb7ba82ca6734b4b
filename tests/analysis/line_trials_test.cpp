// cal::LineTrials (issue 32): the vibration's line fit at several trial frequencies in one pass.
// Its rows against long double sines and cosines of the same arguments, within the stated
// bound; its sums against the rows summed sample by sample; its bad arguments refused.
#include "cal/analysis/line_trials.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

namespace {

constexpr double pi = std::numbers::pi;

// Trial k's row at t, exactly (to long double's 2^-64) from the arguments the trials take in
// double: a = 2 pi centre t, b = 2 pi step t, e = 2 pi f0 t, each rounded as the code rounds it.
// sin(a + k b) from sin a, cos a, sin k b, cos k b: k b is exact in long double (|k| <= 16
// adds at most 5 bits to b's 53), whereas a + k b itself would be rounded to an ulp of a
// (1e-14 rad at a = 1e5).
std::array<long double, 6> exact_row(double centre, double step, double f0, double t, int k) {
  const double a = 2 * pi * centre * t, b = 2 * pi * step * t, e = 2 * pi * f0 * t;
  const long double kb = static_cast<long double>(k) * b;
  const long double sa = std::sin(static_cast<long double>(a)),
                    ca = std::cos(static_cast<long double>(a));
  const long double s = sa * std::cos(kb) + ca * std::sin(kb),
                    c = ca * std::cos(kb) - sa * std::sin(kb);
  const long double sb = std::sin(static_cast<long double>(e)),
                    cb = std::cos(static_cast<long double>(e));
  return {s * cb - c * sb, c * cb + s * sb, s, c, s * cb + c * sb, c * cb - s * sb};
}

// Random runs (times up to an hour, vibrations 1 Hz - 5 kHz, steps of a fraction of a hertz,
// the feed's frequency 0.005 - 0.5 Hz): every component of every trial's row within
// row_error_bound(k) of the exact one, for the grid's reach (10), the refinement's (3) and the
// largest the class takes (max_offset, 16), each with and without the centre. The arguments reach
// 1e8 rad, past sin_cos's own range (2^19 pi / 2), where glibc's sincos takes over. A ladder step
// of the wrong sign or direction, a lane swapped or a row's term mixed up is off by O(1).
TEST(LineTrials, RowsWithinTheirBoundOfTheSameArgumentsTakenExactly) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double worst_ratio = 0.0, worst_abs = 0.0;
  for (int run = 0; run < 4000; ++run) {
    const double centre = 1.0 + 5000.0 * unit(rng), step = 0.3 * unit(rng),
                 f0 = 0.005 + 0.5 * unit(rng);
    const int reach = run % 3 == 0 ? 3 : run % 3 == 1 ? 10 : cal::LineTrials::max_offset;
    const bool with_centre = run % 2 == 1;
    cal::LineTrials lt(f0, centre, step, reach, with_centre, 1);
    ASSERT_EQ(lt.offsets().size(), static_cast<std::size_t>(2 * reach + (with_centre ? 1 : 0)));
    for (int i = 0; i < 25; ++i) {
      const double t = (i < 5 ? 40.0 : 3600.0) * unit(rng);
      const auto rows = lt.rows(t);
      ASSERT_EQ(rows.size(), lt.offsets().size());
      for (std::size_t q = 0; q < rows.size(); ++q) {
        const int k = lt.offsets()[q];
        const auto exact = exact_row(centre, step, f0, t, k);
        for (std::size_t c = 0; c < 6; ++c) {
          const double err =
              static_cast<double>(std::abs(static_cast<long double>(rows[q][c]) - exact[c]));
          worst_abs = std::max(worst_abs, err);
          worst_ratio = std::max(worst_ratio, err / cal::LineTrials::row_error_bound(k));
          ASSERT_LE(err, cal::LineTrials::row_error_bound(k))
              << "trial " << k << " component " << c << " at t = " << t << ", centre " << centre
              << ", step " << step << ", f0 " << f0;
        }
      }
    }
  }
  std::printf("LineTrials rows: worst error %.3g, %.3f of the bound\n", worst_abs, worst_ratio);
}

// The sums are the rows' products summed sample after sample, one product and one addition
// each (what Eigen's rank update of the pass per trial did), into the sample's piece: bit for
// bit against the same sums written out from rows(), for every trial and piece. A piece, pair
// or lane misplaced, or a sum's index shifted, fails it.
TEST(LineTrials, SumsAreTheRowsSummedIntoTheirPieces) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (const bool with_centre : {true, false}) {
    const int reach = with_centre ? 10 : 3;
    const std::size_t pieces = 3;
    cal::LineTrials lt(0.0265, 123.4, 0.007, reach, with_centre, pieces);
    const auto n = lt.offsets().size();
    std::vector<std::array<double, 21>> lower(n * pieces, std::array<double, 21>{});
    std::vector<std::array<double, 6>> ry(n * pieces, std::array<double, 6>{});
    for (int j = 0; j < 2000; ++j) {
      const double t = 0.01 * j, y = unit(rng) - 0.5;
      const auto g = static_cast<std::size_t>(j % 7 == 0 ? 2 : j / 1000);  // pieces interleaved
      lt.add(g, t, y);
      const auto rows = lt.rows(t);
      for (std::size_t q = 0; q < n; ++q) {
        const auto& r = rows[q];
        auto& lo = lower[q * pieces + g];
        for (std::size_t a = 0, p = 0; a < 6; ++a)
          for (std::size_t b = 0; b <= a; ++b, ++p) lo[p] = lo[p] + r[b] * r[a];
        for (std::size_t a = 0; a < 6; ++a)
          ry[q * pieces + g][a] = ry[q * pieces + g][a] + r[a] * y;
      }
    }
    for (std::size_t q = 0; q < n; ++q)
      for (std::size_t g = 0; g < pieces; ++g) {
        const auto s = lt.sums(lt.offsets()[q], g);
        EXPECT_EQ(s.lower, lower[q * pieces + g]) << "trial " << lt.offsets()[q] << " piece " << g;
        EXPECT_EQ(s.ry, ry[q * pieces + g]) << "trial " << lt.offsets()[q] << " piece " << g;
      }
  }
}

// The row at one frequency, taken directly: (f - f0), f, (f + f0) by hand at t = 0.25 s,
// f = 2 Hz, f0 = 0.5 Hz: phi = pi, phi0 = pi / 4.
TEST(LineTrials, TheDirectRowByHand) {
  const auto r = cal::LineTrials::row(2.0, 0.5, 0.25);
  const double h = std::sqrt(0.5);
  const double expected[6] = {std::sin(3 * pi / 4), std::cos(3 * pi / 4), 0.0, -1.0,
                              std::sin(5 * pi / 4), std::cos(5 * pi / 4)};
  for (std::size_t c = 0; c < 6; ++c) EXPECT_NEAR(r[c], expected[c], 1e-15) << c;
  EXPECT_NEAR(r[0], h, 1e-15);
  EXPECT_NEAR(r[5], -h, 1e-15);
}

TEST(LineTrials, RefusesABadReachPieceOrTrial) {
  EXPECT_THROW(cal::LineTrials(0.03, 100, 0.01, 0, true, 1), std::invalid_argument);
  EXPECT_THROW(cal::LineTrials(0.03, 100, 0.01, cal::LineTrials::max_offset + 1, true, 1),
               std::invalid_argument);
  EXPECT_THROW(cal::LineTrials(0.03, 100, 0.01, 3, true, 0), std::invalid_argument);
  const cal::LineTrials lt(0.03, 100, 0.01, 3, false, 2);
  EXPECT_THROW(static_cast<void>(lt.sums(0, 0)), std::invalid_argument);  // no centre
  EXPECT_THROW(static_cast<void>(lt.sums(4, 0)), std::invalid_argument);
  EXPECT_THROW(static_cast<void>(lt.sums(1, 2)), std::invalid_argument);
}

}  // namespace
