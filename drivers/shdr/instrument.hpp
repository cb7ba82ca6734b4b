#pragma once
// An MTConnect SHDR adapter as a position feed (codec: shdr/codec.hpp).
#include <chrono>
#include <memory>
#include <optional>

#include "cal/drivers/instrument.hpp"
#include "shdr/codec.hpp"

namespace cal::drivers {

// The heartbeat, as the MTConnect agent does it (cppagent connector.cpp): "* PING" once after
// connecting; when the adapter answers "* PONG <ms>", a PING every <ms> and silence longer than
// 2 x <ms> is a lost connection. Without a PONG the feed is never timed out for silence
// (adapters send only on change: a machine dwelling at a target is silent) unless
// legacy_timeout is set (the agent's LegacyTimeout, 600 s by default there).
struct ShdrHeartbeat {
  std::chrono::milliseconds override_period{0};  // > 0: ping this often instead of <ms>
  std::optional<std::chrono::milliseconds> legacy_timeout;
};

// Readings: machine_position_m, channel = axis (0 X, 1 Y, 2 Z), timed on arrival.
// InstrumentOptions::poll_period and silence_timeout are not used: the adapter's PONG sets both.
std::unique_ptr<Instrument> make_shdr(boost::asio::io_context& io,
                                      std::unique_ptr<transport::Transport> transport,
                                      InstrumentOptions options, codec::ShdrConfig config = {},
                                      ShdrHeartbeat heartbeat = {});

}  // namespace cal::drivers
