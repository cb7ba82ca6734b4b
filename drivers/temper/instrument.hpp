#pragma once
// A PCsensor TEMPer on a HID transport (codec: temper/codec.hpp).
#include <memory>

#include "cal/drivers/instrument.hpp"
#include "temper/codec.hpp"

namespace cal::drivers {

struct TemperOptions {
  codec::TemperFamily family = codec::TemperFamily::gold;
  // What the thermometer measures: the machine structure (material) or the air.
  Quantity quantity = Quantity::material_temperature_degc;
};

// Sends the init report once, then polls with the read report every options.poll_period.
// Readings: `quantity` per sensor (channel 0 inner, 1 the probe), and air_humidity_pct for
// TEMPerX/HUM models.
std::unique_ptr<Instrument> make_temper(boost::asio::io_context& io,
                                        std::unique_ptr<transport::Transport> transport,
                                        InstrumentOptions options, TemperOptions temper = {});

}  // namespace cal::drivers
