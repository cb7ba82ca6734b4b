// LinuxCNC halsampler position feed (codec: halsampler/codec.hpp): it only listens.
#include "halsampler/instrument.hpp"

#include <fmt/format.h>

#include "position_feed_core.hpp"

namespace cal::drivers {
namespace {

class Halsampler final
    : public detail::PositionFeedCore<codec::HalsamplerCodec, codec::HalsamplerConfig> {
 public:
  using PositionFeedCore::PositionFeedCore;

 private:
  void on_connected() override { reset_codec(); }
  // Samples halsampler says it lost (an "overrun" line, or a jump of -t's numbers): a gap.
  void on_frame(const codec::PositionFrame& f) override {
    if (!f.overrun && f.lost_before == 0) return;
    const std::int64_t t = now_ns();
    report_gap({t, t,
                f.lost_before > 0 ? fmt::format("halsampler lost {} samples", f.lost_before)
                                  : std::string("halsampler overrun: samples lost")});
  }
};

}  // namespace

std::unique_ptr<Instrument> make_halsampler(boost::asio::io_context& io,
                                            std::unique_ptr<transport::Transport> transport,
                                            InstrumentOptions options,
                                            codec::HalsamplerConfig config) {
  return std::make_unique<Halsampler>(io, std::move(transport), std::move(options), config);
}

}  // namespace cal::drivers
