#pragma once
// SIMULATED Vaisala PTU300 on a pseudo-terminal, answering from the simulated air (see
// sim/twin.hpp).
#include <cstdint>
#include <memory>
#include <string>

#include "cal/drivers/sim/twin.hpp"

namespace cal::drivers::sim {

struct Ptu300TwinConfig {
  bool start_in_run_mode = false;  // SMODE RUN: a line every `interval_s` without asking
  double interval_s = 1.0;         // INTV
};

// transport(): "serial PATH 4800 7E1".
class Ptu300Twin final : public PtyTwin {
 public:
  // Opens a pseudo-terminal pair; the driver opens device_path() like a /dev/ttyUSB0.
  Ptu300Twin(boost::asio::io_context& io, World& world, Clock clock, Ptu300TwinConfig config = {});

 private:
  struct Impl;
  explicit Ptu300Twin(std::shared_ptr<Impl> impl);
  std::shared_ptr<Impl> impl_;
};

}  // namespace cal::drivers::sim
