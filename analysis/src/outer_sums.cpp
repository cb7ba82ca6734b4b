// Sums of outer products (outer_sums.hpp). Each path holds a tile of the sums in registers (4
// weights by 12 columns with AVX2, by 6 with SSE2) over all the rows, then the next tile; the
// order of each sum's terms is the rows' in every path, so the paths agree bit for bit.
#include "cal/analysis/outer_sums.hpp"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

// The tiles' loops unrolled, so that their registers stay registers (without it GCC keeps the
// arrays in memory: three times the time).
#define CALDAQ_UNROLL _Pragma("GCC unroll 4")

namespace cal {
namespace {

#if defined(__x86_64__)
// Columns [m0, m0 + 2 L) of weights [j0, j0 + 4), L two-double registers a weight.
template <int L>
inline void tile_sse2(double* s, const double* w, const double* p, std::size_t rows, std::size_t nw,
                      std::size_t np, std::size_t j0, std::size_t m0) {
  __m128d acc[4][L];
  CALDAQ_UNROLL for (int a = 0; a < 4; ++a) CALDAQ_UNROLL for (int b = 0; b < L; ++b) acc[a][b] =
      _mm_loadu_pd(s + (j0 + a) * np + m0 + 2 * b);
  for (std::size_t i = 0; i < rows; ++i) {
    const double* pi = p + i * np + m0;
    const double* wi = w + i * nw + j0;
    __m128d x[L];
    CALDAQ_UNROLL for (int b = 0; b < L; ++b) x[b] = _mm_loadu_pd(pi + 2 * b);
    CALDAQ_UNROLL for (int a = 0; a < 4; ++a) {
      const __m128d v = _mm_set1_pd(wi[a]);
      CALDAQ_UNROLL for (int b = 0; b < L; ++b) acc[a][b] =
          _mm_add_pd(acc[a][b], _mm_mul_pd(v, x[b]));
    }
  }
  CALDAQ_UNROLL for (int a = 0; a < 4; ++a) CALDAQ_UNROLL for (int b = 0; b < L; ++b)
      _mm_storeu_pd(s + (j0 + a) * np + m0 + 2 * b, acc[a][b]);
}

void add_sse2(double* s, const double* w, const double* p, std::size_t rows, std::size_t nw,
              std::size_t np) {
  for (std::size_t j0 = 0; j0 < nw; j0 += 4) {
    std::size_t m0 = 0;
    for (; m0 + 6 <= np; m0 += 6) tile_sse2<3>(s, w, p, rows, nw, np, j0, m0);
    for (; m0 < np; m0 += 2) tile_sse2<1>(s, w, p, rows, nw, np, j0, m0);
  }
}

// The same with four-double registers.
template <int L>
__attribute__((target("avx2"))) inline void tile_avx2(double* s, const double* w, const double* p,
                                                      std::size_t rows, std::size_t nw,
                                                      std::size_t np, std::size_t j0,
                                                      std::size_t m0) {
  __m256d acc[4][L];
  CALDAQ_UNROLL for (int a = 0; a < 4; ++a) CALDAQ_UNROLL for (int b = 0; b < L; ++b) acc[a][b] =
      _mm256_loadu_pd(s + (j0 + a) * np + m0 + 4 * b);
  for (std::size_t i = 0; i < rows; ++i) {
    const double* pi = p + i * np + m0;
    const double* wi = w + i * nw + j0;
    __m256d x[L];
    CALDAQ_UNROLL for (int b = 0; b < L; ++b) x[b] = _mm256_loadu_pd(pi + 4 * b);
    CALDAQ_UNROLL for (int a = 0; a < 4; ++a) {
      const __m256d v = _mm256_broadcast_sd(wi + a);
      CALDAQ_UNROLL for (int b = 0; b < L; ++b) acc[a][b] =
          _mm256_add_pd(acc[a][b], _mm256_mul_pd(v, x[b]));
    }
  }
  CALDAQ_UNROLL for (int a = 0; a < 4; ++a) CALDAQ_UNROLL for (int b = 0; b < L; ++b)
      _mm256_storeu_pd(s + (j0 + a) * np + m0 + 4 * b, acc[a][b]);
}

__attribute__((target("avx2"))) void add_avx2(double* s, const double* w, const double* p,
                                              std::size_t rows, std::size_t nw, std::size_t np) {
  for (std::size_t j0 = 0; j0 < nw; j0 += 4) {
    std::size_t m0 = 0;
    for (; m0 + 12 <= np; m0 += 12) tile_avx2<3>(s, w, p, rows, nw, np, j0, m0);
    for (; m0 < np; m0 += 4) tile_avx2<1>(s, w, p, rows, nw, np, j0, m0);
  }
}

bool detect_avx2() {
  __builtin_cpu_init();  // may run before the CPU-model constructor of libgcc
  return __builtin_cpu_supports("avx2");
}
// False (the SSE2 path, the same sums) if a static initializer elsewhere runs first.
const bool kAvx2 = detect_avx2();
#else
const bool kAvx2 = false;
#endif

}  // namespace

void add_outer_products_portable(double* s, const double* w, const double* p, std::size_t rows,
                                 std::size_t nw, std::size_t np) {
  for (std::size_t j = 0; j < nw; ++j)
    for (std::size_t m = 0; m < np; ++m) {
      double sum = s[j * np + m];
      for (std::size_t i = 0; i < rows; ++i) sum += w[i * nw + j] * p[i * np + m];
      s[j * np + m] = sum;
    }
}

void add_outer_products(double* s, const double* w, const double* p, std::size_t rows,
                        std::size_t nw, std::size_t np) {
#if defined(__x86_64__)
  if (kAvx2) return add_avx2(s, w, p, rows, nw, np);
  return add_sse2(s, w, p, rows, nw, np);
#else
  add_outer_products_portable(s, w, p, rows, nw, np);
#endif
}

bool outer_products_avx2() { return kAvx2; }

#if defined(__x86_64__)
bool detail::add_outer_products_sse2(double* s, const double* w, const double* p, std::size_t rows,
                                     std::size_t nw, std::size_t np) {
  add_sse2(s, w, p, rows, nw, np);
  return true;
}

bool detail::add_outer_products_avx2(double* s, const double* w, const double* p, std::size_t rows,
                                     std::size_t nw, std::size_t np) {
  if (!detect_avx2()) return false;  // (not kAvx2: false too if read before it is set)
  add_avx2(s, w, p, rows, nw, np);
  return true;
}
#else
// Neither path on other CPUs: the caller is told so.
bool detail::add_outer_products_sse2(double*, const double*, const double*, std::size_t,
                                     std::size_t, std::size_t) {
  return false;
}
bool detail::add_outer_products_avx2(double*, const double*, const double*, std::size_t,
                                     std::size_t, std::size_t) {
  return false;
}
#endif

}  // namespace cal
