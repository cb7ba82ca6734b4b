#pragma once
// Simulated twins: servers that speak the exact protocols of the supported instruments over
// real channels (a loopback TCP port, pseudo-terminals), backed by the simulated machine and
// air, so the real transports, codecs and instruments can be run against them. Simulated, and
// named so: they are for tests, the demo and training, never for a measurement.
//
// Boost.Asio stays out of this header; io_context is forward-declared in transport.hpp.
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>

#include "cal/drivers/sim/environment.hpp"
#include "cal/drivers/sim/machine.hpp"
#include "cal/drivers/transport/transport.hpp"

namespace cal::drivers::sim {

// The machine and the air on one simulated time line, advanced on demand. Every twin asks
// for the state "now" through the same World, so they all agree on time.
class World {
 public:
  World(MachineConfig machine, AirConfig air, double step_s = 1e-3);
  // Steps the machine up to t_s (never backwards: an earlier t is a no-op).
  void advance_to(double t_s);
  Machine& machine() { return machine_; }
  const MachineState& state() const { return machine_.state(); }
  Air& air() { return air_; }
  double time_s() const { return machine_.state().time_s; }

 private:
  Machine machine_;
  Air air_;
  double step_s_;
};

// Simulated seconds since the session start. The default clock runs `speed` times faster
// than the steady clock, so a 36 s ballbar circle can be acquired in a few seconds of a test.
using Clock = std::function<double()>;
Clock steady_clock(double speed = 1.0);

// --- Attocube IDS3010 ------------------------------------------------------------------------

struct IdsTwinConfig {
  std::uint16_t port = 0;  // 0: an ephemeral port on 127.0.0.1 (see IdsTwin::port())
  // Which machine axis each of the three interferometer axes measures (-1: none, reads 0),
  // and the tool position (mm along that axis) where its displacement was reset to zero.
  std::array<int, 3> machine_axis{0, -1, -1};
  std::array<double, 3> datum_mm{0.0, 0.0, 0.0};
  double starting_s = 0.2;  // "measurement starting" lasts this long after startMeasurement
  bool ecu_connected = true;
};

class IdsTwin {
 public:
  IdsTwin(boost::asio::io_context& io, World& world, Clock clock, IdsTwinConfig config = {});
  ~IdsTwin();
  IdsTwin(const IdsTwin&) = delete;
  IdsTwin& operator=(const IdsTwin&) = delete;

  std::uint16_t port() const;
  // Simulates a blocked beam on one axis: its displacement requests answer with an error
  // code (the twin's stand-in for the device's signal-lost warning) until restored.
  void set_beam_lost(int axis, bool lost);
  // Drops every client connection (as a power cycle or a pulled cable would).
  void drop_connections();
  std::uint64_t requests_served() const;

  static constexpr std::int64_t error_not_measuring = 1;  // twin's code: not in measurement
  static constexpr std::int64_t error_beam_lost = 2;      // twin's code: signal lost on axis

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

// --- MTConnect SHDR adapter (a machine position feed) on loopback TCP ---------------------------

struct ShdrTwinConfig {
  std::uint16_t port = 0;  // 0: an ephemeral port on 127.0.0.1
  // Wall-clock period of the position lines, each "|Xcom|x|Ycom|y|Zcom|z" (no timestamp: the
  // agent stamps it), the control's commanded position in mm.
  std::chrono::milliseconds period{5};
  std::int64_t pong_timeout_ms = 10000;  // the answer to "* PING": "* PONG 10000"
};

// Streams the simulated control's commanded position to every connected agent and answers
// its heartbeats, as an MTConnect adapter does.
class ShdrTwin {
 public:
  ShdrTwin(boost::asio::io_context& io, World& world, Clock clock, ShdrTwinConfig config = {});
  ~ShdrTwin();
  ShdrTwin(const ShdrTwin&) = delete;
  ShdrTwin& operator=(const ShdrTwin&) = delete;
  std::uint16_t port() const;
  std::uint64_t lines_sent() const;
  std::uint64_t pings_answered() const;

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

// --- Vaisala PTU300 on a pseudo-terminal -----------------------------------------------------

struct Ptu300TwinConfig {
  bool start_in_run_mode = false;  // SMODE RUN: a line every `interval_s` without asking
  double interval_s = 1.0;         // INTV
};

class Ptu300Twin {
 public:
  // Opens a pseudo-terminal pair; the driver opens device_path() like a /dev/ttyUSB0.
  Ptu300Twin(boost::asio::io_context& io, World& world, Clock clock, Ptu300TwinConfig config = {});
  ~Ptu300Twin();
  Ptu300Twin(const Ptu300Twin&) = delete;
  Ptu300Twin& operator=(const Ptu300Twin&) = delete;

  const std::string& device_path() const;
  // Closes the master side: the driver sees what an unplugged USB adapter looks like.
  void unplug();
  std::uint64_t lines_sent() const;

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

// --- A line-oriented serial sensor on a pty: by default the length gauge of a telescoping ---
// --- ballbar; with a value function, any scalar (a material thermometer) -------------------

struct GaugeTwinConfig {
  Vec3 pivot_mm{};                 // centre of the table ball, workpiece coordinates
  double zero_length_mm = 100.0;   // the bar length at which the gauge reads 0
  double sample_rate_hz = 1000.0;  // continuous output rate (simulated time)
  bool continuous = true;          // false: one reading per request line
  std::string request = "?";       // the request line (without its CR) in polled mode
  int decimals = 5;                // "+000.12345": 10 nm resolution
  // What the line carries; empty: the ballbar, length(tool, pivot) - zero_length_mm. Another
  // function makes a serial thermometer on the structure, e.g. the machine temperature.
  std::function<double(const World&)> value;
};

class GaugeTwin {
 public:
  GaugeTwin(boost::asio::io_context& io, World& world, Clock clock, GaugeTwinConfig config = {});
  ~GaugeTwin();
  GaugeTwin(const GaugeTwin&) = delete;
  GaugeTwin& operator=(const GaugeTwin&) = delete;

  const std::string& device_path() const;
  void unplug();
  std::uint64_t lines_sent() const;
  // Starts (from the current simulated time) or stops the continuous output: a bar is only
  // mounted, and a stream only read, for its test.
  void set_streaming(bool on);

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;
};

}  // namespace cal::drivers::sim
