// MTConnect SHDR adapter as a position feed (codec: shdr/codec.hpp; heartbeat: instrument.hpp).
#include "shdr/instrument.hpp"

#include <fmt/format.h>

#include "position_feed_core.hpp"

namespace cal::drivers {
namespace {

class Shdr final : public detail::PositionFeedCore<codec::ShdrCodec, codec::ShdrConfig> {
 public:
  Shdr(boost::asio::io_context& io, std::unique_ptr<transport::Transport> t, InstrumentOptions o,
       codec::ShdrConfig config, ShdrHeartbeat heartbeat)
      : PositionFeedCore(io, std::move(t), std::move(o), std::move(config)),
        heartbeat_(heartbeat) {}

 private:
  void on_connected() override {
    reset_codec();
    beating_ = false;
    set_silence_timeout(heartbeat_.legacy_timeout);
    send(codec::ShdrCodec::ping());  // the agent pings once right after connecting
  }
  void on_poll() override {
    if (std::exchange(skip_poll_, false)) return;  // the first period starts at the PONG
    send(codec::ShdrCodec::ping());
  }
  void on_bytes(std::span<const std::byte> bytes) override {
    PositionFeedCore::on_bytes(bytes);
    const auto pong = codec().pong_timeout_ms();
    if (beating_ || !pong) return;
    // "* PONG <ms>": ping every <ms> (or the configured period), and silence beyond twice
    // that period is a lost connection.
    beating_ = true;
    const auto period = heartbeat_.override_period.count() > 0 ? heartbeat_.override_period
                                                               : std::chrono::milliseconds(*pong);
    set_poll_period(period);
    set_silence_timeout(2 * period);
    report_message({.severity = DeviceMessage::Severity::info,
                    .text = fmt::format("adapter answered * PONG {}: heartbeat every {} ms", *pong,
                                        period.count())});
    skip_poll_ = true;
    start_polling();
  }

  ShdrHeartbeat heartbeat_;
  bool beating_ = false;
  bool skip_poll_ = false;
};

}  // namespace

std::unique_ptr<Instrument> make_shdr(boost::asio::io_context& io,
                                      std::unique_ptr<transport::Transport> transport,
                                      InstrumentOptions options, codec::ShdrConfig config,
                                      ShdrHeartbeat heartbeat) {
  return std::make_unique<Shdr>(io, std::move(transport), std::move(options), std::move(config),
                                heartbeat);
}

}  // namespace cal::drivers
