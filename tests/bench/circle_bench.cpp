// Ballbar diagnostics fit of 2 x 36,000 samples: two 360 degree traces at 1 kHz, 36 s each
// (R = 100 mm at 1047 mm/min), with the cyclic-error period given, and with it searched
// (61 trial periods); and the peak resident memory of the analysis of longer runs.
// BENCHMARK_MAIN is in analysis_bench.cpp.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "cal/analysis/circle.hpp"
#include "cal/analysis/circle_records.hpp"
#include "cal/analysis/circle_search.hpp"
#include "cal/analysis/sin_cos.hpp"

namespace {

using namespace cal::circle;

// Two traces of n samples each over 360 degrees: an ellipse, a squareness and noise.
std::vector<Trace> traces(int n = 36'000) {
  std::mt19937_64 rng(1);
  std::normal_distribution<double> noise(0.0, 0.2);
  std::vector<Trace> out;
  for (auto d : {Direction::ccw, Direction::cw}) {
    Trace t{d, {}, {}};
    t.angle_deg.reserve(static_cast<std::size_t>(n));
    t.deviation_um.reserve(static_cast<std::size_t>(n));
    const double s = d == Direction::ccw ? 1.0 : -1.0;
    for (int i = 0; i < n; ++i) {
      const double a = s * i * 360.0 / n;  // degrees
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

// The same search with a pass over every sample for each of its refinement's trials, as before
// the one-pass series (issue 32): the results agree (OnePassPeriodSearchEqualsThePassPerTrial...).
void BM_BallbarDiagnosticsPeriodSearchPassPerTrial_2x36000(benchmark::State& state) {
  const auto t = traces();
  const Setup setup{.radius_mm = 100, .feed_mm_per_min = 1047};
  for (auto _ : state)
    benchmark::DoNotOptimize(
        analyse(setup, t, fit_records_held_max_samples, PeriodRefinement::pass_per_trial));
  state.SetItemsProcessed(state.iterations() * 72'000);
}
BENCHMARK(BM_BallbarDiagnosticsPeriodSearchPassPerTrial_2x36000)->Unit(benchmark::kMillisecond);

// The two above with the fit's records rebuilt on every pass, as for a run of more than
// fit_records_held_max_samples samples: what the bounded memory costs.
void BM_BallbarDiagnosticsRebuilt_2x36000(benchmark::State& state) {
  const auto t = traces();
  const Setup setup{.radius_mm = 100, .feed_mm_per_min = 1047, .cyclic_period_mm = 10.0};
  for (auto _ : state) benchmark::DoNotOptimize(analyse(setup, t, 0));
  state.SetItemsProcessed(state.iterations() * 72'000);
}
BENCHMARK(BM_BallbarDiagnosticsRebuilt_2x36000)->Unit(benchmark::kMillisecond);

void BM_BallbarDiagnosticsPeriodSearchRebuilt_2x36000(benchmark::State& state) {
  const auto t = traces();
  const Setup setup{.radius_mm = 100, .feed_mm_per_min = 1047};
  for (auto _ : state) benchmark::DoNotOptimize(analyse(setup, t, 0));
  state.SetItemsProcessed(state.iterations() * 72'000);
}
BENCHMARK(BM_BallbarDiagnosticsPeriodSearchRebuilt_2x36000)->Unit(benchmark::kMillisecond);

// A run in which the vibration diagnostic finds a vibration: the traces above (at n samples
// over 360 degrees in 36 s, R = 100 mm at 1047 mm/min: 1 kHz for n = 36,000, 10 kHz for
// 360,000, whose spectrum is then averaged over Welch segments and the lines fitted in two
// pieces a trace) with 1 um (peak) at 123.4 Hz along X added: the bar reads
// 1 um sin(2 pi 123.4 t) cos(theta), rms 0.5 um in the lines 123.4 -+ f0 (docs/circle.md). The
// time is the angle's: t = |theta| / w, as the analysis reads it. Issue 32's other cases have no
// vibration, so they never paid for its line fit (docs/benchmarks.md, eleventh pass).
constexpr double vibration_hz = 123.4, vibration_um = 1.0;
std::vector<Trace> vibrating_traces(int n) {
  auto out = traces(n);
  const double w = 1047.0 / 60.0 / 100.0;  // rad/s
  for (auto& t : out)
    for (std::size_t i = 0; i < t.angle_deg.size(); ++i) {
      const double th = t.angle_deg[i] * std::numbers::pi / 180, t_s = std::abs(th) / w;
      t.deviation_um[i] +=
          vibration_um * std::sin(2 * std::numbers::pi * vibration_hz * t_s) * std::cos(th);
    }
  return out;
}

void vibration_case(benchmark::State& state, int n) {
  const auto t = vibrating_traces(n);
  const Setup setup{.radius_mm = 100, .feed_mm_per_min = 1047, .cyclic_period_mm = 10.0};
  double found_hz = 0, found_um = 0;
  for (auto _ : state) {
    const auto r = analyse(setup, t);
    for (const auto& d : r.diagnostics)
      if (d.key == "vibration") found_hz = d.frequency_hz.value_or(0), found_um = d.value;
    benchmark::DoNotOptimize(r);
  }
  // What it found, beside the injection (123.4 Hz, 0.5 um rms): the case measures the search
  // it means to.
  state.counters["vibration_hz"] = found_hz;
  state.counters["vibration_um"] = found_um;
  state.SetItemsProcessed(state.iterations() * 2 * n);
}
void BM_BallbarDiagnosticsVibration_2x36000(benchmark::State& state) {
  vibration_case(state, 36'000);
}
BENCHMARK(BM_BallbarDiagnosticsVibration_2x36000)->Unit(benchmark::kMillisecond);
void BM_BallbarDiagnosticsVibration_2x360000(benchmark::State& state) {
  vibration_case(state, 360'000);
}
BENCHMARK(BM_BallbarDiagnosticsVibration_2x360000)->Unit(benchmark::kMillisecond);
// The same 10 kHz traces without the vibration: what the search adds.
void BM_BallbarDiagnostics_2x360000(benchmark::State& state) {
  const auto t = traces(360'000);
  const Setup setup{.radius_mm = 100, .feed_mm_per_min = 1047, .cyclic_period_mm = 10.0};
  for (auto _ : state) benchmark::DoNotOptimize(analyse(setup, t));
  state.SetItemsProcessed(state.iterations() * 720'000);
}
BENCHMARK(BM_BallbarDiagnostics_2x360000)->Unit(benchmark::kMillisecond);

// The floor of any fit of this model: one pass over the samples, each angle's cos and sin
// and the deviation summed against them (the least a fit must do with every sample once).
void BM_BallbarOnePassFloor_2x36000(benchmark::State& state) {
  const auto t = traces();
  for (auto _ : state) {
    double sy = 0, syc = 0, sys = 0;
    for (const auto& tr : t)
      for (std::size_t i = 0; i < tr.angle_deg.size(); ++i) {
        const double a = tr.angle_deg[i] * std::numbers::pi / 180, y = tr.deviation_um[i];
        sy += y, syc += y * std::cos(a), sys += y * std::sin(a);
      }
    benchmark::DoNotOptimize(sy + syc + sys);
  }
  state.SetItemsProcessed(state.iterations() * 72'000);
}
BENCHMARK(BM_BallbarOnePassFloor_2x36000)->Unit(benchmark::kMillisecond);

// A field of /proc/self/status in kB ("VmRSS", "VmHWM"); -1 when absent.
long status_kb(const std::string& key) {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind(key + ":", 0) == 0) return std::stol(line.substr(key.size() + 1));
  return -1;
}

// Peak resident memory of one analysis of 2 x n samples (R = 100 mm, period given, 10 kHz:
// the feed makes each trace last n / 10,000 s). The peak (VmHWM) is reset to the current RSS
// (clear_refs 5) once the traces are made, so peak_MB is the process' whole footprint during
// the analysis and analysis_B_per_sample what the analysis adds per sample beyond its input
// (the traces, 16 bytes per sample). The fit's records are held as analyse(setup, traces)
// holds them (for 2 n above fit_records_held_max_samples: rebuilt on every pass).
void peak_rss(benchmark::State& state, std::size_t records_held_max_samples) {
  const int n = static_cast<int>(state.range(0));
  const auto t = traces(n);
  const double duration_s = n / 10'000.0;
  const Setup setup{.radius_mm = 100,
                    .feed_mm_per_min = 2 * std::numbers::pi * 100 / duration_s * 60,
                    .cyclic_period_mm = 10.0};
  long before_kb = 0, peak_kb = 0;
  for (auto _ : state) {
    std::ofstream("/proc/self/clear_refs") << "5";
    before_kb = status_kb("VmRSS");
    benchmark::DoNotOptimize(analyse(setup, t, records_held_max_samples));
    peak_kb = status_kb("VmHWM");
  }
  state.counters["peak_MB"] = static_cast<double>(peak_kb) / 1024.0;
  state.counters["analysis_B_per_sample"] =
      static_cast<double>(peak_kb - before_kb) * 1024.0 / (2.0 * n);
  state.SetItemsProcessed(state.iterations() * 2 * n);
}
void BM_BallbarPeakRss(benchmark::State& state) { peak_rss(state, fit_records_held_max_samples); }
BENCHMARK(BM_BallbarPeakRss)
    ->Arg(36'000)
    ->Arg(360'000)
    ->Iterations(1)
    ->Unit(benchmark::kMillisecond);
// The same with every record held, as before issue 32's rebuilt records (the same results).
void BM_BallbarPeakRssHeld(benchmark::State& state) { peak_rss(state, SIZE_MAX); }
BENCHMARK(BM_BallbarPeakRssHeld)->Arg(360'000)->Iterations(1)->Unit(benchmark::kMillisecond);
// Six minutes of a 10 kHz circle (2 x 1.8 M samples): not in the suite's smoke run.
void BM_BallbarPeakRssLong(benchmark::State& state) { BM_BallbarPeakRss(state); }
BENCHMARK(BM_BallbarPeakRssLong)->Arg(1'800'000)->Iterations(1)->Unit(benchmark::kMillisecond);

// cal::sin_cos on 4096 phases |x| < 2000 (the fit's k c), independent calls; the peer in the
// same run, BM_SinCosGlibc, is glibc's sincos on the same arguments.
std::vector<double> phases() {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-2000.0, 2000.0);
  std::vector<double> xs(4096);
  for (auto& x : xs) x = u(rng);
  return xs;
}

void BM_SinCos(benchmark::State& state) {
  const auto xs = phases();
  for (auto _ : state)
    for (const double x : xs) benchmark::DoNotOptimize(cal::sin_cos(x));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * xs.size()));
}
BENCHMARK(BM_SinCos);

void BM_SinCosGlibc(benchmark::State& state) {
  const auto xs = phases();
  for (auto _ : state)
    for (const double x : xs) {
      cal::SinCos r{};
      ::sincos(x, &r.s, &r.c);
      benchmark::DoNotOptimize(r);
    }
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * xs.size()));
}
BENCHMARK(BM_SinCosGlibc);

}  // namespace
