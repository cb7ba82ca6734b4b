#pragma once
// Sums of outer products, S += W' P for row-major W (rows x nw) and P (rows x np): the one-pass
// period search's series and Gram matrix of the ballbar analysis, 16 x ~50 sums a sample (issue
// 32: Eigen's product, SSE2 only in this build, took 2.3 instructions a multiply-add at these
// shapes). Each sum is taken over the rows in order, one multiplication and one addition a row
// (no fused multiply-add), so every path gives the same bits: the portable loop, the SSE2 one
// and, where the CPU has it, the AVX2 one (OuterSums.* in tests/analysis/circle_kernels_test.cpp).
#include <cstddef>

namespace cal {

// s[j np + m] += sum over i < rows, in order, of w[i nw + j] * p[i np + m] (j < nw, m < np).
// nw and np multiples of 4.
void add_outer_products(double* s, const double* w, const double* p, std::size_t rows,
                        std::size_t nw, std::size_t np);
// The same by a plain loop (the reference the others equal bit for bit).
void add_outer_products_portable(double* s, const double* w, const double* p, std::size_t rows,
                                 std::size_t nw, std::size_t np);
// Whether add_outer_products takes the AVX2 path on this CPU.
bool outer_products_avx2();

namespace detail {
// The x86-64 paths themselves, whatever add_outer_products would choose, for the test that
// holds them to the same bits (tests/analysis/circle_kernels_test.cpp). Each returns false,
// having done nothing, where it cannot run: not an x86-64 build, or (AVX2) not on this CPU.
bool add_outer_products_sse2(double* s, const double* w, const double* p, std::size_t rows,
                             std::size_t nw, std::size_t np);
bool add_outer_products_avx2(double* s, const double* w, const double* p, std::size_t rows,
                             std::size_t nw, std::size_t np);
}  // namespace detail

}  // namespace cal
