// Codec throughput: bytes/s (SetBytesProcessed) and frames/s (items_per_second) of each codec
// on a realistic stream, fed in 4 KiB chunks as a transport delivers them. Numbers are read by
// hand (docs/benchmarks.md); the suite only smoke-runs this.
#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include <span>
#include <string>
#include <utility>
#include <vector>

#include "halsampler/codec.hpp"
#include "ids3010/codec.hpp"
#include "line_gauge/codec.hpp"
#include "ptu300/codec.hpp"
#include "shdr/codec.hpp"
#include "temper/codec.hpp"

namespace {

using namespace cal::drivers::codec;
constexpr int kFrames = 10'000;

template <class Codec>
void feed_chunks(Codec& codec, const std::string& stream, std::vector<typename Codec::Frame>& out,
                 std::vector<CodecError>& errors) {
  for (std::size_t i = 0; i < stream.size(); i += 4096)
    codec.feed(std::string_view(stream).substr(i, 4096), out, errors);
}

template <class MakeCodec>
void run(benchmark::State& state, const std::string& stream, MakeCodec make,
         std::size_t frames_expected) {
  for (auto _ : state) {
    state.PauseTiming();
    auto codec = make();
    std::vector<typename decltype(codec)::Frame> frames;
    std::vector<CodecError> errors;
    frames.reserve(frames_expected);
    state.ResumeTiming();
    feed_chunks(codec, stream, frames, errors);
    if (frames.size() != frames_expected) state.SkipWithError("frames lost");
    benchmark::DoNotOptimize(frames.data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * stream.size()));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * frames_expected));
}

// getAxesDisplacement as the instrument runs it: one request encoded (its id remembered), then
// its answer as the IDS3010 sends it (picometres) decoded; one request in flight at a time.
void BM_Ids3010(benchmark::State& state) {
  std::vector<std::string> answers;
  std::size_t bytes = 0;
  for (int i = 1; i <= kFrames; ++i) {
    answers.push_back(fmt::format(R"({{"jsonrpc":"2.0","result":[0,{},{},0],"id":{}}})"
                                  "\n",
                                  123456789012 + i * 37, -4567890 + i, i));
    bytes += answers.back().size();
  }
  for (auto _ : state) {
    IdsCodec codec;
    std::vector<IdsResponse> frames;
    std::vector<CodecError> errors;
    frames.reserve(kFrames);
    for (const auto& a : answers) {
      benchmark::DoNotOptimize(codec.encode(IdsMethod::get_axes_displacement));
      codec.feed(a, frames, errors);
    }
    if (frames.size() != kFrames) state.SkipWithError("frames lost");
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * bytes));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kFrames));
}

// Replay of a recorded IDS3010 session: each request line as the instrument sent it
// (note_requests learns its id from the bytes), then the device's answer (feed). This is the
// codec's share of `daq replay` of an IDS3010 capture (docs/benchmarks.md, IDS3010 replay).
struct RecordedSession {
  std::vector<std::string> requests;  // one line each, as the instrument sent it
  std::vector<std::string> answers;   // one line each, as the device answered
  std::size_t bytes = 0;              // of both directions
};

RecordedSession recorded_session() {
  IdsCodec live;
  live.set_api(IdsApi::sen);  // firmware 1.9.1 and later
  RecordedSession s;
  for (int i = 1; i <= kFrames; ++i) {
    s.requests.push_back(live.encode(IdsMethod::get_axes_displacement));
    s.answers.push_back(fmt::format(R"({{"jsonrpc":"2.0","result":[0,{},{},0],"id":{}}})"
                                    "\n",
                                    123456789012 + i * 37, -4567890 + i, i));
    s.bytes += s.requests.back().size() + s.answers.back().size();
  }
  return s;
}

void BM_Ids3010Replay(benchmark::State& state) {
  const auto [requests, answers, bytes] = recorded_session();
  for (auto _ : state) {
    IdsCodec codec;
    std::vector<IdsResponse> frames;
    std::vector<CodecError> errors;
    frames.reserve(kFrames);
    for (std::size_t i = 0; i < answers.size(); ++i) {
      codec.note_requests(std::as_bytes(std::span(requests[i])));
      codec.feed(answers[i], frames, errors);
    }
    if (frames.size() != kFrames || !errors.empty()) state.SkipWithError("frames lost");
    benchmark::DoNotOptimize(frames.data());
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * bytes));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kFrames));
}

// The floor under BM_Ids3010Replay: the same bytes in the same pieces through the line
// splitter alone (one memchr pass, no decoding). No decoder of these lines can beat it.
void BM_Ids3010ReplayFloor(benchmark::State& state) {
  const auto [requests, answers, bytes] = recorded_session();
  for (auto _ : state) {
    LineSplitter sent, received;
    std::size_t lines = 0;
    auto count = [&](std::string_view line, std::uint64_t) { lines += line.size() > 2; };
    for (std::size_t i = 0; i < answers.size(); ++i) {
      sent.feed(std::as_bytes(std::span(requests[i])), count, [](std::uint64_t) {});
      received.feed(std::as_bytes(std::span(answers[i])), count, [](std::uint64_t) {});
    }
    if (lines != 2 * kFrames) state.SkipWithError("lines lost");
    benchmark::DoNotOptimize(lines);
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * bytes));
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * kFrames));
}

void BM_Ptu300(benchmark::State& state) {
  std::string stream;
  for (int i = 0; i < kFrames; ++i)
    stream += fmt::format("P= {:.1f} hPa T= {:.1f} 'C RH= {:.1f} %RH\r\n", 1013.2 + 0.1 * (i % 7),
                          21.3 + 0.1 * (i % 5), 41.0 + 0.1 * (i % 3));
  run(
      state, stream, [] { return Ptu300Codec{}; }, kFrames);
}

void BM_LineGauge(benchmark::State& state) {
  std::string stream;
  for (int i = 0; i < kFrames; ++i) stream += fmt::format("{:+09.4f}\r\n", 0.0123 * (i % 100));
  run(
      state, stream, [] { return GaugeCodec{}; }, kFrames);
}

void BM_Temper(benchmark::State& state) {
  std::string stream;
  for (int i = 0; i < kFrames; ++i) {
    const int v = 2300 + i % 50;  // 23.00 .. 23.49 degC
    stream += std::string{
        '\x80', '\x80', static_cast<char>(v >> 8), static_cast<char>(v & 0xff), 0, 0, 0, 0};
  }
  run(
      state, stream, [] { return TemperCodec{}; }, kFrames);
}

void BM_Halsampler(benchmark::State& state) {
  std::string stream;
  for (int i = 0; i < kFrames; ++i)
    stream += fmt::format("{} {:.6f} {:.6f} {:.6f}\n", i, 0.01 * i, -3.25, 100.0);
  run(
      state, stream, [] { return HalsamplerCodec({.sample_numbers = true}); }, kFrames);
}

void BM_Shdr(benchmark::State& state) {
  std::string stream;
  for (int i = 0; i < kFrames; ++i)
    stream += fmt::format("2026-11-23T12:00:{:02}.{:06}Z|Xact|{:.4f}|Yact|{:.4f}|Zact|0.0000\n",
                          i / 1000 % 60, i % 1000 * 1000, 0.01 * i, -5.0);
  run(
      state, stream, [] { return ShdrCodec{}; }, kFrames);
}

BENCHMARK(BM_Ids3010)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Ids3010Replay)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Ids3010ReplayFloor)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Ptu300)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_LineGauge)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Temper)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Halsampler)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Shdr)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
