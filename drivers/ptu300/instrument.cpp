// Vaisala PTU300 instrument (codec: ptu300/codec.hpp).
#include "ptu300/instrument.hpp"

#include <vector>

#include "instrument_core.hpp"

namespace cal::drivers {
namespace {

class Ptu300 final : public detail::InstrumentCore {
 public:
  Ptu300(boost::asio::io_context& io, std::unique_ptr<transport::Transport> t, InstrumentOptions o,
         codec::Ptu300Config config)
      : InstrumentCore(io, std::move(t), std::move(o)),
        config_(std::move(config)),
        codec_(config_) {}

  const codec::CodecStats& codec_stats() const override { return codec_.stats(); }

 private:
  void on_connected() override {
    codec_ = codec::Ptu300Codec(config_);
    send(codec::ptu300_stop());  // a unit left in RUN mode would interleave its own lines
    start_polling();
  }
  void on_poll() override {
    sent_ns_ = now_ns();
    send(codec::ptu300_send());
  }
  void on_bytes(std::span<const std::byte> bytes) override {
    decode(codec_, bytes, frames_);
    const std::int64_t t = now_ns();
    for (const auto& f : frames_)
      ptu300::for_each_reading(
          f, [&](Quantity q, double v) { emit({.time_ns = t, .quantity = q, .value = v}); });
  }

  codec::Ptu300Config config_;
  codec::Ptu300Codec codec_;
  std::vector<codec::Ptu300Frame> frames_;
  std::int64_t sent_ns_ = 0;
};

}  // namespace

std::unique_ptr<Instrument> make_ptu300(boost::asio::io_context& io,
                                        std::unique_ptr<transport::Transport> transport,
                                        InstrumentOptions options, codec::Ptu300Config config) {
  return std::make_unique<Ptu300>(io, std::move(transport), std::move(options), std::move(config));
}

}  // namespace cal::drivers
