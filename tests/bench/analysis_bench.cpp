// Google Benchmark programs of the analysis library. Run by hand:
//   build/tests/analysis_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// The suite only smoke-runs them (ctest bench_smoke) so that they keep compiling and running.
#include <benchmark/benchmark.h>

#include <random>

#include "cal/analysis/air.hpp"
#include "cal/analysis/iso230_2.hpp"

namespace {

void BM_RefractiveIndex(benchmark::State& state) {
  const auto eq = static_cast<cal::air::Equation>(state.range(0));
  cal::air::Conditions c;
  double t = 20.0;
  for (auto _ : state) {
    c.temperature_degc = t;
    t = t > 25.0 ? 15.0 : t + 1e-3;  // vary the input so nothing is hoisted out of the loop
    benchmark::DoNotOptimize(cal::air::refractive_index(c, eq).n);
  }
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(std::string(cal::air::to_string(eq)));
}
BENCHMARK(BM_RefractiveIndex)
    ->Arg(static_cast<int>(cal::air::Equation::edlen))
    ->Arg(static_cast<int>(cal::air::Equation::ciddor))
    ->Arg(static_cast<int>(cal::air::Equation::shop_floor));

// ISO 230-2 evaluation of 100 targets x 10 runs x 2 directions (2000 deviations).
void BM_Iso230_2_Evaluate(benchmark::State& state) {
  const int targets = static_cast<int>(state.range(0)), runs = static_cast<int>(state.range(1));
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, 0.5);
  std::vector<cal::iso230_2::Measurement> data;
  for (int i = 0; i < targets; ++i) {
    for (int j = 1; j <= runs; ++j) {
      for (auto d : {cal::iso230_2::Direction::up, cal::iso230_2::Direction::down}) {
        data.push_back({10.0 * i, j, d, 0.01 * i + noise(rng)});
      }
    }
  }
  for (auto _ : state) {
    auto e = cal::iso230_2::evaluate(data, cal::iso230_2::Standard::iso230_2_2014);
    benchmark::DoNotOptimize(e.axis.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(data.size()));
}
BENCHMARK(BM_Iso230_2_Evaluate)->Args({100, 10})->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
