#pragma once
// A simulated twin: a server that speaks a device's protocol as the real device does, over a
// real channel (a loopback TCP port, a pseudo-terminal) or, where the kernel offers no such
// channel to an unprivileged process (USB-HID), through an in-process transport. Each device's
// twin is in its folder (drivers/<device>/twin.hpp) and the registry builds it
// (DeviceDriver::make_twin). SIMULATED, and named so.
#include <memory>
#include <string>

#include "cal/drivers/sim/world.hpp"
#include "cal/drivers/transport/transport.hpp"

namespace cal::drivers::sim {

class Twin {
 public:
  virtual ~Twin() = default;
  Twin() = default;
  Twin(const Twin&) = delete;
  Twin& operator=(const Twin&) = delete;

  // How a configuration reaches it: "tcp 127.0.0.1:PORT", "serial /dev/pts/N 4800 7E1"; empty
  // when it is reachable in this process only (see connect()).
  virtual std::string transport() const = 0;
  // A transport to the twin within this process; nullptr when transport() is the way.
  virtual std::unique_ptr<transport::Transport> connect(boost::asio::io_context& /*io*/) {
    return nullptr;
  }
  // What a pulled cable or a power cycle does: the connections drop.
  virtual void unplug() = 0;
};

}  // namespace cal::drivers::sim
