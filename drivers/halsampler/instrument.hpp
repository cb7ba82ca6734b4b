#pragma once
// A LinuxCNC halsampler position feed (codec: halsampler/codec.hpp).
#include <memory>

#include "cal/drivers/instrument.hpp"
#include "halsampler/codec.hpp"

namespace cal::drivers {

// Readings: machine_position_m, channel = axis (0 X, 1 Y, 2 Z), timed on arrival.
std::unique_ptr<Instrument> make_halsampler(boost::asio::io_context& io,
                                            std::unique_ptr<transport::Transport> transport,
                                            InstrumentOptions options,
                                            codec::HalsamplerConfig config = {});

}  // namespace cal::drivers
