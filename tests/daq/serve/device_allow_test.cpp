// Which devices `daq serve` may open (daq/src/serve/device_allow.hpp): the configuration's
// own and those an --allow-device pattern names, nothing else.
#include "serve/device_allow.hpp"

#include <gtest/gtest.h>

#include "cal/analysis/error.hpp"

namespace {

using daq::serve::device_target;
using daq::serve::DeviceAllowList;

cal::daq::Config config_with(std::initializer_list<const char*> transports) {
  cal::daq::Config c;
  int n = 0;
  for (const char* t : transports)
    c.devices.push_back({.id = "d" + std::to_string(n++), .driver = "x", .transport = t});
  return c;
}

// What `list` allows and what it refuses: a failure names the transport text.
void expect_allows(const DeviceAllowList& list, std::initializer_list<const char*> allowed,
                   std::initializer_list<const char*> refused) {
  for (const char* t : allowed) EXPECT_TRUE(list.allows(t)) << t;
  for (const char* t : refused) EXPECT_FALSE(list.allows(t)) << t;
}

TEST(DeviceAllow, NothingIsAllowedByDefault) {
  const DeviceAllowList none;
  expect_allows(none, {},
                {"serial /dev/tty0 9600 8N1", "tcp 127.0.0.1:9090", "hid 413d:2107", "nonsense"});
}

TEST(DeviceAllow, TheConfigurationsDevicesWhateverTheLineSettings) {
  DeviceAllowList a;
  a.allow_devices_of(config_with({"serial /dev/ttyUSB0 4800 7E1", "tcp Laser.local:9090",
                                  "hid 413D:2107", "hid /dev/hidraw3"}));
  // Refused: another device, another port, the address of an allowed name (a name is not its
  // address), and an allowed path as another kind of device.
  expect_allows(a,
                {"serial /dev/ttyUSB0 9600 8N1 rtscts", "tcp laser.local:9090", "hid 413d:2107",
                 "hid /dev/hidraw3"},
                {"serial /dev/ttyUSB1 4800 7E1", "tcp laser.local:9091", "tcp 127.0.0.1:9090",
                 "hid 413d:2108", "serial /dev/hidraw3 9600 8N1"});
}

TEST(DeviceAllow, PathGlobs) {
  const DeviceAllowList a({"/dev/ttyUSB*", "serial /dev/serial/by-id/usb-FTDI*"});
  // '*' does not cross '/', ".." matches nothing, and "serial GLOB" allows serial devices only.
  expect_allows(a,
                {"serial /dev/ttyUSB0 4800 7E1", "serial /dev/ttyUSB12 4800 7E1",
                 "serial /dev/serial/by-id/usb-FTDI_FT232R-if00 4800 7E1"},
                {"serial /dev/tty0 4800 7E1", "serial /dev/ttyACM0 4800 7E1",
                 "serial /dev/ttyUSB0/../tty0 4800 7E1",
                 "serial /dev/ttyUSB../../dev/tty0 4800 7E1", "hid /dev/serial/by-id/usb-FTDI_x"});
  const DeviceAllowList hidraw({"/dev/hidraw*"});
  expect_allows(hidraw, {"hid /dev/hidraw0"}, {});
}

TEST(DeviceAllow, TcpHostsAndPortRanges) {
  const DeviceAllowList a({"192.168.1.*:9090", "10.0.0.5:7000-7010", "tcp [::1]:9090"});
  expect_allows(
      a, {"tcp 192.168.1.20:9090", "tcp 10.0.0.5:7000", "tcp 10.0.0.5:7010", "tcp [::1]:9090"},
      {"tcp 192.168.1.20:9091", "tcp 192.168.2.20:9090", "tcp 10.0.0.5:7011", "tcp 10.0.0.5:6999",
       "tcp [::2]:9090", "serial 192.168.1.20:9090 4800 7E1"});
}

TEST(DeviceAllow, HidIds) {
  const DeviceAllowList a({"hid 413d:*", "hid 1A86:E025"});
  expect_allows(a, {"hid 413d:2107", "hid 1a86:e025"}, {"hid 1a86:e026", "tcp 413d:2107"});
}

TEST(DeviceAllow, MalformedPatternsAreRefusedNamingThem) {
  for (const char* bad : {"", "ttyUSB0", "host", "host:0", "host:70000", "host:90-80",
                          "usb 1234:5678", "serial ttyUSB0", "hid 1234", "tcp /dev/x"}) {
    try {
      DeviceAllowList a({bad});
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const cal::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("'") + bad + "'"), std::string::npos)
          << e.what();
    }
  }
}

TEST(DeviceAllow, TheRefusalNamesTheDeviceAndHowToAllowIt) {
  DeviceAllowList a({"/dev/ttyUSB*"});
  EXPECT_FALSE(a.refusal({{"air", "serial /dev/ttyUSB0 4800 7E1"}}));
  const auto r = a.refusal({{"air", "serial /dev/ttyUSB0 4800 7E1"},
                            {"laser", "tcp 127.0.0.1:5555"},
                            {"probe", "serial /dev/tty0 9600 8N1"}});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->device, "devices.laser");
  EXPECT_EQ(r->allow, "--allow-device 127.0.0.1:5555");
  EXPECT_NE(r->message.find("devices.laser"), std::string::npos) << r->message;
  EXPECT_NE(r->message.find("--allow-device 127.0.0.1:5555"), std::string::npos) << r->message;
  EXPECT_EQ(a.refusal({{"probe", "serial /dev/tty0 9600 8N1"}})->allow, "--allow-device /dev/tty0");
  EXPECT_EQ(a.refusal({{"t", "hid 413d:2107"}})->allow, "--allow-device 'hid 413d:2107'");
}

TEST(DeviceAllow, TargetsOfTransportTexts) {
  EXPECT_EQ(device_target("serial /dev/ttyUSB0 4800 7E1")->name, "/dev/ttyUSB0");
  EXPECT_EQ(device_target("tcp Host:80")->name, "host");
  EXPECT_EQ(device_target("tcp Host:80")->port, 80u);
  EXPECT_EQ(device_target("hid 413D:2107")->name, "413d:2107");
  EXPECT_FALSE(device_target("tcp host"));
  EXPECT_FALSE(device_target("tcp host:0"));
  EXPECT_FALSE(device_target("usb 1:2"));
  EXPECT_FALSE(device_target(""));
}

}  // namespace
