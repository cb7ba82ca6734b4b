#pragma once
// USB-HID transport through hidapi (hidraw back end on Linux, so the udev uaccess rules on
// /dev/hidraw* apply). Used for the PCsensor TEMPer thermometers.
#include <chrono>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "cal/drivers/transport/transport.hpp"

namespace cal::drivers::transport {

struct HidDeviceInfo {
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
  std::string path;  // hidapi's path, e.g. /dev/hidraw3: unique per interface
  std::string serial_number;
  std::string manufacturer;
  std::string product;
  int interface_number = -1;
};

// The attached HID interfaces, all of them when vendor_id == 0, or those of one VID (and PID
// when product_id != 0). Throws std::runtime_error if hidapi cannot be initialised.
std::vector<HidDeviceInfo> enumerate_hid(std::uint16_t vendor_id = 0, std::uint16_t product_id = 0);

struct HidSettings {
  // Either a path (exact interface) or VID:PID with an optional serial number; TEMPer
  // devices expose two interfaces, so `interface_number` picks one when >= 0.
  std::string path;
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
  std::string serial_number;
  int interface_number = -1;
  // hidapi has no asynchronous read: the transport polls with a non-blocking read on the
  // event loop at this interval (thermometers answer in tens of ms, so 5 ms costs nothing).
  std::chrono::milliseconds poll_interval{5};
};

// Writes are passed to hid_write unchanged: the first byte is the report ID (0x00 for devices
// with a single report), as hidapi requires. Each input report arrives as one data chunk.
std::unique_ptr<Transport> make_hid(boost::asio::io_context& io, HidSettings settings);

}  // namespace cal::drivers::transport
