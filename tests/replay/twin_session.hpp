#pragma once
// The session of the checked-in captures in tests/data/captures (see its README.md): four
// real instruments against the SIMULATED twins, recorded by record_captures and replayed by
// checked_in_captures_test. Both build the instruments here, so the replay decodes the bytes
// with exactly the settings they were recorded with.
//
// Simulated truth (what every replayed reading is checked against):
//   air: 21.3 degC, 99 870 Pa, 42 %RH, CO2 450 umol/mol, no drift or noise (Ciddor);
//   machine: no geometric, servo-noise, backlash or thermal errors; parked at X = 250 mm for
//   1 s, then G1 X260 F600, then parked at X = 260 mm;
//   laser axis 1 along X with its datum at X = 0: it reads n_air * X;
//   ballbar from the tool to a table ball at (150, 0, 0) mm, zeroed at 100 mm: reads X - 250;
//   SHDR adapter: the commanded Xcom, Ycom = Zcom = 0.
//   Disturbances: beam blocked on axis 1 from 0.6 s to 0.8 s; the IDS connection dropped at
//   3.2 s (the instrument reconnects, the gap is recorded).
#include <array>
#include <memory>
#include <vector>

#include "ids3010/instrument.hpp"
#include "ids3010/twin.hpp"
#include "line_gauge/instrument.hpp"
#include "line_gauge/twin.hpp"
#include "ptu300/instrument.hpp"
#include "ptu300/twin.hpp"
#include "shdr/instrument.hpp"
#include "shdr/twin.hpp"

namespace twin_session {

namespace d = cal::drivers;
using namespace std::chrono_literals;

inline constexpr double air_temperature_degc = 21.3;
inline constexpr double air_pressure_pa = 99'870.0;
inline constexpr double air_humidity_pct = 42.0;
inline constexpr double start_x_mm = 250.0;
inline constexpr double end_x_mm = 260.0;
inline constexpr double pivot_x_mm = 150.0;
inline constexpr double bar_zero_mm = 100.0;
inline constexpr double session_s = 4.5;

enum Device : std::uint16_t { laser = 0, ptu300 = 1, ballbar = 2, position = 3 };

inline d::sim::AirConfig air() {
  return {.temperature_degc = {.start = air_temperature_degc},
          .pressure_pa = {.start = air_pressure_pa},
          .humidity_pct = {.start = air_humidity_pct}};
}

inline d::sim::MachineConfig machine() {
  d::sim::MachineConfig c;
  c.start_mm = {start_x_mm, 0, 0};
  return c;
}

inline std::vector<d::sim::Move> program() {
  return {d::sim::Move::dwell(1.0), d::sim::Move::linear({end_x_mm, 0, 0}, 600.0),
          d::sim::Move::dwell(10.0)};
}

inline d::InstrumentOptions options(Device device, const char* name) {
  return {.device = device,
          .name = name,
          .backoff = {.initial = 50ms, .max = 200ms},
          // The laser at 10 ms (the checked-in capture was recorded at 20 ms): since issue 13
          // a warning costs the IDS3010 a mode check and, once, its text, and a loaded machine
          // polls late, so 20 ms left as few as 2 readings in the 0.2 s of a blocked beam.
          .poll_period = device == laser    ? 10ms
                         : device == ptu300 ? 250ms
                                            : 1000ms};
}

inline d::Ids3010Options ids_options() { return {.environment_period = 500ms}; }
inline d::codec::GaugeConfig gauge_config() { return {}; }
inline d::codec::ShdrConfig feed_options() {
  return {.keys = {{"Xcom", 0}, {"Ycom", 1}, {"Zcom", 2}}};
}

// The four instruments on the given transports (real ones when recording, the replay bus's
// when replaying), with the clock and recorder of `base`.
template <class Transports>
std::array<std::unique_ptr<d::Instrument>, 4> instruments(boost::asio::io_context& io,
                                                          Transports&& transport,
                                                          const d::InstrumentOptions& base) {
  const auto with = [&](d::InstrumentOptions o) {
    o.clock = base.clock;
    o.recorder = base.recorder;
    o.replay = base.replay;
    return o;
  };
  return {
      d::make_ids3010(io, transport(laser), with(options(laser, "laser")), ids_options()),
      d::make_ptu300(io, transport(ptu300), with(options(ptu300, "PTU300"))),
      d::make_gauge(io, transport(ballbar), with(options(ballbar, "ballbar")), gauge_config()),
      d::make_shdr(io, transport(position), with(options(position, "position")), feed_options())};
}

}  // namespace twin_session
