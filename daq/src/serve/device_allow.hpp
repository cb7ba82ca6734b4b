#pragma once
// Which devices `daq serve` may open (docs/web.md, "Devices"): a set-up applied from the page
// names its devices by transport text, and a token holder on the network must not be able to
// make the PC connect into its networks or open a terminal. The service opens only
//  - the devices of the configuration it was started with (-c, or the simulated shop's): the
//    same serial path, TCP host and port, or HID id, whatever the line settings; and
//  - those matching an --allow-device pattern:
//      /dev/ttyUSB*           a path glob (fnmatch; '*' does not cross '/'): serial devices and
//                             HID devices named by path; "serial GLOB" for serial ones only
//      HOST:PORT, HOST:LOW-HIGH, "tcp HOST:PORT"
//                             TCP; HOST a glob on the text as written ("192.168.1.*",
//                             "[fe80::1]"): a name matches that name, not its address
//      "hid VID:PID"          a HID device by the ids `daq devices` shows (hex; globs allowed)
// A path with a ".." component matches no pattern.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cal/daq/config.hpp"

namespace daq::serve {

// What a transport text names: kind "serial" (name: the path), "tcp" (host, port) or "hid"
// (name: "vvvv:pppp" lower-case, or the path); nullopt for text that is not a transport.
struct DeviceTarget {
  std::string kind;
  std::string name;
  unsigned port = 0;
};
std::optional<DeviceTarget> device_target(std::string_view transport);

// A device the service may not open, and how the operator would allow it.
struct DeviceRefusal {
  std::string device;     // "devices.laser"
  std::string transport;  // as the set-up names it
  std::string allow;      // the option that would allow it: "--allow-device 127.0.0.1:9090"
  std::string message;    // the whole reason, for the error body
};

class DeviceAllowList {
 public:
  // Throws cal::InputError naming a pattern that is not one of the forms above.
  explicit DeviceAllowList(const std::vector<std::string>& patterns = {});

  // The devices of the configuration the service started with are allowed as they are.
  void allow_devices_of(const cal::daq::Config& config);
  bool allows(std::string_view transport) const;
  // The first device of `devices` (id, transport text) not allowed; nullopt if all are.
  std::optional<DeviceRefusal> refusal(
      const std::vector<std::pair<std::string, std::string>>& devices) const;

 private:
  struct Pattern {
    std::string kind;            // "path" (serial or hid by path), "serial", "tcp", "hid"
    std::string glob;            // the path, host or id glob
    unsigned low = 0, high = 0;  // tcp ports
  };
  std::vector<Pattern> patterns_;
  std::vector<DeviceTarget> configured_;
};

}  // namespace daq::serve
