#pragma once
// A centred moving median over every stride-th value (the ballbar's stick-slip high-pass,
// circle_dynamics.cpp). Header-only: the values are read through a callable, so that a caller
// can read them in its own order without copying them.
#include <algorithm>
#include <cstddef>
#include <cstring>
#include <vector>

namespace cal {

// For each i in [0, n): out(i, the median of at(k) for k = a, a + stride, ... < b), where
// a = max(0, i - m) and b = min(n, i + m + 1) (the window clipped at the ends). The median is
// the element of rank size / 2 of the window (the upper one of an even-sized window), so it is
// always one of the values. stride >= 1.
//
// Where a window lies wholly inside, the window of i + stride is that of i less its first value
// plus one more, so each residue class of i mod stride slides one sorted window along (one
// shift of the values between the leaving and the entering one) instead of selecting every
// window's median anew: O(n w) for a window of w values, and w is small (the ballbar's is at
// most about 80), where a sorted array beats a pair of heaps. The ends select anew.
// std::lower_bound's place in the sorted v[0, n), n >= 1 (the first not less than x), by a
// bisection whose steps are selects rather than branches.
inline std::size_t lower_place(const double* v, std::size_t n, double x) {
  const double* base = v;
  while (n > 1) {
    const std::size_t half = n / 2;
    base = base[half] < x ? base + half : base;
    n -= half;
  }
  return static_cast<std::size_t>(base - v) + (*base < x ? 1 : 0);
}

// std::upper_bound's place in the sorted v[0, n), n >= 1 (the first greater than x), likewise.
inline std::size_t upper_place(const double* v, std::size_t n, double x) {
  const double* base = v;
  while (n > 1) {
    const std::size_t half = n / 2;
    base = base[half] <= x ? base + half : base;
    n -= half;
  }
  return static_cast<std::size_t>(base - v) + (*base <= x ? 1 : 0);
}

template <class At, class Out>
void moving_median(std::size_t n, std::size_t m, std::size_t stride, At&& at, Out&& out) {
  std::vector<double> win;
  const auto clipped = [&](std::size_t i) {  // the window selected anew
    const std::size_t a = i > m ? i - m : 0, b = std::min(n, i + m + 1);
    win.clear();
    for (std::size_t k = a; k < b; k += stride) win.push_back(at(k));
    std::nth_element(win.begin(), win.begin() + static_cast<std::ptrdiff_t>(win.size() / 2),
                     win.end());
    return win[win.size() / 2];
  };
  const bool slides = n >= 2 * m + 1;  // some window lies wholly inside
  for (std::size_t i = 0; i < n; ++i)
    if (!slides || i < m || i + m + 1 > n) out(i, clipped(i));
  if (!slides) return;
  const std::size_t count = (2 * m + 1 + stride - 1) / stride;  // values in an inner window
  // Every residue class's window slides along together, i in order: the same operations per
  // class as one class after the other, but the values are read in one forward pass (two
  // reading positions, i - m and i - m + count stride), not one strided pass a class over the
  // whole series, which through a paged array read every page once per class (issue 32). The
  // windows hold stride x count values, about the window's 2m + 1 samples: not the series'.
  std::size_t classes = 0;
  while (classes < stride && m + classes + m + 1 <= n) ++classes;
  std::vector<double> wins(classes * count);
  for (std::size_t r = 0; r < classes; ++r) {
    double* w = wins.data() + r * count;
    for (std::size_t k = 0; k < count; ++k) w[k] = at(r + k * stride);
    std::sort(w, w + count);
  }
  for (std::size_t i = m, r = 0; i + m + 1 <= n; ++i, r = r + 1 == stride ? 0 : r + 1) {
    double* w = wins.data() + r * count;
    out(i, w[count / 2]);
    if (i + stride + m + 1 > n) continue;
    const double leaving = at(i - m), entering = at(i - m + count * stride);
    // Replace `leaving` by `entering` and keep the window sorted: the values between the
    // leaving one's place and the first above `entering` (std::upper_bound's place) move one
    // place towards the leaving one's, and `entering` takes the place freed. Both places come
    // from bisections without branches (on residuals they are random, and the mispredicted
    // branches of std::lower_bound and std::upper_bound were most of the stick-slip's time),
    // the move is one memmove: a loop of one value a step, whose exit is random too, was 10 %
    // slower (issue 32).
    const std::size_t j = lower_place(w, count, leaving), p = upper_place(w, count, entering);
    if (p > j) {  // w[j] = leaving <= entering: w[j + 1, p) down one place
      std::memmove(w + j, w + j + 1, (p - 1 - j) * sizeof(double));
      w[p - 1] = entering;
    } else {  // entering < leaving: w[p, j) up one place
      std::memmove(w + p + 1, w + p, (j - p) * sizeof(double));
      w[p] = entering;
    }
  }
}

}  // namespace cal
