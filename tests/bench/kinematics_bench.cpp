// Benchmarks of the kinematic model (run with build/tests/analysis_bench; BENCHMARK_MAIN is in
// analysis_bench.cpp): the volumetric error map of 50 x 50 x 50 points over a 1000 x 800 x 600
// mm volume, by the exact HTM product and by the first-order sum, on a machine whose 18
// component errors are cubic polynomials and two of them tables (the table search is part of
// the cost a real measured machine has), on XFYZ and on YFXZ; building the model from 21
// component tables as measured runs give them (41 points each, the three squareness values),
// with its cross-axis compensation tables; and the correction and residual of the verification
// loop over the same 50 x 50 x 50 grid.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "cal/analysis/kinematics.hpp"
#include "cal/analysis/volumetric_comp.hpp"

namespace {

using namespace cal::kinematics;

Machine bench_machine(Topology t = Topology::xfyz) {
  Machine m;
  m.topology = t;
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
  const auto topology = static_cast<Topology>(state.range(2));
  const Machine m = bench_machine(topology);
  const Grid g{{0.0, 0.0, -600.0}, {1000.0, 800.0, 0.0}, {n, n, n}};
  for (auto _ : state) {
    auto map = volumetric_error_map(m, g, method);
    benchmark::DoNotOptimize(map.errors_um.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n * n * n));
  state.SetLabel(std::string(method == Method::htm ? "htm " : "first_order ") +
                 std::string(to_string(topology)));
}
BENCHMARK(BM_KinematicsMap)
    ->Args({static_cast<int>(Method::htm), 50, static_cast<int>(Topology::xfyz)})
    ->Args({static_cast<int>(Method::first_order), 50, static_cast<int>(Topology::xfyz)})
    ->Args({static_cast<int>(Method::htm), 50, static_cast<int>(Topology::yfxz)})
    ->Args({static_cast<int>(Method::first_order), 50, static_cast<int>(Topology::yfxz)})
    ->Unit(benchmark::kMillisecond);

// The model from 21 measured components: 18 tables of 41 points (every 25 mm over 1000 mm, as
// a laser run gives them) and three squareness values, then its nine cross-axis tables on a
// 25 mm grid (what `daq model build` followed by `daq model compensate` will do per machine).
void BM_ModelFrom21Tables(benchmark::State& state) {
  std::vector<std::vector<double>> values;
  std::vector<double> q;
  for (int i = 0; i <= 40; ++i) q.push_back(25.0 * i);
  for (int c = 0; c < 18; ++c) {
    std::vector<double> v;
    for (int i = 0; i <= 40; ++i) v.push_back(0.1 * (c + 1) * std::sin(0.2 * i + c));
    values.push_back(v);
  }
  const std::array<cal::volcomp::AxisGrid, 3> grid{cal::volcomp::AxisGrid{0.0, 25.0, 41},
                                                   cal::volcomp::AxisGrid{0.0, 25.0, 33},
                                                   cal::volcomp::AxisGrid{0.0, 25.0, 25}};
  for (auto _ : state) {
    Machine m;
    m.topology = Topology::yfxz;
    for (std::size_t c = 0; c < 18; ++c)
      component(m, all_components()[c]) = ErrorFunction::table(q, values[c]);
    m.squareness = {20.0, -15.0, 10.0};
    m.tool_offset_mm = {0.0, 0.0, -150.0};
    auto tables = cal::volcomp::cross_tables(m, grid, {500.0, 400.0, 300.0});
    benchmark::DoNotOptimize(tables.tables.data());
  }
}
BENCHMARK(BM_ModelFrom21Tables)->Unit(benchmark::kMicrosecond);

// The verification loop over 50 x 50 x 50 points: the correction (first order) and the exact
// residual after applying it, per point.
void BM_CorrectionAndResidual(benchmark::State& state) {
  const Machine m = bench_machine(Topology::yfxz);
  const int n = 50;
  for (auto _ : state) {
    double worst = 0.0;
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j)
        for (int i = 0; i < n; ++i) {
          const Vec3 p{1000.0 * i / (n - 1), 800.0 * j / (n - 1), -600.0 * k / (n - 1)};
          const Vec3 r = cal::volcomp::residual_um(m, p, cal::volcomp::correction_um(m, p));
          worst = std::max(worst, std::abs(r[0]) + std::abs(r[1]) + std::abs(r[2]));
        }
    benchmark::DoNotOptimize(worst);
  }
  state.SetItemsProcessed(state.iterations() * n * n * n);
}
BENCHMARK(BM_CorrectionAndResidual)->Unit(benchmark::kMillisecond);

}  // namespace
