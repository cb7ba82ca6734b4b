// cal::PowerSpectrum against the definition |sum_j x_j e^(-2 pi i j k / n)|^2 summed directly in
// long double, and against spectra known by hand (a line on a bin, a constant, the alternating
// series), on the vibration search's own length (262,144 points, issue 32).
#include "cal/analysis/power_spectrum.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

namespace {

// |X_k|^2 by the definition, k = 0 .. n / 2.
std::vector<double> direct(const std::vector<double>& x) {
  const std::size_t n = x.size();
  const long double two_pi = 2 * std::numbers::pi_v<long double>;
  std::vector<double> out(n / 2 + 1);
  for (std::size_t k = 0; k <= n / 2; ++k) {
    long double re = 0, im = 0;
    for (std::size_t j = 0; j < n; ++j) {
      // j k reduced modulo n: the angle stays below 2 pi, so its cosine is exact to long double
      const long double a = two_pi * static_cast<long double>((j * k) % n) / n;
      re += x[j] * std::cos(a), im -= x[j] * std::sin(a);
    }
    out[k] = static_cast<double>(re * re + im * im);
  }
  return out;
}

std::vector<double> spectrum(std::vector<double> x, double divisor = 1.0) {
  std::vector<double> p(x.size() / 2 + 1, 0.0);
  cal::PowerSpectrum(x.size()).add(x, divisor, p);
  return p;
}

TEST(PowerSpectrum, IsTheDefinitionOnRandomSeries) {
  std::mt19937_64 rng(262144);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (std::size_t n = 4; n <= 2048; n *= 2) {
    std::vector<double> x(n);
    for (auto& v : x) v = normal(rng);
    const auto want = direct(x), got = spectrum(x);
    double peak = 0.0;
    for (double v : want) peak = std::max(peak, v);
    for (std::size_t k = 0; k <= n / 2; ++k)
      ASSERT_NEAR(got[k], want[k], 1e-13 * peak) << "n " << n << ", bin " << k;
  }
}

TEST(PowerSpectrum, ALineOnABinAConstantAndTheAlternatingSeries) {
  const std::size_t n = 262144;  // the vibration's Welch segments: 131,072 samples padded twice
  // A cos(2 pi k0 j / n + phi) puts (A n / 2)^2 in bin k0 and nothing elsewhere.
  const double a = 0.7, phi = 0.3;
  const std::size_t k0 = 12345;
  std::vector<double> x(n);
  for (std::size_t j = 0; j < n; ++j)
    x[j] = a * std::cos(2 * std::numbers::pi * static_cast<double>((j * k0) % n) /
                            static_cast<double>(n) +
                        phi);
  const auto p = spectrum(x, 4.0);  // and divided by 4
  const double line = (a * n / 2) * (a * n / 2) / 4.0;
  EXPECT_NEAR(p[k0], line, 1e-12 * line);
  double elsewhere = 0.0;
  for (std::size_t k = 0; k <= n / 2; ++k)
    if (k != k0) elsewhere = std::max(elsewhere, p[k]);
  EXPECT_LT(elsewhere, 1e-20 * line);
  // A constant c: (c n)^2 at 0 only; (-1)^j: n^2 at n / 2 only.
  const auto dc = spectrum(std::vector<double>(n, 2.5));
  EXPECT_NEAR(dc[0], (2.5 * n) * (2.5 * n), 1e-12 * dc[0]);
  EXPECT_EQ(dc[1], 0.0);
  EXPECT_EQ(dc[n / 2], 0.0);
  std::vector<double> alt(n);
  for (std::size_t j = 0; j < n; ++j) alt[j] = j % 2 == 0 ? 1.0 : -1.0;
  const auto ny = spectrum(alt);
  EXPECT_DOUBLE_EQ(ny[n / 2], static_cast<double>(n) * static_cast<double>(n));
  EXPECT_EQ(ny[0], 0.0);
  EXPECT_EQ(ny[n / 4], 0.0);
}

TEST(PowerSpectrum, AddsToWhatThereIs) {
  std::vector<double> x = {1.0, 0.0, 0.0, 0.0}, p = {1.0, 2.0, 3.0};  // X_k = 1 for every k
  cal::PowerSpectrum(4).add(x, 2.0, p);
  EXPECT_EQ(p, (std::vector<double>{1.5, 2.5, 3.5}));
}

TEST(PowerSpectrum, RefusesOtherLengths) {
  EXPECT_THROW(cal::PowerSpectrum(2), std::invalid_argument);
  EXPECT_THROW(cal::PowerSpectrum(96), std::invalid_argument);
  cal::PowerSpectrum s(8);
  std::vector<double> x(8), p(4);
  EXPECT_THROW(s.add(x, 1.0, p), std::invalid_argument);  // p needs 5
}

}  // namespace
