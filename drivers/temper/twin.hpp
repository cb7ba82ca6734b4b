#pragma once
// SIMULATED PCsensor TEMPer. USB-HID cannot be offered to an unprivileged process without
// kernel support (uhid needs root), so this twin is reached in-process: connect() gives a
// transport that behaves as hidapi's does (writes are output reports with the report ID first,
// each input report arrives as one 8-byte chunk). The stick reads the simulated air, its probe
// the simulated machine structure. See sim/twin.hpp.
#include <cstdint>
#include <memory>
#include <string>

#include "cal/drivers/sim/twin.hpp"
#include "temper/codec.hpp"

namespace cal::drivers::sim {

struct TemperTwinConfig {
  // The answer to the firmware query (01 86 ff 01), as the device sends it: 16 bytes in two
  // reports, padded as the public projects show (e.g. "TEMPer2_V3.7    ").
  std::string firmware = "TEMPer2_V3.7    ";
  codec::TemperFamily family = codec::TemperFamily::gold;
  bool inner = true;      // the sensor in the stick (the air around it)
  bool probe = true;      // the probe on its cable (the machine structure)
  bool humidity = false;  // temperx: the stick's humidity
  // The first this many firmware queries are answered with the second report only ("V3.3    "),
  // as a real TEMPer1F sometimes does (urwen/temper #9, PR #16's usbmon trace).
  int half_firmware_answers = 0;
};

class TemperTwin final : public Twin {
 public:
  TemperTwin(boost::asio::io_context& io, World& world, Clock clock, TemperTwinConfig config = {});
  ~TemperTwin() override;

  std::string transport() const override { return {}; }  // in-process only
  std::unique_ptr<transport::Transport> connect(boost::asio::io_context& io) override;
  void unplug() override;
  std::uint64_t reports_sent() const;
  int firmware_queries() const;  // how many 01 86 ff 01 it was sent

  struct Impl;  // (public so that the in-process transport can hold it weakly)

 private:
  std::shared_ptr<Impl> impl_;
};

}  // namespace cal::drivers::sim
