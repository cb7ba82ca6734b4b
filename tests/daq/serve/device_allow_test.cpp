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

TEST(DeviceAllow, NothingIsAllowedByDefault) {
  const DeviceAllowList none;
  EXPECT_FALSE(none.allows("serial /dev/tty0 9600 8N1"));
  EXPECT_FALSE(none.allows("tcp 127.0.0.1:9090"));
  EXPECT_FALSE(none.allows("hid 413d:2107"));
  EXPECT_FALSE(none.allows("nonsense"));
}

TEST(DeviceAllow, TheConfigurationsDevicesWhateverTheLineSettings) {
  DeviceAllowList a;
  a.allow_devices_of(config_with({"serial /dev/ttyUSB0 4800 7E1", "tcp Laser.local:9090",
                                  "hid 413D:2107", "hid /dev/hidraw3"}));
  EXPECT_TRUE(a.allows("serial /dev/ttyUSB0 9600 8N1 rtscts"));
  EXPECT_FALSE(a.allows("serial /dev/ttyUSB1 4800 7E1"));
  EXPECT_TRUE(a.allows("tcp laser.local:9090"));
  EXPECT_FALSE(a.allows("tcp laser.local:9091"));
  EXPECT_FALSE(a.allows("tcp 127.0.0.1:9090"));  // a name is not its address
  EXPECT_TRUE(a.allows("hid 413d:2107"));
  EXPECT_FALSE(a.allows("hid 413d:2108"));
  EXPECT_TRUE(a.allows("hid /dev/hidraw3"));
  EXPECT_FALSE(a.allows("serial /dev/hidraw3 9600 8N1"));  // another kind of device
}

TEST(DeviceAllow, PathGlobs) {
  const DeviceAllowList a({"/dev/ttyUSB*", "serial /dev/serial/by-id/usb-FTDI*"});
  EXPECT_TRUE(a.allows("serial /dev/ttyUSB0 4800 7E1"));
  EXPECT_TRUE(a.allows("serial /dev/ttyUSB12 4800 7E1"));
  EXPECT_FALSE(a.allows("serial /dev/tty0 4800 7E1"));
  EXPECT_FALSE(a.allows("serial /dev/ttyACM0 4800 7E1"));
  // '*' does not cross '/', and ".." matches nothing.
  EXPECT_FALSE(a.allows("serial /dev/ttyUSB0/../tty0 4800 7E1"));
  EXPECT_FALSE(a.allows("serial /dev/ttyUSB../../dev/tty0 4800 7E1"));
  EXPECT_TRUE(a.allows("serial /dev/serial/by-id/usb-FTDI_FT232R-if00 4800 7E1"));
  EXPECT_FALSE(a.allows("hid /dev/serial/by-id/usb-FTDI_x"));  // "serial GLOB": serial only
  const DeviceAllowList hidraw({"/dev/hidraw*"});
  EXPECT_TRUE(hidraw.allows("hid /dev/hidraw0"));
}

TEST(DeviceAllow, TcpHostsAndPortRanges) {
  const DeviceAllowList a({"192.168.1.*:9090", "10.0.0.5:7000-7010", "tcp [::1]:9090"});
  EXPECT_TRUE(a.allows("tcp 192.168.1.20:9090"));
  EXPECT_FALSE(a.allows("tcp 192.168.1.20:9091"));
  EXPECT_FALSE(a.allows("tcp 192.168.2.20:9090"));
  EXPECT_TRUE(a.allows("tcp 10.0.0.5:7000"));
  EXPECT_TRUE(a.allows("tcp 10.0.0.5:7010"));
  EXPECT_FALSE(a.allows("tcp 10.0.0.5:7011"));
  EXPECT_FALSE(a.allows("tcp 10.0.0.5:6999"));
  EXPECT_TRUE(a.allows("tcp [::1]:9090"));
  EXPECT_FALSE(a.allows("tcp [::2]:9090"));
  EXPECT_FALSE(a.allows("serial 192.168.1.20:9090 4800 7E1"));
}

TEST(DeviceAllow, HidIds) {
  const DeviceAllowList a({"hid 413d:*", "hid 1A86:E025"});
  EXPECT_TRUE(a.allows("hid 413d:2107"));
  EXPECT_TRUE(a.allows("hid 1a86:e025"));
  EXPECT_FALSE(a.allows("hid 1a86:e026"));
  EXPECT_FALSE(a.allows("tcp 413d:2107"));
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
