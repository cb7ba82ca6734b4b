// Line gauges and serial thermometers (codec: line_gauge/codec.hpp).
#include "line_gauge/instrument.hpp"

#include <algorithm>
#include <deque>
#include <vector>

#include "instrument_core.hpp"

namespace cal::drivers {
namespace {

class Gauge final : public detail::InstrumentCore {
 public:
  Gauge(boost::asio::io_context& io, std::unique_ptr<transport::Transport> t, InstrumentOptions o,
        codec::GaugeConfig config)
      : InstrumentCore(io, std::move(t), std::move(o)),
        config_(std::move(config)),
        codec_(config_) {
    quantity_ = config_.unit == codec::GaugeUnit::degc ? Quantity::material_temperature_degc
                : codec::is_angle(config_.unit)        ? Quantity::angle_rad
                                                       : Quantity::length_m;
  }
  const codec::CodecStats& codec_stats() const override { return codec_.stats(); }
  std::optional<AnswerLatency> answer_latency() const override {
    if (config_.request.empty()) return std::nullopt;
    AnswerLatency a{.answers = answers_, .unmatched = unmatched_};
    if (latencies_.empty()) return a;
    std::vector<std::int64_t> sorted(latencies_.begin(), latencies_.end());
    const auto mid = sorted.begin() + static_cast<std::ptrdiff_t>(sorted.size() / 2);
    std::nth_element(sorted.begin(), mid, sorted.end());
    a.median_ns = *mid;
    a.max_ns = max_latency_ns_;
    return a;
  }

 private:
  void on_connected() override {
    codec_ = codec::GaugeCodec(config_);
    requests_.clear();
    if (!config_.request.empty()) start_polling();
  }
  void on_disconnected() override { requests_.clear(); }
  void on_poll() override {
    send(config_.request);
    requested(last_sent_ns());
  }
  // Replay: the recorded requests, at their recorded times (the instrument sends nothing), so
  // a replay stamps the answers as the live session did.
  void on_sent(std::span<const std::byte>) override { requested(last_sent_ns()); }
  void requested(std::int64_t t) {
    requests_.push_back(t);
    if (requests_.size() > kMaxOutstanding) requests_.pop_front();  // never answered
  }
  // When a value was measured. A polled gauge measures between the request and the answer:
  // the reading carries the request's time (the earliest it can be, so a late answer is never
  // taken for a stop the machine reached after the request) and the answer's delay after it
  // (the latest it can be, so a late answer is never taken for a stop the machine had left by
  // then): docs/iso230-2.md, "Which samples make a stop's value". The answers come in the order
  // of the requests (one line each). A streaming gauge, or an answer with no request
  // outstanding: the arrival time.
  struct Measured {
    std::int64_t time_ns;
    std::uint16_t within_ms = 0;
  };
  Measured measured(std::int64_t arrival_ns) {
    if (config_.request.empty()) return {arrival_ns};
    if (requests_.empty()) {
      ++unmatched_;
      return {arrival_ns};
    }
    const std::int64_t t = requests_.front();
    requests_.pop_front();
    const std::int64_t latency = arrival_ns - t;
    ++answers_;
    max_latency_ns_ = std::max(max_latency_ns_, latency);
    latencies_.push_back(latency);
    if (latencies_.size() > AnswerLatency::kLatencyWindow) latencies_.pop_front();
    const std::int64_t ms = (std::max<std::int64_t>(latency, 0) + 999'999) / 1'000'000;
    return {t, static_cast<std::uint16_t>(std::min<std::int64_t>(ms, 65535))};
  }
  void on_bytes(std::span<const std::byte> bytes) override {
    errors_.clear();
    // A streaming gauge delivers several lines per read; they get the read's time. The
    // spacing within a chunk is unknown here (the pipeline assigns sample times from the
    // sample rate where it matters, e.g. the ballbar).
    const std::int64_t t = now_ns();
    // The chunk's readings go out together (one call for a batch consumer), then its errors,
    // as before.
    readings_.clear();
    codec_.feed_values(
        bytes,
        [&](double value_si, std::string_view) {
          const auto m = measured(t);
          readings_.push_back({.time_ns = m.time_ns,
                               .quantity = quantity_,
                               .measured_within_ms = m.within_ms,
                               .value = value_si});
        },
        errors_);
    // A line that gave no value answered a request too (its place among the chunk's lines is
    // not known here: counted after them).
    if (!config_.request.empty())
      for (std::size_t k = 0; k < errors_.size() && !requests_.empty(); ++k) requests_.pop_front();
    emit_all(readings_);
    report_codec_errors(errors_);
  }

  // More requests than this without an answer: the oldest were lost (at 10 Hz, 6 s).
  static constexpr std::size_t kMaxOutstanding = 64;

  codec::GaugeConfig config_;
  codec::GaugeCodec codec_;
  Quantity quantity_;
  std::vector<codec::CodecError> errors_;
  std::vector<Reading> readings_;       // one chunk's, reused
  std::deque<std::int64_t> requests_;   // the times of the requests not answered yet, oldest first
  std::deque<std::int64_t> latencies_;  // the last kLatencyWindow answers' latencies
  std::uint64_t answers_ = 0, unmatched_ = 0;
  std::int64_t max_latency_ns_ = 0;
};

}  // namespace

std::unique_ptr<Instrument> make_gauge(boost::asio::io_context& io,
                                       std::unique_ptr<transport::Transport> transport,
                                       InstrumentOptions options, codec::GaugeConfig config) {
  return std::make_unique<Gauge>(io, std::move(transport), std::move(options), std::move(config));
}

}  // namespace cal::drivers
