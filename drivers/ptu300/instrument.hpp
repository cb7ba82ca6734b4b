#pragma once
// The Vaisala PTU300 instrument (codec: ptu300/codec.hpp).
#include <memory>
#include <optional>
#include <string>

#include "cal/drivers/instrument.hpp"
#include "ptu300/codec.hpp"

namespace cal::drivers {

// Stops any RUN output on connect, then polls with SEND every options.poll_period (a PTU300
// updates about once a second; 1 s is the usual period). Readings: air_pressure_pa,
// air_temperature_degc, air_humidity_pct, dew_point_degc.
namespace ptu300 {
// The readings of one output line (channel 0): P, T, RH and the dew point where it carries them.
template <class Emit>
void for_each_reading(const codec::Ptu300Frame& f, Emit&& emit) {
  const auto put = [&](const std::optional<double>& v, Quantity q) {
    if (v) emit(q, *v);
  };
  put(f.pressure_pa, Quantity::air_pressure_pa);
  put(f.temperature_degc, Quantity::air_temperature_degc);
  put(f.relative_humidity_pct, Quantity::air_humidity_pct);
  put(f.dew_point_degc, Quantity::dew_point_degc);
}

// A field the device printed as stars, of a quantity caldaq takes (P, T, RH, dew point): the
// sentence that says so, with the reason the user's guide gives (docs/drivers.md, "PTU300
// stars"); nullopt for a value, or for a field caldaq does not read (A3H is "*" for 3 hours).
std::optional<std::string> unavailable_text(const codec::Ptu300Field& field);
}  // namespace ptu300

std::unique_ptr<Instrument> make_ptu300(boost::asio::io_context& io,
                                        std::unique_ptr<transport::Transport> transport,
                                        InstrumentOptions options, codec::Ptu300Config config = {});

}  // namespace cal::drivers
