#pragma once
// A line gauge or serial thermometer (codec: line_gauge/codec.hpp).
#include <memory>

#include "cal/drivers/instrument.hpp"
#include "line_gauge/codec.hpp"

namespace cal::drivers {

// Streaming, or polled with config.request every options.poll_period. Readings: length_m, or
// material_temperature_degc for a degC gauge (a serial thermometer on the machine structure),
// channel 0.
std::unique_ptr<Instrument> make_gauge(boost::asio::io_context& io,
                                       std::unique_ptr<transport::Transport> transport,
                                       InstrumentOptions options, codec::GaugeConfig config = {});

}  // namespace cal::drivers
