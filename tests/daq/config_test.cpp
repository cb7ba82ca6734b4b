// Configuration files: a full example parses to the values written in it, and every mistake
// is refused with the file, line, column and key.
#include "cal/daq/config.hpp"

#include <gtest/gtest.h>

#include "cal/analysis/error.hpp"

namespace {

using cal::daq::parse_config;

constexpr const char* kExample = R"(
campaign = "2026-11 annual"

[machine]
name = "VMC-1"
description = "3-axis vertical machining centre"

[devices.laser]
driver = "ids3010"
transport = "tcp 192.168.1.5:9090"
axes = [0]
role = "laser"

[devices.air]
driver = "ptu300"
transport = "serial /dev/ttyUSB0 4800 7E1"
poll_s = 1
role = "air"

[environment]
equation = "edlen"
stale_after_s = 5
on_stale = "fallback"
fallback_pressure_pa = 100000
expansion_ppm_per_k = 11.7

[trigger]
tolerance_um = 2
dwell_s = 1.5

[test.linear]
axis = "Y"
first_mm = 0
last_mm = 800
interval_mm = 100
random_fraction = 0.2
runs = 5
dwell_s = 4

[test.circle]
radius_mm = 150
feed_mm_per_min = 1000
centre_mm = [250, 200, -100]
)";

