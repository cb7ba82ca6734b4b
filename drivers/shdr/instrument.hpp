#pragma once
// An MTConnect SHDR adapter as a position feed (codec: shdr/codec.hpp).
#include <memory>

#include "cal/drivers/instrument.hpp"
#include "shdr/codec.hpp"

namespace cal::drivers {

// Sends "* PING" every options.poll_period and reads the adapter's lines. Readings:
// machine_position_m, channel = axis (0 X, 1 Y, 2 Z), timed on arrival.
std::unique_ptr<Instrument> make_shdr(boost::asio::io_context& io,
                                      std::unique_ptr<transport::Transport> transport,
                                      InstrumentOptions options, codec::ShdrConfig config = {});

}  // namespace cal::drivers
