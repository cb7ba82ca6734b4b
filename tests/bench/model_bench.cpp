// The model file caldaq.model.v1: reading (parse and validate) and writing a model of 18
// component tables of 41 points each and three squareness values, the size `daq model build`
// writes for a machine measured every 25 mm over 1000 mm. Run build/tests/model_bench (Google
// Benchmark; method in docs/benchmarks.md).
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>

#include "model/model_file.hpp"

namespace {

namespace kin = cal::kinematics;

cal::daq::model::Model model_of_21_tables() {
  cal::daq::model::Model m;
  m.name = "bench";
  m.machine.topology = kin::Topology::yfxz;
  std::vector<double> q;
  for (int i = 0; i <= 40; ++i) q.push_back(25.0 * i);
  std::size_t c = 0;
  for (kin::Component comp : kin::all_components()) {
    std::vector<double> v;
    for (int i = 0; i <= 40; ++i)
      v.push_back(0.1 * static_cast<double>(c + 1) * std::sin(0.2 * i + static_cast<double>(c)));
    kin::component(m.machine, comp) = kin::ErrorFunction::table(q, v);
    m.components[c].given = true;
    ++c;
  }
  m.machine.squareness = {20.0, -15.0, 10.0};
  for (auto& s : m.squareness) s.given = true;
  m.travel_mm = std::array<std::array<double, 2>, 3>{{{0, 1000}, {0, 1000}, {0, 1000}}};
  return m;
}

void BM_ModelFileWrite(benchmark::State& state) {
  const auto m = model_of_21_tables();
  std::size_t bytes = 0;
  for (auto _ : state) {
    const std::string text = cal::daq::model::to_json(m);
    bytes = text.size();
    benchmark::DoNotOptimize(text.data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * bytes));
}
BENCHMARK(BM_ModelFileWrite)->Unit(benchmark::kMicrosecond);

void BM_ModelFileRead(benchmark::State& state) {
  const std::string text = cal::daq::model::to_json(model_of_21_tables());
  for (auto _ : state) {
    auto m = cal::daq::model::parse(text, "bench.json");
    benchmark::DoNotOptimize(&m);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * text.size()));
}
BENCHMARK(BM_ModelFileRead)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
