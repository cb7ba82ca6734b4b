#pragma once
// SIMULATED LinuxCNC halsampler feed on a loopback TCP port (as `halsampler | nc -l` would
// serve it): one line per sample of the pins X, Y, Z (the simulated actual tool position in mm),
// "%f " per pin as halsampler prints it, the sample number first only when tagged (-t). See
// sim/twin.hpp.
#include <chrono>
#include <cstdint>
#include <memory>

#include "cal/drivers/sim/twin.hpp"

namespace cal::drivers::sim {

struct HalsamplerTwinConfig {
  std::uint16_t port = 0;          // 0: an ephemeral port on 127.0.0.1
  bool tagged = false;             // halsampler -t: the sample number first
  double sample_rate_hz = 1000.0;  // the sampler's thread rate (simulated time)
  // Samples per line are not skipped; every `overrun_every` samples (0: never) the sampler
  // falls behind once: halsampler prints "overrun" and the sample numbers jump.
  std::uint64_t overrun_every = 0;
  std::uint64_t overrun_lost = 5;
};

class HalsamplerTwin final : public TcpTwin {
 public:
  HalsamplerTwin(boost::asio::io_context& io, World& world, Clock clock,
                 HalsamplerTwinConfig config = {});
  std::uint64_t lines_sent() const;

 private:
  struct Impl;
  explicit HalsamplerTwin(std::shared_ptr<Impl> impl);
  std::shared_ptr<Impl> impl_;
};

}  // namespace cal::drivers::sim
