#pragma once
// The Attocube IDS3010 instrument (codec: ids3010/codec.hpp): a transport (real, or the replay
// transport) with the device's protocol steps on the common instrument life cycle.
#include <array>
#include <chrono>
#include <memory>

#include "cal/drivers/instrument.hpp"

namespace cal::drivers {

struct Ids3010Options {
  std::array<bool, 3> axes{true, false, false};  // interferometer axes to read
  bool start_measurement = true;  // send startMeasurement on connect (else only observe)
  bool read_environment = true;   // poll the ECU (air temperature, pressure, humidity, n)
  std::chrono::milliseconds environment_period{1000};
};

// Polls getAxesDisplacement every options.poll_period (one request in flight at a time; the
// reading's time is the midpoint between request and answer). Readings: displacement_m per
// axis (raw: the IDS counts the vacuum wavelength), status signal_lost while the device
// reports a non-zero error code; with the ECU, air readings on channel 0.
std::unique_ptr<Instrument> make_ids3010(boost::asio::io_context& io,
                                         std::unique_ptr<transport::Transport> transport,
                                         InstrumentOptions options, Ids3010Options ids = {});

}  // namespace cal::drivers
