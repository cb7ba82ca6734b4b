#pragma once
// The vibration's line fit (circle_dynamics.cpp, docs/circle.md) at several trial frequencies
// in one pass over the samples (issue 32). The fit's row at frequency f and time t is
//   r = (sin, cos)(phi - phi0), (sin, cos)(phi), (sin, cos)(phi + phi0),
//   phi = 2 pi f t, phi0 = 2 pi f0 t (f0 the feed's frequency),
// and its normal equations are the sums of r r' and r y over each piece of a trace. The search
// tries f = centre + k step for several k; a pass a trial, each with two sines and two cosines
// a sample, made a run with a vibration cost 15x the analysis of one without.
//
// Here each sample costs three sin_cos whatever the number of trials: (sin, cos)(phi) of trial
// k is e^{i 2 pi centre t} d^k with d = e^{i 2 pi step t}, stepped out from the centre by d
// and its conjugate (angle sums, the trials -m and +m side by side in one SSE2 register),
// anchored afresh at every sample, so the error does not grow along the run. Its error,
// against the same arguments 2 pi centre t, 2 pi step t, 2 pi f0 t taken exactly: each
// component of a row within (|k| + 2) 6.5e-16 (`row_error_bound`, tested in
// tests/analysis/line_trials_test.cpp). Each sin_cos is within 1.2e-16 a component
// (0.8 - 1.1 ulp of values up to 1, sin_cos.hpp), 1.7e-16 as a complex number; each step of
// the ladder adds d's error and its own rounding (two products and a sum a component,
// 3.3e-16; 4.7e-16 as a complex number), so the phase of trial k is within 1.7e-16 +
// |k| 6.4e-16, and the row's products
// with the rotation at f0 add 1.7e-16 + 3.3e-16. That is far below the rounding of the phase
// itself (2 pi f t for t of tens of seconds is 1e3 - 1e5 rad, whose ulp is 1e-13 - 1.5e-11),
// which the pass per trial had too. The sums are taken as the pass per trial took them
// (Eigen's rank update of the lower triangle, and r y, sample after sample, one multiplication
// and one addition each, no fused multiply-add), so with the same rows they would be the same
// bits.
#include <array>
#include <cstddef>
#include <vector>

namespace cal {

class LineTrials {
 public:
  static constexpr int max_offset = 16;
  // The largest error of a row's component of trial k (|k| <= max_offset), against the same
  // arguments taken exactly (see above).
  static constexpr double row_error_bound(int k) { return ((k < 0 ? -k : k) + 2) * 6.5e-16; }

  using Row = std::array<double, 6>;
  struct Sums {
    std::array<double, 21> lower{};  // sum r r', lower triangle by rows: (0,0), (1,0), (1,1), ...
    Row ry{};                        // sum r y
  };

  // Trials f = centre_hz + k step_hz for k = -reach .. reach (1 <= reach <= max_offset), k = 0
  // only if `centre` (a search's later rounds know it already), each summed in `pieces`
  // pieces. Throws std::invalid_argument on a reach out of range or no piece.
  LineTrials(double f0_hz, double centre_hz, double step_hz, int reach, bool centre,
             std::size_t pieces);

  // Sample y at time t_s into piece `piece` (< pieces) of every trial.
  void add(std::size_t piece, double t_s, double y);

  // The trials' offsets k, rising.
  const std::vector<int>& offsets() const { return offsets_; }
  // The sums of trial `offset` over piece g.
  Sums sums(int offset, std::size_t g) const;

  // The rows of every trial at t_s (in offsets()'s order), as add() makes them (for the
  // error's test).
  std::vector<Row> rows(double t_s) const;
  // One row at f_hz, its sine and cosine each taken directly (sin_cos): the fitted lines'
  // contribution at the frequency found.
  static Row row(double f_hz, double f0_hz, double t_s);

 private:
  // f(pair, sin a, cos a, sin b, cos b) for each pair of trials, a the trials' phases (two
  // lanes), b the rotation's at f0.
  template <class F>
  void each_pair(double t_s, F&& f) const;
  std::size_t pair_of(int offset) const;
  std::size_t lane_of(int offset) const { return offset > 0 ? 1 : 0; }

  double f0_hz_, centre_hz_, step_hz_;
  int reach_ = 0;
  bool centre_ = false;
  std::vector<int> offsets_;
  std::size_t pairs_ = 0;  // pair 0 is (0, unused) with the centre; then (-m, m), m = 1 .. reach
  std::size_t pieces_ = 0;
  std::vector<double> sums_;  // per piece, per pair, 27 sums of 2 lanes
};

}  // namespace cal
