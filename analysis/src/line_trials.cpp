// The vibration's line fit at several trial frequencies in one pass (line_trials.hpp).
#include "cal/analysis/line_trials.hpp"

#include <cstring>
#include <numbers>
#include <stdexcept>
#include <string>

#include "cal/analysis/sin_cos.hpp"

namespace cal {
namespace {

constexpr double pi = std::numbers::pi;
constexpr std::size_t sums_per_trial = 27;  // 21 of r r' and 6 of r y

// Two trials side by side in one SSE2 register (GCC's and Clang's vector extension; plain x86-64
// has SSE2): each lane's operations are the scalar ones, so its values are the scalar bits.
// Loaded and stored unaligned (a std::vector<double> promises 8 bytes).
typedef double Pair __attribute__((vector_size(16)));

Pair load(const double* p) {
  Pair v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
void store(double* p, Pair v) { std::memcpy(p, &v, sizeof v); }

}  // namespace

LineTrials::LineTrials(double f0_hz, double centre_hz, double step_hz, int reach, bool centre,
                       std::size_t pieces)
    : f0_hz_(f0_hz),
      centre_hz_(centre_hz),
      step_hz_(step_hz),
      reach_(reach),
      centre_(centre),
      pairs_(static_cast<std::size_t>(reach) + (centre ? 1 : 0)),
      pieces_(pieces) {
  if (reach < 1 || reach > max_offset || pieces == 0)
    throw std::invalid_argument("LineTrials: reach " + std::to_string(reach) + " not in 1 .. " +
                                std::to_string(max_offset) + ", or no piece");
  for (int k = -reach; k <= reach; ++k)
    if (k != 0 || centre) offsets_.push_back(k);
  sums_.assign(pieces_ * pairs_ * sums_per_trial * 2, 0.0);
}

std::size_t LineTrials::pair_of(int offset) const {
  const int m = offset < 0 ? -offset : offset;
  return static_cast<std::size_t>(m) - (centre_ ? 0 : 1);
}

template <class F>
void LineTrials::each_pair(double t_s, F&& f) const {
  // The arguments as the pass per trial wrote them (2 pi f t, left to right).
  const SinCos c = sin_cos(2 * pi * centre_hz_ * t_s), d = sin_cos(2 * pi * step_hz_ * t_s),
               e = sin_cos(2 * pi * f0_hz_ * t_s);
  const Pair sb = {e.s, e.s}, cb = {e.c, e.c};
  std::size_t q = 0;
  if (centre_) f(q++, Pair{c.s, 0.0}, Pair{c.c, 0.0}, sb, cb);  // the unused lane's sums stay 0
  // The trials -m and +m: c conj(d)^m and c d^m, each the last pair times (conj d, d).
  const Pair dr = {d.c, d.c}, di = {-d.s, d.s};
  Pair zr = Pair{c.c, c.c} * dr - Pair{c.s, c.s} * di;
  Pair zi = Pair{c.s, c.s} * dr + Pair{c.c, c.c} * di;
  for (int m = 1;; ++m) {
    f(q++, zi, zr, sb, cb);
    if (m == reach_) break;
    const Pair next_r = zr * dr - zi * di;
    zi = zi * dr + zr * di;
    zr = next_r;
  }
}

void LineTrials::add(std::size_t piece, double t_s, double y) {
  const Pair yy = {y, y};
  double* const first = sums_.data() + piece * pairs_ * sums_per_trial * 2;
  // Inlined (GCC called it for each pair, a third of the time).
  each_pair(
      t_s, [ first, yy ](std::size_t q, Pair sa, Pair ca, Pair sb,
                         Pair cb) __attribute__((always_inline)) {
        double* const acc = first + q * sums_per_trial * 2;
        // The row as the pass per trial made it: (f - f0), f, (f + f0).
        const Pair r0 = sa * cb - ca * sb, r1 = ca * cb + sa * sb, r2 = sa, r3 = ca,
                   r4 = sa * cb + ca * sb, r5 = ca * cb - sa * sb;
        // r r' by rows of its lower triangle, then r y: each sum one product and one addition.
        // Written out, so that the row stays in registers.
        const auto sum = [acc](std::size_t p, Pair v) {
          store(acc + 2 * p, load(acc + 2 * p) + v);
        };
        sum(0, r0 * r0);
        sum(1, r0 * r1), sum(2, r1 * r1);
        sum(3, r0 * r2), sum(4, r1 * r2), sum(5, r2 * r2);
        sum(6, r0 * r3), sum(7, r1 * r3), sum(8, r2 * r3), sum(9, r3 * r3);
        sum(10, r0 * r4), sum(11, r1 * r4), sum(12, r2 * r4), sum(13, r3 * r4), sum(14, r4 * r4);
        sum(15, r0 * r5), sum(16, r1 * r5), sum(17, r2 * r5), sum(18, r3 * r5), sum(19, r4 * r5);
        sum(20, r5 * r5);
        sum(21, r0 * yy), sum(22, r1 * yy), sum(23, r2 * yy), sum(24, r3 * yy), sum(25, r4 * yy);
        sum(26, r5 * yy);
      });
}

LineTrials::Sums LineTrials::sums(int offset, std::size_t g) const {
  if (offset < -reach_ || offset > reach_ || (offset == 0 && !centre_) || g >= pieces_)
    throw std::invalid_argument("LineTrials::sums: no trial " + std::to_string(offset) +
                                " or piece " + std::to_string(g));
  const double* acc =
      sums_.data() + (g * pairs_ + pair_of(offset)) * sums_per_trial * 2 + lane_of(offset);
  Sums out;
  for (std::size_t p = 0; p < 21; ++p) out.lower[p] = acc[2 * p];
  for (std::size_t p = 0; p < 6; ++p) out.ry[p] = acc[2 * (21 + p)];
  return out;
}

std::vector<LineTrials::Row> LineTrials::rows(double t_s) const {
  std::vector<std::array<double, 12>> pairs(pairs_);  // each pair's two rows, lane by lane
  each_pair(t_s, [&pairs](std::size_t q, Pair sa, Pair ca, Pair sb, Pair cb) {
    const Pair r[6] = {sa * cb - ca * sb, ca * cb + sa * sb, sa, ca,
                       sa * cb + ca * sb, ca * cb - sa * sb};
    for (std::size_t i = 0; i < 6; ++i) pairs[q][i] = r[i][0], pairs[q][6 + i] = r[i][1];
  });
  std::vector<Row> out;
  for (const int k : offsets_) {
    const auto& p = pairs[pair_of(k)];
    Row row;
    for (std::size_t i = 0; i < 6; ++i) row[i] = p[6 * lane_of(k) + i];
    out.push_back(row);
  }
  return out;
}

LineTrials::Row LineTrials::row(double f_hz, double f0_hz, double t_s) {
  const SinCos a = sin_cos(2 * pi * f_hz * t_s), b = sin_cos(2 * pi * f0_hz * t_s);
  return {a.s * b.c - a.c * b.s, a.c * b.c + a.s * b.s, a.s, a.c,
          a.s * b.c + a.c * b.s, a.c * b.c - a.s * b.s};
}

}  // namespace cal
