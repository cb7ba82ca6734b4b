#pragma once
// The power spectrum of a real series of a power-of-two length: |X_k|^2, k = 0 .. n / 2, of
// X_k = sum_j x_j e^(-2 pi i j k / n). The ballbar's vibration search (circle_dynamics.cpp)
// transforms Welch segments of 262,144 points: Eigen's kissfft took a third of the search's time
// (4 % of a long ballbar replay), walking a 2 MB array in strides, and held its output and plan
// tables beside the input (5 MB, each page a fault on first use: issue 32, docs/benchmarks.md).
// This one works in place in its input: the series read as n / 2 complex values (even and odd
// samples), a radix-2 decimation in frequency taken depth first above 1024 values (each half
// finished before the next: below that size a group stays in the cache for all its stages) and
// stage after stage below, and the real series' spectrum made from the complex one's (the same
// split as kissfft's and every real FFT's). Its twiddle factors are one table of n / 4 + 1 cosines,
// each from std::cos, the sines read from its other end.
#include <cstddef>
#include <span>
#include <vector>

namespace cal {

class PowerSpectrum {
 public:
  // n: a power of two from 4 to 2^32 (std::invalid_argument otherwise).
  explicit PowerSpectrum(std::size_t n);
  std::size_t size() const { return n_; }

  // Adds |X_k|^2 / divisor to p[k], k = 0 .. n / 2, for the series x (n values). x is the
  // transform's work space: its values are gone afterwards. p holds n / 2 + 1 values.
  void add(std::span<double> x, double divisor, std::span<double> p) const;

 private:
  void dif(double* z, std::size_t m, std::size_t stride) const;
  std::size_t n_;
  int bits_ = 0;                // n / 2 is 2^bits_
  std::vector<double> cosine_;  // cos(2 pi k / n), k = 0 .. n / 4
};

}  // namespace cal
