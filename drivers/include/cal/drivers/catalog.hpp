#pragma once
// The USB devices the drivers know by VID:PID, and which driver takes each. The udev rules
// in udev/ cover the same list (tests/udev/check_rules.sh checks it). Serial instruments
// behind generic USB-serial adapters cannot be recognised by VID:PID; `daq devices --probe`
// asks them.
#include <cstdint>
#include <span>
#include <string_view>

namespace cal::drivers {

struct KnownDevice {
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
  std::string_view driver;       // "temper", "ptu300", ...
  std::string_view description;  // what is written on the device
  std::string_view transport;    // "hid" or "serial"
};

std::span<const KnownDevice> known_usb_devices();
const KnownDevice* find_known_device(std::uint16_t vendor_id, std::uint16_t product_id);

}  // namespace cal::drivers
