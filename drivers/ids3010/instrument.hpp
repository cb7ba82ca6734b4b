#pragma once
// The Attocube IDS3010 instrument (codec: ids3010/codec.hpp): a transport (real, or the replay
// transport) with the device's protocol steps on the common instrument life cycle.
#include <array>
#include <chrono>
#include <memory>

#include "cal/drivers/instrument.hpp"

namespace cal::drivers {

// Which API generation to speak (ids3010/codec.hpp): found out at connect, or forced.
enum class IdsApiChoice { automatic, ids, sen };

struct Ids3010Options {
  std::array<bool, 3> axes{true, false, false};  // interferometer axes to read
  bool start_measurement = true;  // send startMeasurement on connect (else only observe)
  bool read_environment = true;   // enable and poll the ECU (air temperature, pressure, ...)
  std::chrono::milliseconds environment_period{1000};
  IdsApiChoice api = IdsApiChoice::automatic;
};

// On connect: the API generation (automatic: getCurrentMode in com.attocube.sen; a JSON-RPC
// error, then com.attocube.ids; neither answering fails the connection, naming both), the
// ECU's interface enabled (com.attocube.ecu.enable: it reports nothing before) when it is
// read, then startMeasurement. Then polls getAxesDisplacement every options.poll_period (one
// request in flight at a time; the reading's time is the midpoint between request and answer).
// Readings: displacement_m per axis (raw: the IDS counts the vacuum wavelength), status
// signal_lost while the device reports a warning number; with the ECU, air readings on
// channel 0 (none for an answer with a non-zero error number: that value is no measurement). Every
// non-zero result[0] and every JSON-RPC error is reported as a DeviceMessage with the device's own
// number and its text (errorNumberToString), a warning for the displacement getters, an error
// otherwise; startMeasurement refused three times, or the ECU refusing to enable, ends the
// connection with that text instead of polling silently.
std::unique_ptr<Instrument> make_ids3010(boost::asio::io_context& io,
                                         std::unique_ptr<transport::Transport> transport,
                                         InstrumentOptions options, Ids3010Options ids = {});

}  // namespace cal::drivers
