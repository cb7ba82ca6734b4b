#pragma once
// A simulated twin: a server that speaks a device's protocol as the real device does, over a
// real channel (a loopback TCP port, a pseudo-terminal) or, where the kernel offers no such
// channel to an unprivileged process (USB-HID), through an in-process transport. Each device's
// twin is in its folder (drivers/<device>/twin.hpp) and the registry builds it
// (DeviceDriver::make_twin). SIMULATED, and named so.
#include <cstdint>
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

namespace detail {
struct PtyChannel;  // sim/twin_io.hpp (private to drivers/)
struct TcpChannel;
}  // namespace detail

// A twin on a pseudo-terminal: the driver opens device_path() like a /dev/ttyUSB0. The twin's
// Impl is a detail::PtyChannel (the pty and the timer that paces its output).
class PtyTwin : public Twin {
 public:
  ~PtyTwin() override;  // stops the timer and closes the pty

  const std::string& device_path() const;
  std::string transport() const override;  // "serial PATH SETTINGS", e.g. "... 4800 7E1"
  // Closes the master side: the driver sees what an unplugged USB adapter looks like.
  void unplug() override;
  std::uint64_t lines_sent() const;

 protected:
  PtyTwin(std::shared_ptr<detail::PtyChannel> channel, std::string settings);

 private:
  std::shared_ptr<detail::PtyChannel> channel_;
  std::string settings_;
};

// A twin on a loopback TCP port. The twin's Impl is a detail::TcpChannel (the line server and
// the timer that paces its output, if it sends unasked).
class TcpTwin : public Twin {
 public:
  ~TcpTwin() override;  // stops the timer, stops accepting and drops every client

  std::uint16_t port() const;
  std::string transport() const override;  // "tcp 127.0.0.1:PORT"
  // Drops every client connection, as a power cycle or a pulled cable would.
  void unplug() override;

 protected:
  explicit TcpTwin(std::shared_ptr<detail::TcpChannel> channel);

 private:
  std::shared_ptr<detail::TcpChannel> channel_;
};

}  // namespace cal::drivers::sim
