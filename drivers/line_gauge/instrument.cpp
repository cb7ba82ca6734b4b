// Line gauges and serial thermometers (codec: line_gauge/codec.hpp).
#include "line_gauge/instrument.hpp"

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

 private:
  void on_connected() override {
    codec_ = codec::GaugeCodec(config_);
    if (!config_.request.empty()) start_polling();
  }
  void on_poll() override { send(config_.request); }
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
          readings_.push_back({.time_ns = t, .quantity = quantity_, .value = value_si});
        },
        errors_);
    emit_all(readings_);
    report_codec_errors(errors_);
  }

  codec::GaugeConfig config_;
  codec::GaugeCodec codec_;
  Quantity quantity_;
  std::vector<codec::CodecError> errors_;
  std::vector<Reading> readings_;  // one chunk's, reused
};

}  // namespace

std::unique_ptr<Instrument> make_gauge(boost::asio::io_context& io,
                                       std::unique_ptr<transport::Transport> transport,
                                       InstrumentOptions options, codec::GaugeConfig config) {
  return std::make_unique<Gauge>(io, std::move(transport), std::move(options), std::move(config));
}

}  // namespace cal::drivers
