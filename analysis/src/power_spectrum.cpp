#include "cal/analysis/power_spectrum.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <stdexcept>

namespace cal {

namespace {

// The bits of a byte in reverse order.
constexpr std::array<std::uint8_t, 256> reversed_bytes = [] {
  std::array<std::uint8_t, 256> out{};
  for (unsigned b = 0; b < 256; ++b) {
    unsigned r = 0;
    for (int i = 0; i < 8; ++i) r |= ((b >> i) & 1u) << (7 - i);
    out[b] = static_cast<std::uint8_t>(r);
  }
  return out;
}();

// The low `bits` bits of k in reverse order (bits <= 32), without a loop whose length varies
// with k: its branches are random in the spectrum's pass.
std::size_t reverse_bits(std::size_t k, int bits) {
  const std::uint32_t r = static_cast<std::uint32_t>(reversed_bytes[k & 0xff]) << 24 |
                          static_cast<std::uint32_t>(reversed_bytes[(k >> 8) & 0xff]) << 16 |
                          static_cast<std::uint32_t>(reversed_bytes[(k >> 16) & 0xff]) << 8 |
                          static_cast<std::uint32_t>(reversed_bytes[(k >> 24) & 0xff]);
  return r >> (32 - bits);
}

}  // namespace

PowerSpectrum::PowerSpectrum(std::size_t n) : n_(n) {
  if (n < 4 || (n & (n - 1)) != 0 || n > (std::size_t{1} << 32))
    throw std::invalid_argument("PowerSpectrum: the length must be a power of two from 4 to 2^32");
  while ((std::size_t{1} << bits_) < n / 2) ++bits_;
  // cos(2 pi k / n) for k = 0 .. n / 4: the sines and the second quarter are these read from
  // the other end (a quarter of the table, of the calls, and of the page faults).
  cosine_.resize(n / 4 + 1);
  for (std::size_t k = 0; k <= n / 4; ++k)
    cosine_[k] = std::cos(2 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(n));
}

// The m complex values at z (interleaved) transformed in place, their transform in bit-reversed
// order: radix-2 stages of decimation in frequency, each the sums of the halves of a group of
// `size` values and their differences times e^(-2 pi i j / size), which is e^(-2 pi i k / n)
// for k = j stride. Above `block` values one stage, then each half the same way (depth first:
// a half of at most `block` values, 16 kB, stays in the cache for all its stages); at most
// `block`, its stages one after the other, without a call a group.
void PowerSpectrum::dif(double* z, std::size_t m, std::size_t stride) const {
  constexpr std::size_t block = 1024;
  const double* c = cosine_.data();
  const std::size_t quarter = n_ / 4, half = n_ / 2;
  // One stage over the groups of `size` values in z[0, m): size >= 8. k < n / 4 in the first
  // half of the j and at least n / 4 in the second, so each half reads its cosine and sine
  // without a test a value: e^(-i a) = cos a - i sin a, sin(2 pi k / n) = cos(2 pi (n / 4 - k) /
  // n), and past a quarter cos(2 pi k / n) = -cos(2 pi (n / 2 - k) / n), sin = cos(2 pi (k -
  // n / 4) / n).
  const auto stage = [&](std::size_t size, std::size_t step) {
    const std::size_t h = size / 2;
    for (double* a = z; a < z + 2 * m; a += 2 * size) {
      double* b = a + 2 * h;
      const auto butterfly = [&](std::size_t j, double wr, double wi) {
        const double ar = a[2 * j], ai = a[2 * j + 1], br = b[2 * j], bi = b[2 * j + 1];
        const double dr = ar - br, di = ai - bi;
        a[2 * j] = ar + br, a[2 * j + 1] = ai + bi;
        b[2 * j] = dr * wr - di * wi, b[2 * j + 1] = dr * wi + di * wr;
      };
      for (std::size_t j = 0; j < h / 2; ++j) butterfly(j, c[j * step], -c[quarter - j * step]);
      for (std::size_t j = h / 2; j < h; ++j)
        butterfly(j, -c[half - j * step], -c[j * step - quarter]);
    }
  };
  if (m > block) {
    stage(m, stride);
    dif(z, m / 2, 2 * stride);
    dif(z + m, m / 2, 2 * stride);
    return;
  }
  if (m == 2) {  // n = 4: one stage of two values
    const double ar = z[0], ai = z[1];
    z[0] = ar + z[2], z[1] = ai + z[3], z[2] = ar - z[2], z[3] = ai - z[3];
    return;
  }
  for (std::size_t size = m; size >= 8; size /= 2, stride *= 2) stage(size, stride);
  // The last two stages: e^(-2 pi i j / 4) is 1 or -i, e^(-2 pi i j / 2) is 1.
  for (double* a = z; a < z + 2 * m; a += 8) {
    const double d0r = a[0] - a[4], d0i = a[1] - a[5], d1r = a[2] - a[6], d1i = a[3] - a[7];
    const double s0r = a[0] + a[4], s0i = a[1] + a[5], s1r = a[2] + a[6], s1i = a[3] + a[7];
    // size 4: (s0, s1 | d0, -i d1), then size 2 on each pair
    a[0] = s0r + s1r, a[1] = s0i + s1i, a[2] = s0r - s1r, a[3] = s0i - s1i;
    a[4] = d0r + d1i, a[5] = d0i - d1r, a[6] = d0r - d1i, a[7] = d0i + d1r;
  }
}

void PowerSpectrum::add(std::span<double> x, double divisor, std::span<double> p) const {
  if (x.size() != n_ || p.size() != n_ / 2 + 1)
    throw std::invalid_argument(
        "PowerSpectrum::add: the series or the spectrum has the wrong size");
  const std::size_t m = n_ / 2;  // complex values z_j = x_2j + i x_2j+1
  double* z = x.data();
  dif(z, m, 2);  // e^(-2 pi i j / m) is e^(-2 pi i k / n) for k = 2 j
  // X_k = (Z_k + conj Z_m-k) / 2 - i e^(-2 pi i k / n) (Z_k - conj Z_m-k) / 2, and X_m-k from the
  // same pair (kissfft's split, as Eigen has it); Z_k is at the bit reverse of k.
  p[0] += (z[0] + z[1]) * (z[0] + z[1]) / divisor;
  p[m] += (z[0] - z[1]) * (z[0] - z[1]) / divisor;
  const double* c = cosine_.data();
  for (std::size_t k = 1; k <= m / 2; ++k) {
    const std::size_t r = reverse_bits(k, bits_), rm = reverse_bits(m - k, bits_);
    const double zr = z[2 * r], zi = z[2 * r + 1], nr = z[2 * rm], ni = -z[2 * rm + 1];
    const double sr = zr + nr, si = zi + ni, dr = zr - nr, di = zi - ni;
    const double wr = c[k], wi = -c[n_ / 4 - k];                  // e^(-2 pi i k / n), k <= n / 4
    const double er = dr * wr - di * wi, ei = dr * wi + di * wr;  // e (dr + i di)
    const double tr = ei, ti = -er;                               // times -i
    const double xr = 0.5 * (sr + tr), xi = 0.5 * (si + ti);      // X_k
    const double yr = 0.5 * (sr - tr), yi = -0.5 * (si - ti);     // X_m-k
    p[k] += (xr * xr + xi * xi) / divisor;
    if (k != m - k) p[m - k] += (yr * yr + yi * yi) / divisor;
  }
}

}  // namespace cal
