#pragma once
// What is attached or reachable (`daq devices`, and the set-up page's "detected" list).
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace daq {

struct DevicesOptions {
  std::vector<std::string> tcp_probes;     // HOST[:PORT]
  std::vector<std::string> serial_probes;  // DEVICE[@SETTINGS]
  bool json = false;
  bool options = false;   // the drivers and their option tables instead of the attached devices
  bool markdown = false;  // with options: the Markdown of docs/drivers.md
};

// caldaq.devices.v1: USB devices with the driver that takes them, HID instruments, serial
// ports, and the answers of the probes asked for (each probe waits up to 2 s).
nlohmann::json list_devices(const DevicesOptions& o);

}  // namespace daq
