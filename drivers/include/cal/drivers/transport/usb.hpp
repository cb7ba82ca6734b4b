#pragma once
// libusb: enumeration of attached USB devices and hot-plug arrival/removal events. Serial
// and HID instruments are then opened through their own transports (the kernel's cdc_acm /
// ftdi_sio / hidraw drivers); libusb tells which devices are there and when they come and go.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace boost::asio {
class io_context;
}

namespace cal::drivers::transport {

struct UsbDeviceInfo {
  std::uint16_t vendor_id = 0;
  std::uint16_t product_id = 0;
  std::uint8_t bus = 0;
  std::uint8_t address = 0;
  std::string port_path;  // "1-2.4": bus, then the hub port numbers; stable across re-plugs
};

// Attached devices, all of them when vendor_id == 0, or one VID (and PID if != 0). An empty
// list when the machine has no USB (containers); throws std::runtime_error if libusb fails.
std::vector<UsbDeviceInfo> enumerate_usb(std::uint16_t vendor_id = 0, std::uint16_t product_id = 0);

// True when the platform's libusb delivers hot-plug events (Linux with udev or netlink).
bool usb_hotplug_supported();

// Delivers arrival/removal of matching devices on the io_context's thread until destroyed.
// libusb needs its own event thread; the watcher owns it (RAII) and posts every event to the
// io_context, so handlers never run concurrently with the rest of the service.
class UsbHotplugWatcher {
 public:
  enum class Event { arrived, left };
  using Handler = std::function<void(Event, const UsbDeviceInfo&)>;

  // vendor_id/product_id 0 match any. Throws std::runtime_error if hot-plug is unsupported
  // or registration fails. Devices already attached are reported as `arrived` first.
  UsbHotplugWatcher(boost::asio::io_context& io, std::uint16_t vendor_id, std::uint16_t product_id,
                    Handler handler);
  ~UsbHotplugWatcher();
  UsbHotplugWatcher(const UsbHotplugWatcher&) = delete;
  UsbHotplugWatcher& operator=(const UsbHotplugWatcher&) = delete;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cal::drivers::transport
