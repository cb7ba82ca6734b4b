// Machine position feeds (codecs: codec/position_feed.hpp): halsampler lines or an MTConnect
// SHDR adapter. Each fed axis becomes a machine_position_m reading on its channel.
#include "cal/drivers/codec/position_feed.hpp"
#include "cal/drivers/instruments.hpp"
#include "instrument_core.hpp"

namespace cal::drivers {
namespace {

template <class Codec>
class PositionFeed final : public detail::InstrumentCore {
 public:
  PositionFeed(boost::asio::io_context& io, std::unique_ptr<transport::Transport> t,
               InstrumentOptions o, std::function<Codec()> make, bool heartbeat)
      : InstrumentCore(io, std::move(t), std::move(o)),
        make_(std::move(make)),
        codec_(make_()),
        heartbeat_(heartbeat) {}
  const codec::CodecStats& codec_stats() const override { return codec_.stats(); }

 private:
  // An SHDR adapter is asked for heartbeats ("* PING" every poll period): it answers
  // "* PONG", and the silence watchdog notices an adapter that stops answering.
  void on_connected() override {
    codec_ = make_();
    if (heartbeat_) {
      on_poll();
      start_polling();
    }
  }
  void on_poll() override { send(codec::ShdrCodec::ping()); }
  void on_bytes(std::span<const std::byte> bytes) override {
    frames_.clear();
    errors_.clear();
    codec_.feed(bytes, frames_, errors_);
    report_codec_errors(errors_);
    const std::int64_t t = now_ns();
    for (const auto& f : frames_)
      for (std::uint8_t axis = 0; axis < 3; ++axis)
        if (f.position_m[axis])
          emit({.time_ns = t,
                .channel = axis,
                .quantity = Quantity::machine_position_m,
                .value = *f.position_m[axis]});
  }

  std::function<Codec()> make_;
  Codec codec_;
  bool heartbeat_;
  std::vector<codec::PositionFrame> frames_;
  std::vector<codec::CodecError> errors_;
};

}  // namespace

std::unique_ptr<Instrument> make_position_feed(boost::asio::io_context& io,
                                               std::unique_ptr<transport::Transport> transport,
                                               InstrumentOptions options,
                                               PositionFeedOptions feed) {
  if (feed.kind == PositionFeedKind::shdr)
    return std::make_unique<PositionFeed<codec::ShdrCodec>>(
        io, std::move(transport), std::move(options),
        [c = feed.shdr] { return codec::ShdrCodec(c); }, true);
  return std::make_unique<PositionFeed<codec::HalsamplerCodec>>(
      io, std::move(transport), std::move(options),
      [c = feed.halsampler] { return codec::HalsamplerCodec(c); }, false);
}

}  // namespace cal::drivers
