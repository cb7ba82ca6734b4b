// Ballbar diagnostics fit of 2 x 36,000 samples: two 360 degree traces at 1 kHz, 36 s each
// (R = 100 mm at 1047 mm/min), with the cyclic-error period given, and with it searched
// (61 trial periods). BENCHMARK_MAIN is in analysis_bench.cpp.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "cal/analysis/circle.hpp"

namespace {

using namespace cal::circle;

std::vector<Trace> traces() {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, 0.2);
  std::vector<Trace> out;
  for (auto d : {Direction::ccw, Direction::cw}) {
    Trace t{d, {}, {}};
    const double s = d == Direction::ccw ? 1.0 : -1.0;
    for (int i = 0; i < 36'000; ++i) {
      const double a = s * i * 0.01;  // degrees
      const double r = a * std::numbers::pi / 180;
      t.angle_deg.push_back(a);
      t.deviation_um.push_back(3 * std::cos(2 * r) - 2 * std::sin(2 * r) +
                               1.5 * s * std::sin(2 * r) + noise(rng));
    }
    out.push_back(std::move(t));
  }
  return out;
}

void BM_BallbarDiagnostics_2x36000(benchmark::State& state) {
  const auto t = traces();
  const Setup setup{.radius_mm = 100, .feed_mm_per_min = 1047, .cyclic_period_mm = 10.0};
  for (auto _ : state) benchmark::DoNotOptimize(analyse(setup, t));
  state.SetItemsProcessed(state.iterations() * 72'000);
}
BENCHMARK(BM_BallbarDiagnostics_2x36000)->Unit(benchmark::kMillisecond);

void BM_BallbarDiagnosticsPeriodSearch_2x36000(benchmark::State& state) {
  const auto t = traces();
  const Setup setup{.radius_mm = 100, .feed_mm_per_min = 1047};
  for (auto _ : state) benchmark::DoNotOptimize(analyse(setup, t));
  state.SetItemsProcessed(state.iterations() * 72'000);
}
BENCHMARK(BM_BallbarDiagnosticsPeriodSearch_2x36000)->Unit(benchmark::kMillisecond);

}  // namespace
