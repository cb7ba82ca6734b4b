#pragma once
// A PCsensor TEMPer on a HID transport (codec: temper/codec.hpp).
#include <chrono>
#include <memory>
#include <optional>
#include <vector>

#include "cal/drivers/instrument.hpp"
#include "temper/codec.hpp"

namespace cal::drivers {

struct TemperOptions {
  // The report family; nullopt: from the firmware string (codec::temper_models()), an unknown
  // firmware being refused with its string.
  std::optional<codec::TemperFamily> family = codec::TemperFamily::gold;
  // What the thermometer measures: the machine structure (material) or the air.
  Quantity quantity = Quantity::material_temperature_degc;
  // The channels read (0 the stick's sensor, 1 the probe); empty: every sensor of the model.
  // A channel the model does not have ends the connection with a message saying which it has.
  std::vector<std::uint8_t> channels;
  // Detection (no `family`): how often the firmware query is asked when its answer is not
  // whole, and the quiet time that ends an answer (ccwienk/temper: 10 tries, 0.2 s).
  int firmware_tries = 10;
  std::chrono::milliseconds firmware_quiet{200};
};

// Asks for the firmware string (01 86 ff 01) and, unless the family is given, detects the
// model from it (asking again, up to firmware_tries times, while the answer is not two
// reports: a TEMPer1F may send only the second half); then sends the init report once and polls
// with the read report every options.poll_period. Readings: `quantity` per sensor, each on its
// channel (0 inner, 1 the probe; two sensors are two series, never one), and air_humidity_pct
// (channel 0) for models with humidity. The firmware and the model found are reported as a
// DeviceMessage.
std::unique_ptr<Instrument> make_temper(boost::asio::io_context& io,
                                        std::unique_ptr<transport::Transport> transport,
                                        InstrumentOptions options, TemperOptions temper = {});

}  // namespace cal::drivers
