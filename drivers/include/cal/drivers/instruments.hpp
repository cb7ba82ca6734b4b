#pragma once
// The supported instruments: factories that combine a transport (real, or the replay
// transport) with the device's codec and protocol steps. The transport is passed in so that
// the same instrument code runs on hardware, on the simulated twins and on a replayed capture.
#include <array>
#include <chrono>
#include <memory>

#include "cal/drivers/codec/line_gauge.hpp"
#include "cal/drivers/codec/position_feed.hpp"
#include "cal/drivers/codec/temper.hpp"
#include "cal/drivers/codec/vaisala_ptu300.hpp"
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

// Vaisala PTU300: stops any RUN output on connect, then polls with SEND every
// options.poll_period (a PTU300 updates about once a second; 1 s is the usual period).
// Readings: air_pressure_pa, air_temperature_degc, air_humidity_pct, dew_point_degc.
std::unique_ptr<Instrument> make_ptu300(boost::asio::io_context& io,
                                        std::unique_ptr<transport::Transport> transport,
                                        InstrumentOptions options, codec::Ptu300Config config = {});

// A line gauge (codec/line_gauge.hpp): streaming, or polled with config.request every
// options.poll_period. Readings: length_m, or material_temperature_degc for a degC gauge
// (a serial thermometer on the machine structure), channel 0.
std::unique_ptr<Instrument> make_gauge(boost::asio::io_context& io,
                                       std::unique_ptr<transport::Transport> transport,
                                       InstrumentOptions options, codec::GaugeConfig config = {});

struct TemperOptions {
  codec::TemperFamily family = codec::TemperFamily::gold;
  // What the thermometer measures: the machine structure (material) or the air.
  Quantity quantity = Quantity::material_temperature_degc;
};

// A PCsensor TEMPer on a HID transport (transport/hid.hpp): sends the init report once, then
// polls with the read report every options.poll_period. Readings: `quantity` per sensor
// (channel 0 inner, 1 the probe), and air_humidity_pct for TEMPerX/HUM models.
std::unique_ptr<Instrument> make_temper(boost::asio::io_context& io,
                                        std::unique_ptr<transport::Transport> transport,
                                        InstrumentOptions options, TemperOptions temper = {});

enum class PositionFeedKind { halsampler, shdr };
struct PositionFeedOptions {
  PositionFeedKind kind = PositionFeedKind::shdr;
  codec::HalsamplerConfig halsampler;
  codec::ShdrConfig shdr;
};

// A machine position feed (LinuxCNC halsampler lines, or an MTConnect SHDR adapter that is
// sent "* PING" every options.poll_period). Readings: machine_position_m, channel = axis
// (0 X, 1 Y, 2 Z), timed on arrival with the service's clock.
std::unique_ptr<Instrument> make_position_feed(boost::asio::io_context& io,
                                               std::unique_ptr<transport::Transport> transport,
                                               InstrumentOptions options,
                                               PositionFeedOptions feed = {});

}  // namespace cal::drivers
