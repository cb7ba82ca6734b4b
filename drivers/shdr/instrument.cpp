// MTConnect SHDR adapter as a position feed (codec: shdr/codec.hpp).
#include "shdr/instrument.hpp"

#include "position_feed_core.hpp"

namespace cal::drivers {
namespace {

class Shdr final : public detail::PositionFeedCore<codec::ShdrCodec, codec::ShdrConfig> {
 public:
  using PositionFeedCore::PositionFeedCore;

 private:
  // The adapter is asked for heartbeats ("* PING" every poll period): it answers "* PONG",
  // and the silence watchdog notices an adapter that stops answering.
  void on_connected() override {
    reset_codec();
    on_poll();
    start_polling();
  }
  void on_poll() override { send(codec::ShdrCodec::ping()); }
};

}  // namespace

std::unique_ptr<Instrument> make_shdr(boost::asio::io_context& io,
                                      std::unique_ptr<transport::Transport> transport,
                                      InstrumentOptions options, codec::ShdrConfig config) {
  return std::make_unique<Shdr>(io, std::move(transport), std::move(options), std::move(config));
}

}  // namespace cal::drivers
