// LinuxCNC halsampler position feed (codec: halsampler/codec.hpp): it only listens.
#include "halsampler/instrument.hpp"

#include "position_feed_core.hpp"

namespace cal::drivers {
namespace {

class Halsampler final
    : public detail::PositionFeedCore<codec::HalsamplerCodec, codec::HalsamplerConfig> {
 public:
  using PositionFeedCore::PositionFeedCore;

 private:
  void on_connected() override { reset_codec(); }
};

}  // namespace

std::unique_ptr<Instrument> make_halsampler(boost::asio::io_context& io,
                                            std::unique_ptr<transport::Transport> transport,
                                            InstrumentOptions options,
                                            codec::HalsamplerConfig config) {
  return std::make_unique<Halsampler>(io, std::move(transport), std::move(options), config);
}

}  // namespace cal::drivers
