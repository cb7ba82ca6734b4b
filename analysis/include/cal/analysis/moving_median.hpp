#pragma once
// A centred moving median over every stride-th value (the ballbar's stick-slip high-pass,
// circle_dynamics.cpp). Header-only: the values are read through a callable, so that a caller
// can read them in its own order without copying them.
#include <algorithm>
#include <cstddef>
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
  for (std::size_t r = 0; r < stride && m + r + m + 1 <= n; ++r) {
    std::size_t i = m + r;
    win.clear();
    for (std::size_t k = 0; k < count; ++k) win.push_back(at(i - m + k * stride));
    std::sort(win.begin(), win.end());
    for (;;) {
      out(i, win[count / 2]);
      if (i + stride + m + 1 > n) break;
      const double leaving = at(i - m), entering = at(i - m + count * stride);
      // Replace `leaving` by `entering` and keep the window sorted: shift the values between.
      auto gone = std::lower_bound(win.begin(), win.end(), leaving);
      if (entering >= leaving) {
        const auto to = std::upper_bound(gone + 1, win.end(), entering);
        std::move(gone + 1, to, gone);
        *(to - 1) = entering;
      } else {
        const auto to = std::upper_bound(win.begin(), gone, entering);
        std::move_backward(to, gone, gone + 1);
        *to = entering;
      }
      i += stride;
    }
  }
}

}  // namespace cal
