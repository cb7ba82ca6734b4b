#pragma once
// What `daq run` and `daq serve` share: the instruments of a configuration's devices, their
// options, and the session capture. Boost.Asio stays out (io_context is forward-declared).
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "cal/daq/config.hpp"
#include "cal/drivers/instrument.hpp"
#include "cal/replay/capture.hpp"
#include "cal/replay/session.hpp"
#include "linear_run.hpp"
#include "session_spec.hpp"

namespace daq {

struct RunOptions {
  std::string config, db, capture;
  int give_up_after = 20;
  bool json = false;
  // The simulated shop in the same process (daq serve --simulate): the instruments read the
  // shop's clock, and the configuration's poll periods are in simulated seconds (multiplied by
  // poll_scale = 1 / speed for the wall-clock timers). Empty / 1: the steady clock, real time.
  cal::drivers::Clock clock;
  double poll_scale = 1.0;
  // Wraps each instrument a run makes (daq serve: the device board watches their states and
  // readings); empty: none.
  std::function<std::unique_ptr<cal::drivers::Instrument>(
      const cal::daq::DeviceConfig&, std::unique_ptr<cal::drivers::Instrument>)>
      wrap;
};

// "tcp HOST:PORT", "serial DEVICE BAUD FRAME", "hid VID:PID" or "hid /dev/hidrawN"; throws
// cal::InputError naming the device and its transport text.
std::unique_ptr<cal::drivers::transport::Transport> make_transport(boost::asio::io_context& io,
                                                                   const cal::daq::DeviceConfig& c);
// The same checks without making anything (the set-up form's validation).
void check_transport(const cal::daq::DeviceConfig& c);
// The ballbar of a circle test: the device with role "ballbar", a line gauge; else
// cal::InputError naming the configuration.
const cal::daq::DeviceConfig& ballbar_device(const cal::daq::Config& c);
InstrumentSpec spec_of(const cal::daq::DeviceConfig& c, std::uint16_t device);
// The device of a role, or cal::InputError naming the configuration file.
const cal::daq::DeviceConfig& need(const cal::daq::Config& c, const char* role);

// Records the capture of a session when asked to (--capture FILE).
struct SessionCapture {
  std::unique_ptr<cal::replay::CaptureWriter> writer;
  std::unique_ptr<cal::replay::CaptureRecorder> recorder;
  SessionCapture(const std::string& path, const cal::daq::Config& c,
                 const std::vector<InstrumentSpec>& specs) {
    if (path.empty()) return;
    writer =
        std::make_unique<cal::replay::CaptureWriter>(path, capture_header(c, specs, "daq 0.1.0"));
    recorder = std::make_unique<cal::replay::CaptureRecorder>(*writer);
  }
  std::string absolute_path(const std::string& path) const {
    return writer ? std::filesystem::absolute(path).string() : std::string{};
  }
};

// A configured poll period (seconds) as the wall-clock timer's period (see RunOptions).
std::chrono::microseconds scaled_poll(double poll_s, const RunOptions& o);
// The options of a configured device: its name, poll period and the run's reconnection limit.
cal::drivers::InstrumentOptions instrument_options(const cal::daq::DeviceConfig& dc,
                                                   const RunOptions& o,
                                                   cal::replay::CaptureRecorder* recorder);

// The instruments of a linear run (laser, air, material sensors, optional position feed).
std::vector<InstrumentSpec> linear_specs(const cal::daq::Config& config);
void add_linear_instruments(boost::asio::io_context& io, const cal::daq::Config& config,
                            const std::vector<InstrumentSpec>& specs, const RunOptions& o,
                            cal::replay::CaptureRecorder* recorder, LinearRunSetup& setup);

}  // namespace daq
