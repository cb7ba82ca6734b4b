// How schema1.sqlite was made: with the store of caldaq commit 604604a (schema version 1, the
// 17-byte chunk records), before the chunk format changed. Not built by the project; kept so
// that the fixture's contents are known. The readings follow formulas that
// tests/storage/store_test.cpp recomputes independently:
//   run 1 (complete): 3 batches of 4000 readings of a 10 kHz length stream (device 0, quantity 1)
//     with air (device 1, quantities 2, 3, 4; value s = i / 2000: 20 + 0.01 s degC,
//     101325 - s Pa, 45 + 0.1 s %RH) at every 2000th reading; reading i at i * 100000 ns,
//     value 0.1 + 1e-9 * (i % 977), status 1 when i % 1000 == 999;
//   run 2 (left running: its owner_pid was then set to 4194305, above Linux's largest pid, so
//     it reads as a crashed run): 1000 readings of device 0, quantity 0 at i * 1000 ns,
//     value -0.25 + i * 1e-6;
//   one captured target and one result for run 1.
// Build: g++ -std=c++20 -I/work/main/storage/include -I/work/main/analysis/include
//        make_schema1.cpp /work/main/build/storage/libcaldaq_storage.a -lsqlite3 -lfmt
#include <cstdio>
#include <vector>

#include "cal/storage/store.hpp"

int main(int argc, char** argv) {
  using namespace cal::storage;
  Store store(argc > 1 ? argv[1] : "schema1.sqlite");
  const auto machine = store.add_machine({.name = "fixture mill", .description = "schema 1"});
  const auto run1 = store.begin_run({.machine_id = machine,
                                     .campaign = "schema 1 fixture",
                                     .kind = "linear",
                                     .axis = "X",
                                     .started_unix_ms = 1700000000000});
  store.add_instrument({.run_id = run1, .device = 0, .driver = "gauge", .transport = "fixture"});
  store.add_instrument({.run_id = run1, .device = 1, .driver = "ptu300", .transport = "fixture"});
  std::int64_t i = 0;
  for (int batch = 0; batch < 3; ++batch) {
    std::vector<RawReading> rs;
    for (int k = 0; k < 4000; ++k, ++i) {
      rs.push_back({.time_ns = i * 100000,
                    .device = 0,
                    .quantity = 1,
                    .status = static_cast<std::uint8_t>(i % 1000 == 999 ? 1 : 0),
                    .value = 0.1 + 1e-9 * static_cast<double>(i % 977)});
      if (i % 2000 == 0) {
        const double s = static_cast<double>(i / 2000);
        rs.push_back({.time_ns = i * 100000, .device = 1, .quantity = 2, .value = 20.0 + 0.01 * s});
        rs.push_back({.time_ns = i * 100000, .device = 1, .quantity = 3, .value = 101325.0 - s});
        rs.push_back({.time_ns = i * 100000, .device = 1, .quantity = 4, .value = 45.0 + 0.1 * s});
      }
    }
    store.append_readings(run1, rs);
  }
  store.add_targets(std::vector<CapturedTarget>{{.run_id = run1,
                                                 .target_index = 0,
                                                 .run_number = 1,
                                                 .direction = '+',
                                                 .nominal_mm = 100.0,
                                                 .time_ns = 5000000,
                                                 .raw_m = 0.1000001,
                                                 .deviation_um = 0.1}});
  store.add_result({.run_id = run1, .standard = "fixture", .json = "{\"fixture\": true}"});
  store.finish_run(run1, RunStatus::complete);
  const auto run2 = store.begin_run({.machine_id = machine, .kind = "linear", .axis = "Y"});
  std::vector<RawReading> rs;
  for (std::int64_t k = 0; k < 1000; ++k)
    rs.push_back({.time_ns = k * 1000, .value = -0.25 + static_cast<double>(k) * 1e-6});
  store.append_readings(run2, rs);
  std::printf("runs %lld and %lld written\n", static_cast<long long>(run1),
              static_cast<long long>(run2));
}
