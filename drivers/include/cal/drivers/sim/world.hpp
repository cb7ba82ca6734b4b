#pragma once
// The simulated machine and air on one simulated time line, shared by every simulated twin
// (drivers/<device>/twin.hpp). SIMULATED, and named so: for tests, the demo and training.
#include <functional>

#include "cal/drivers/sim/environment.hpp"
#include "cal/drivers/sim/machine.hpp"

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

}  // namespace cal::drivers::sim
