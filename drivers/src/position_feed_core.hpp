#pragma once
// Private to drivers/: what the machine position feeds (halsampler, shdr) share: each fed axis
// becomes a machine_position_m reading on its channel (0 X, 1 Y, 2 Z), timed on arrival; an
// axis the feed says it has no value for, a signal_lost reading of NaN.
#include <limits>
#include <vector>

#include "cal/drivers/codec/position.hpp"
#include "instrument_core.hpp"

namespace cal::drivers::detail {

template <class Codec, class Config>
class PositionFeedCore : public InstrumentCore {
 public:
  PositionFeedCore(boost::asio::io_context& io, std::unique_ptr<transport::Transport> t,
                   InstrumentOptions o, Config config)
      : InstrumentCore(io, std::move(t), std::move(o)),
        config_(std::move(config)),
        codec_(config_) {}
  const codec::CodecStats& codec_stats() const override { return codec_.stats(); }

 protected:
  void reset_codec() { codec_ = Codec(config_); }
  // Called for every frame before its readings are emitted.
  virtual void on_frame(const codec::PositionFrame& /*frame*/) {}
  Codec& codec() { return codec_; }

  void on_bytes(std::span<const std::byte> bytes) override {
    decode(codec_, bytes, frames_);
    const std::int64_t t = now_ns();
    for (const auto& f : frames_) {
      on_frame(f);
      for (std::uint8_t axis = 0; axis < 3; ++axis) {
        if (f.position_m[axis])
          emit({.time_ns = t,
                .channel = axis,
                .quantity = Quantity::machine_position_m,
                .value = *f.position_m[axis]});
        // An axis the adapter calls UNAVAILABLE: no position (NaN, signal_lost), so a feed that
        // holds its last value (the position trigger's feed_holds) does not hold it on.
        if (f.unavailable[axis])
          emit({.time_ns = t,
                .channel = axis,
                .quantity = Quantity::machine_position_m,
                .status = ReadingStatus::signal_lost,
                .value = std::numeric_limits<double>::quiet_NaN()});
      }
    }
  }

 private:
  Config config_;
  Codec codec_;
  std::vector<codec::PositionFrame> frames_;
};

}  // namespace cal::drivers::detail
