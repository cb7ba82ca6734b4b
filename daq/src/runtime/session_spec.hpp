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
#include "cal/drivers/codec/line_gauge.hpp"
#include "cal/drivers/instrument.hpp"

namespace boost::asio {
class io_context;
}

namespace daq {

struct InstrumentSpec {
  std::uint16_t device = 0;
  std::string driver;     // ids3010 | ptu300 | gauge | temper | shdr | halsampler
  std::string role;       // laser | air | material | ballbar
  std::string transport;  // as described live, e.g. "tcp 127.0.0.1:9090"
  std::array<bool, 3> ids_axes{true, false, false};
  cal::drivers::codec::GaugeConfig gauge;
  std::string temper_family = "gold";  // temper: ds75 | gold | temperx
  // shdr | halsampler: the test axis (0 X, 1 Y, 2 Z), its SHDR key or halsampler column, and
  // the machine unit (mm | in).
  int feed_axis = 0;
  std::string feed_key = "Xact";
  int feed_column = 0;
  std::string feed_unit = "mm";
};

std::unique_ptr<cal::drivers::Instrument> make_instrument(
    boost::asio::io_context& io, const InstrumentSpec& spec,
    std::unique_ptr<cal::drivers::transport::Transport> transport,
    cal::drivers::InstrumentOptions options);

nlohmann::json to_json(const InstrumentSpec& s);
InstrumentSpec instrument_spec_from_json(const nlohmann::json& j);
nlohmann::json to_json(const cal::daq::Config& c);
cal::daq::Config config_from_json(const nlohmann::json& j);

// The capture header of a session: {"format": "caldaq.capture-header.v1", "software",
// "started_utc", "config", "instruments"}.
std::string capture_header(const cal::daq::Config& c, const std::vector<InstrumentSpec>& specs,
                           const std::string& software);

}  // namespace daq
