// Benchmarks of the kinematic model (run with build/tests/analysis_bench; BENCHMARK_MAIN is in
// analysis_bench.cpp): the volumetric error map of 50 x 50 x 50 points over a 1000 x 800 x 600
// mm volume, by the exact HTM product and by the first-order sum, on an XFYZ machine whose 18
// component errors are cubic polynomials and two of them tables (the table search is part of
// the cost a real measured machine has).
#include <benchmark/benchmark.h>

#include <vector>

#include "cal/analysis/kinematics.hpp"

namespace {

using namespace cal::kinematics;

Machine bench_machine() {
  Machine m;
  m.topology = Topology::xfyz;
  double v = 1.0;
  for (Component c : all_components()) {
    component(m, c) = ErrorFunction::polynomial({v, 1e-3 * v, -1e-6 * v, 1e-9 * v});
    v += 1.0;
  }
  std::vector<double> q, e;
  for (int i = 0; i <= 40; ++i) {  // 41-point tables every 25 mm, as a laser run gives
    q.push_back(25.0 * i);
    e.push_back(0.1 * i - 0.002 * i * i);
  }
  m.axes[X].ex_um = ErrorFunction::table(q, e);
  m.axes[X].ey_um = ErrorFunction::table(q, e);
  m.squareness = {20.0, -15.0, 10.0};
  m.tool_offset_mm = {0.0, 0.0, -150.0};
  m.table_offset_mm = {-500.0, 200.0, -50.0};
  return m;
}

void BM_KinematicsMap(benchmark::State& state) {
  const auto method = static_cast<Method>(state.range(0));
  const auto n = static_cast<std::size_t>(state.range(1));
  const Machine m = bench_machine();
  const Grid g{{0.0, 0.0, -600.0}, {1000.0, 800.0, 0.0}, {n, n, n}};
  for (auto _ : state) {
    auto map = volumetric_error_map(m, g, method);
    benchmark::DoNotOptimize(map.errors_um.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n * n * n));
  state.SetLabel(method == Method::htm ? "htm" : "first_order");
}
BENCHMARK(BM_KinematicsMap)
    ->Args({static_cast<int>(Method::htm), 50})
    ->Args({static_cast<int>(Method::first_order), 50})
    ->Unit(benchmark::kMillisecond);

}  // namespace
