#pragma once
// What `daq run` and `daq serve` share: the instruments of a configuration's devices, their
// options, and the session capture. Boost.Asio stays out (io_context is forward-declared).
#include <chrono>
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
  double check_s = 10.0;  // the start-up device check's limit; 0: no check
  // The simulated shop in the same process (daq serve --simulate): the instruments read the
  // shop's clock, and poll periods are in simulated seconds (multiplied by poll_scale =
  // 1 / speed for the wall-clock timers). Empty / 1: the steady clock, real time.
  cal::drivers::Clock clock;
  double poll_scale = 1.0;
  // Wraps each instrument a run makes (daq serve: the device board watches their states and
  // readings); empty: none.
  std::function<std::unique_ptr<cal::drivers::Instrument>(
      const cal::daq::DeviceConfig&, std::unique_ptr<cal::drivers::Instrument>)>
      wrap;
};

// How `daq run` drives its event loop until the run has finished: empty, by the wall clock
// until the run ends (Ctrl-C stops it); `daq sim --acquire` runs the simulated shop's program on
// simulated time instead, then the run is stopped if it has not finished.
using RunDriver = std::function<void(const std::function<bool()>& finished)>;
// `daq run linear` and `daq run circle` on `io` (o.config names the configuration); print the
// results; throw cal::InputError when the run did not complete.
void run_linear_test(const RunOptions& o, boost::asio::io_context& io, const RunDriver& drive);
void run_circle_test(const RunOptions& o, boost::asio::io_context& io, const RunDriver& drive);

// The transport of a device ("tcp HOST:PORT", "serial DEVICE BAUD FRAME", "hid VID:PID" or
// "hid /dev/hidrawN"); throws cal::InputError naming the device and its transport text.
std::unique_ptr<cal::drivers::transport::Transport> make_transport(boost::asio::io_context& io,
                                                                   const cal::daq::DeviceConfig& c);
// The instrument spec of a configured device; throws cal::InputError when its driver's readings
// cannot fill its role (a PTU300 as the ballbar).
InstrumentSpec spec_of(const cal::daq::DeviceConfig& c, std::uint16_t device, int test_axis = 0);
// The ballbar of a circle test: the device with role "ballbar" whose driver gives lengths;
// else cal::InputError naming the configuration.
const cal::daq::DeviceConfig& ballbar_device(const cal::daq::Config& c);
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

// A poll period (seconds of the run's clock) as the wall-clock timer's period (see RunOptions).
std::chrono::microseconds scaled_poll(std::chrono::microseconds period, const RunOptions& o);
// The options of a configured device: its name, poll period (the driver's default when the
// configuration gives none), the run's clock and reconnection limit.
cal::drivers::InstrumentOptions instrument_options(const cal::daq::DeviceConfig& dc,
                                                   const InstrumentSpec& s, const RunOptions& o,
                                                   cal::replay::CaptureRecorder* recorder);

// The start-up check of `daq run` and `daq serve`: every device of `specs` is opened once (no
// reconnection) and must speak (a reading) within `within`; a device that may be silent until
// something happens (a ballbar gauge before it is mounted) must open. Prints each device's
// state through `print`; throws cal::InputError naming every device that failed and why.
void check_devices(const cal::daq::Config& config, const std::vector<InstrumentSpec>& specs,
                   std::chrono::duration<double> within,
                   const std::function<void(const std::string&)>& print);

// The instruments of a linear run (laser, air, material sensors, optional position feed).
std::vector<InstrumentSpec> linear_specs(const cal::daq::Config& config);
// Puts an instrument in its role's place in a linear run (the laser's and the position feed's
// channel from the driver); live and in replay.
void place_linear_instrument(const InstrumentSpec& s,
                             std::unique_ptr<cal::drivers::Instrument> inst, LinearRunSetup& setup);
void add_linear_instruments(boost::asio::io_context& io, const cal::daq::Config& config,
                            const std::vector<InstrumentSpec>& specs, const RunOptions& o,
                            cal::replay::CaptureRecorder* recorder, LinearRunSetup& setup);

}  // namespace daq
