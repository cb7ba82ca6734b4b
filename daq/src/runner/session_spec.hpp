#pragma once
// What a session needs to be rebuilt from its capture: the configuration and the instruments
// (driver, transport, codec settings), as JSON in the capture header. The same factory makes
// the instruments live and in replay, so a replay runs exactly the recorded instrument code.
#include <array>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "cal/daq/config.hpp"
#include "cal/drivers/instrument.hpp"
#include "cal/drivers/registry.hpp"

namespace boost::asio {
class io_context;
}

namespace daq {

struct InstrumentSpec {
  std::uint16_t device = 0;
  std::string driver;             // a registered driver (cal::drivers::device_drivers())
  std::string role;               // laser | air | material | ballbar | position
  std::string transport;          // as configured, e.g. "tcp 127.0.0.1:9090"
  cal::drivers::Options options;  // the driver's options, every one with its value
  int test_axis = 0;              // the axis under test (0 X, 1 Y, 2 Z)
  std::string serial_number, certificate, calibration_due;  // the instrument's records
  std::string origin = "real";  // or "simulated" (DeviceConfig::origin)
  cal::drivers::InstrumentContext context() const { return {role, test_axis}; }
};

std::unique_ptr<cal::drivers::Instrument> make_instrument(
    boost::asio::io_context& io, const InstrumentSpec& spec,
    std::unique_ptr<cal::drivers::transport::Transport> transport,
    cal::drivers::InstrumentOptions options);

nlohmann::json to_json(const InstrumentSpec& s);
// Reads today's entries ({"options": {...}}) and those of captures recorded before the option
// tables (each driver's legacy keys); throws cal::InputError naming the instrument and what is
// wrong (an unknown driver or option, a value its table refuses).
InstrumentSpec instrument_spec_from_json(const nlohmann::json& j);
nlohmann::json to_json(const cal::daq::Config& c);
// The measure keys of a linear test as JSON (stored in a run's settings and a capture header).
nlohmann::json measure_json(const cal::daq::MeasureConfig& m);
cal::daq::MeasureConfig measure_from_json(const nlohmann::json& j);
cal::daq::Config config_from_json(const nlohmann::json& j);

// The capture header of a session: {"format": "caldaq.capture-header.v1", "software",
// "started_utc", "config", "instruments"}.
std::string capture_header(const cal::daq::Config& c, const std::vector<InstrumentSpec>& specs,
                           const std::string& software);

}  // namespace daq