std::string error_of(const std::string& text) {
  try {
    parse_config(text, "machine.toml");
  } catch (const cal::InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(Config, ParsesTheFullExample) {
  const auto c = parse_config(kExample, "machine.toml");
  EXPECT_EQ(c.campaign, "2026-11 annual");
  EXPECT_EQ(c.machine_name, "VMC-1");
  ASSERT_EQ(c.devices.size(), 2u);
  EXPECT_EQ(c.device_for("laser")->transport, "tcp 192.168.1.5:9090");
  EXPECT_EQ(c.device_for("laser")->options.integers("axes"), std::vector<std::int64_t>{0});
  EXPECT_EQ(c.device_for("air")->poll_s, 1.0);  // an integer in TOML is accepted as a number
  EXPECT_EQ(c.device_for("material"), nullptr);
  EXPECT_EQ(c.environment.equation, "edlen");
  EXPECT_EQ(c.environment.on_stale, cal::daq::StalePolicy::fallback);
  EXPECT_EQ(c.environment.fallback_pressure_pa, 100000.0);
  EXPECT_EQ(c.environment.expansion_ppm_per_k, 11.7);
  EXPECT_EQ(c.trigger.tolerance_um, 2.0);
  ASSERT_TRUE(c.linear);
  EXPECT_EQ(c.linear->axis, "Y");
  EXPECT_EQ(*c.linear->interval_mm, 100.0);
  EXPECT_FALSE(c.linear->count);
  ASSERT_TRUE(c.circle);
  EXPECT_EQ(c.circle->centre_mm, (std::vector<double>{250, 200, -100}));
}

TEST(Config, NamesFileLineColumnAndKey) {
  EXPECT_EQ(error_of("[devices.laser]\ndriver = \"foo\"\ntransport = \"tcp a:1\"\n"),
            "machine.toml:2:10: key 'devices.laser.driver': 'foo' is not one of: ids3010, ptu300, "
            "gauge, temper, halsampler, shdr");
  EXPECT_EQ(error_of("[test.linear]\nfirst_mm = 0\nfeed_mm_min = 100\ncount = 5\n"),
            "machine.toml:3:15: key 'test.linear.feed_mm_min': unknown key (a typo?)");
  EXPECT_EQ(error_of("[trigger]\ndwell_s = -1\n"),
            "machine.toml:2:11: key 'trigger.dwell_s': -1 must be > 0");
  EXPECT_EQ(error_of("[test.linear]\ncount = 5\ndwell_s = 1\n"),
            "machine.toml:3:11: key 'test.linear.dwell_s': the programmed dwell 1 s must exceed "
            "the trigger dwell 1.5 s");
  EXPECT_NE(error_of("[test.linear]\ncount = 5\ninterval_mm = 10\n")
                .find("give exactly one of interval_mm and count"),
            std::string::npos);
  EXPECT_NE(error_of("[machine\nname = 1").find("machine.toml:1:"), std::string::npos);
  EXPECT_EQ(
      error_of("[devices.air]\ndriver = \"ptu300\"\ntransport = \"usb x\"\n"),
      "machine.toml:3:13: key 'devices.air.transport': 'usb' is not one of: tcp, serial, hid");
  EXPECT_EQ(error_of("[devices.t]\ndriver = \"temper\"\ntransport = \"hid 413d:2107\"\n"
                     "family = \"silver\"\n"),
            "machine.toml:4:10: key 'devices.t.family': 'silver' is not one of: ds75, gold, "
            "temperx, sht2x, si7005, si7006");
  EXPECT_EQ(parse_config("[devices.t]\ndriver = \"temper\"\ntransport = \"hid 0c45:7401\"\n"
                         "family = \"ds75\"\nrole = \"material\"\n",
                         "m.toml")
                .device_for("material")
                ->options.text("family"),
            "ds75");
  EXPECT_EQ(error_of("[machine]\nname = 3\n"),
            "machine.toml:2:8: key 'machine.name': expected a string");
}

TEST(Config, DeviceKeysAreCheckedAgainstTheDriversOptionTable) {
  const std::string laser =
      "[devices.laser]\ndriver = \"ids3010\"\ntransport = \"tcp 10.0.0.5:9090\"\n";
  // Types, ranges and choices of the driver's own keys, at the value's position.
  EXPECT_EQ(error_of(laser + "axes = [3]\n"),
            "machine.toml:4:8: key 'devices.laser.axes': 3 must be within [0, 2]");
  EXPECT_EQ(error_of(laser + "axes = [0.5]\n"),
            "machine.toml:4:8: key 'devices.laser.axes': expected an array of integers");
  EXPECT_EQ(error_of(laser + "environment = \"yes\"\n"),
            "machine.toml:4:15: key 'devices.laser.environment': expected true or false");
  // A key of another driver is unknown to this one, and the message lists this one's keys.
  EXPECT_EQ(error_of(laser + "family = \"gold\"\n"),
            "machine.toml:4:10: key 'devices.laser.family': unknown key (a typo?); driver "
            "'ids3010' takes driver, transport, role, poll_s, serial_number, certificate, "
            "calibration_due, axes, start_measurement, environment, api, environment_period_s");
  // Checks between options (a gauge pattern without a capture group) name the driver.
  EXPECT_NE(error_of("[devices.bar]\ndriver = \"gauge\"\ntransport = \"serial /dev/x 9600 8N1\"\n"
                     "pattern = \"[0-9]+\"\n")
                .find("machine.toml:1:1: key 'devices.bar.driver': driver 'gauge': gauge pattern"),
            std::string::npos);
  // The transport text is checked when the file is read, not when the run starts.
  EXPECT_EQ(error_of("[devices.laser]\ndriver = \"ids3010\"\ntransport = \"tcp 10.0.0.5\"\n"),
            "machine.toml:3:13: key 'devices.laser.transport': 'tcp 10.0.0.5': expected tcp "
            "HOST:PORT");
  EXPECT_EQ(
      error_of(
          "[devices.air]\ndriver = \"ptu300\"\ntransport = \"serial /dev/ttyUSB0 4800 7X1\"\n"),
      "machine.toml:3:13: key 'devices.air.transport': 'serial /dev/ttyUSB0 4800 7X1': "
      "serial settings '4800 7X1': parity 'X' (expected N, E or O)");
  // The instrument's records: a calibration date must be a real date.
  const auto c = parse_config(laser +
                                  "serial_number = \"IDS-1234\"\ncertificate = \"DKD 0815\"\n"
                                  "calibration_due = \"2028-02-29\"\n",
                              "m.toml");
  EXPECT_EQ(c.devices[0].serial_number, "IDS-1234");
  EXPECT_EQ(c.devices[0].certificate, "DKD 0815");
  EXPECT_EQ(c.devices[0].calibration_due, "2028-02-29");
  EXPECT_EQ(error_of(laser + "calibration_due = \"2027-02-29\"\n"),
            "machine.toml:4:19: key 'devices.laser.calibration_due': '2027-02-29' is not a date "
            "YYYY-MM-DD");
  // Defaults fill the keys not given; a gauge's "\r" written as two characters is a CR.
  const auto g = parse_config(
      "[devices.t]\ndriver = \"gauge\"\ntransport = \"serial /dev/x 9600 8N1\"\n"
      "request = '?\\r'\nunit = \"degC\"\n",
      "m.toml");
  EXPECT_EQ(g.devices[0].options.text("request"), "?\r");
  EXPECT_EQ(g.devices[0].options.number("scale"), 1.0);
  EXPECT_FALSE(g.devices[0].options.has_value("min_si"));
}

TEST(Config, MissingFileIsNamed) {
  try {
    cal::daq::load_config("/nonexistent/machine.toml");
    FAIL();
  } catch (const cal::InputError& e) {
    EXPECT_STREQ(e.what(), "/nonexistent/machine.toml: cannot open");
  }
}

}  // namespace
