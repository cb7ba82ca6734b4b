// Per-reading costs of the ingest pipeline that issue 20 named (method: docs/benchmarks.md):
// CRC-32C of capture blocks and chunks (the CPU instruction, slicing-by-8, and the former
// table look-up per byte, kept here as the reference), and the environmental compensation of
// a 10 kHz stream while the newest air sample is held (the live case: computed once per
// sample) and while every reading falls between two samples (the equation per reading).
// The gauge stage of `daq bench ingest` (its 13-byte lines "+100.000123\r\n", ten per chunk):
// the number alone by std::from_chars (the parser before) and by parse_number (its exact fast
// path), and the whole line decode; and the writer's chunk encoding and checksum of a batch.
#include <benchmark/benchmark.h>

#include <array>
#include <charconv>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "cal/analysis/crc32c.hpp"
#include "cal/daq/env_stage.hpp"
#include "cal/drivers/codec/common.hpp"
#include "cal/storage/chunk.hpp"
#include "line_gauge/codec.hpp"

namespace {

std::vector<std::byte> block() {
  std::vector<std::byte> b(64 * 1024);  // a capture block
  std::mt19937 rng(1);
  for (auto& x : b) x = static_cast<std::byte>(rng());
  return b;
}

// The capture reader's CRC before issue 20: one table look-up per byte.
std::uint32_t crc32c_bytewise(std::span<const std::byte> data) {
  static const auto table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? (c >> 1) ^ 0x82F63B78u : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  std::uint32_t c = ~0u;
  for (std::byte b : data) c = table[(c ^ static_cast<std::uint8_t>(b)) & 0xff] ^ (c >> 8);
  return ~c;
}

void BM_Crc32c(benchmark::State& state) {
  const auto b = block();
  for (auto _ : state) {
    switch (state.range(0)) {
      case 0:
        benchmark::DoNotOptimize(cal::crc32c(b));
        break;
      case 1:
        benchmark::DoNotOptimize(cal::crc32c_portable(b));
        break;
      default:
        benchmark::DoNotOptimize(crc32c_bytewise(b));
    }
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * b.size()));
  state.SetLabel(state.range(0) == 0   ? (cal::crc32c_hardware() ? "CPU instruction" : "portable")
                 : state.range(0) == 1 ? "slicing-by-8"
                                       : "byte at a time (before)");
}
BENCHMARK(BM_Crc32c)->Arg(0)->Arg(1)->Arg(2);

void BM_EnvStageCompensate(benchmark::State& state) {
  const bool held = state.range(0) == 0;
  cal::daq::EnvironmentConfig cfg;
  cal::daq::EnvStage env(cfg, 1);
  constexpr std::int64_t s = 1'000'000'000;
  // Samples at 0 and 1 s: readings after 1 s hold the newest, readings between interpolate.
  for (std::int64_t t : {std::int64_t{0}, s}) {
    env.add_air(t, cal::daq::AirQuantity::temperature_degc, t ? 20.1 : 20.0);
    env.add_air(t, cal::daq::AirQuantity::pressure_pa, t ? 101300.0 : 101325.0);
    env.add_air(t, cal::daq::AirQuantity::humidity_pct, 45.0);
    env.add_material(t, 0, 20.5);
  }
  std::int64_t t = held ? s : 0;
  double sink = 0.0;
  std::int64_t n = 0;
  for (auto _ : state) {
    t += 100'000;  // 10 kHz
    if (!held && t >= s) t = 1;
    if (held && ++n % 10'000 == 0) {  // a new 1 Hz air sample, as live
      const double k = static_cast<double>(n / 10'000 % 100);
      env.add_air(t, cal::daq::AirQuantity::temperature_degc, 20.0 + 1e-3 * k);
      env.add_air(t, cal::daq::AirQuantity::pressure_pa, 101325.0 - 0.1 * k);
      env.add_air(t, cal::daq::AirQuantity::humidity_pct, 45.0);
      env.add_material(t, 0, 20.5);
    }
    sink += env.compensate(t, 0.1).length_m;
  }
  benchmark::DoNotOptimize(sink);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations()));
  state.SetLabel(held ? "newest 1 Hz sample held (once per sample)"
                      : "between two samples (per reading)");
}
BENCHMARK(BM_EnvStageCompensate)->Arg(0)->Arg(1);

// The benchmark's gauge lines, as daq bench ingest writes them (daq/src/cmd_bench.cpp).
std::string gauge_lines(int n) {
  std::string out;
  char line[32];
  for (int k = 0; k < n; ++k) {
    std::snprintf(line, sizeof line, "%+011.6f\r\n", 100.0 + 1e-6 * static_cast<double>(k % 977));
    out += line;
  }
  return out;
}

// Arg 0: std::from_chars after the '+' (parse_number before issue 20); 1: parse_number.
void BM_GaugeNumber(benchmark::State& state) {
  const std::string text = gauge_lines(1000);
  std::vector<std::string_view> numbers;
  for (std::size_t i = 0; i + 13 <= text.size(); i += 13) numbers.push_back({text.data() + i, 11});
  for (auto _ : state) {
    double sum = 0.0;
    for (auto s : numbers) {
      if (state.range(0) == 0) {
        double v = 0.0;
        s.remove_prefix(1);
        std::from_chars(s.data(), s.data() + s.size(), v);
        sum += v;
      } else {
        sum += *cal::drivers::codec::parse_number(s);
      }
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * numbers.size()));
}
BENCHMARK(BM_GaugeNumber)->Arg(0)->Arg(1);

// The gauge codec's whole decode (split, parse, unit, range) of chunks of ten lines.
void BM_GaugeDecode(benchmark::State& state) {
  const std::string text = gauge_lines(1000);
  cal::drivers::codec::GaugeCodec codec;
  std::vector<cal::drivers::codec::CodecError> errors;
  for (auto _ : state) {
    double sum = 0.0;
    for (std::size_t i = 0; i < text.size(); i += 130)
      codec.feed_values(
          cal::drivers::codec::as_bytes(std::string_view(text).substr(i, 130)),
          [&](double v, std::string_view) { sum += v; }, errors);
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * 1000));
}
BENCHMARK(BM_GaugeDecode);

// A writer batch of the bench's series (16384 readings, ten per 1 ms): arg 0 encoding only,
// 1 encoding and the chunk checksum.
void BM_ChunkEncode(benchmark::State& state) {
  cal::storage::chunk::Columns c;
  for (std::int64_t i = 0; i < 16384; ++i)
    c.push({.time_ns = (i / 10) * 1'000'000,
            .value = 1e-3 * (100.0 + 1e-6 * static_cast<double>(i % 977))});
  std::vector<unsigned char> blob;
  for (auto _ : state) {
    cal::storage::chunk::encode(c, blob);
    if (state.range(0) == 1)
      benchmark::DoNotOptimize(cal::storage::chunk::checksum({.count = 16384}, blob));
    benchmark::DoNotOptimize(blob.data());
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * c.size()));
  state.counters["bytes/reading"] =
      static_cast<double>(blob.size()) / static_cast<double>(c.size());
}
BENCHMARK(BM_ChunkEncode)->Arg(0)->Arg(1);

}  // namespace

BENCHMARK_MAIN();
