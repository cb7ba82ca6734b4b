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
            "machine.toml:2:11: key 'trigger.dwell_s': -1 must be > 0 and at most 3600 s");
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

// Issue 15: every value of the non-device tables is checked at load for its type and range,
// with the file, line, column and key: nothing absurd reaches a part program or a run.
TEST(Config, RefusesNonFiniteAbsurdAndOverflowingValues) {
  const std::string lin = "[test.linear]\ncount = 5\n";
  // TOML has nan and inf: refused for every number.
  EXPECT_EQ(error_of("[test.circle]\nradius_mm = inf\n"),
            "machine.toml:2:13: key 'test.circle.radius_mm': inf is not a finite number");
  EXPECT_EQ(error_of("[test.circle]\ncentre_mm = [nan, 0, 0]\n"),
            "machine.toml:2:13: key 'test.circle.centre_mm': nan is not a finite number");
  EXPECT_EQ(error_of("[environment]\nfallback_temperature_degc = -nan\n"),
            "machine.toml:2:29: key 'environment.fallback_temperature_degc': nan is not a finite "
            "number");
  // 4294967297 = 2^32 + 1 would wrap to 1 run in a 32-bit int.
  EXPECT_EQ(error_of(lin + "runs = 4294967297\n"),
            "machine.toml:3:8: key 'test.linear.runs': 4294967297 is out of range");
  EXPECT_EQ(error_of(lin + "runs = 0\n"),
            "machine.toml:3:8: key 'test.linear.runs': 0 must be within 1 .. 1000");
  EXPECT_EQ(error_of(lin + "overrun_mm = 1e9\n"),
            "machine.toml:3:14: key 'test.linear.overrun_mm': 1000000000 must be within 0 .. "
            "1000 mm");
  EXPECT_EQ(error_of(lin + "overrun_mm = -1\n"),
            "machine.toml:3:14: key 'test.linear.overrun_mm': -1 must be within 0 .. 1000 mm");
  EXPECT_EQ(error_of("[test.linear]\ncount = 1000000000\n"),
            "machine.toml:2:9: key 'test.linear.count': 1000000000 must be within 2 .. 10000");
  EXPECT_EQ(error_of("[test.linear]\ninterval_mm = 1e-9\nlast_mm = 1000\n"),
            "machine.toml:1:1: table [test.linear]: targets: interval 1e-09 mm gives "
            "1000000000001 targets over 0 .. 1000 mm, more than 10000");
  EXPECT_EQ(error_of(lin + "feed_mm_per_min = 1e12\n"),
            "machine.toml:3:19: key 'test.linear.feed_mm_per_min': 1000000000000 must be > 0 and "
            "at most 200000 mm/min");
  EXPECT_EQ(error_of(lin + "first_mm = 500\nlast_mm = 100\n"),
            "machine.toml:1:1: table [test.linear]: targets: last (100 mm) must be greater than "
            "first (500 mm)");
  EXPECT_EQ(error_of(lin + "random_fraction = 0.5\n"),
            "machine.toml:3:19: key 'test.linear.random_fraction': 0.5 must be >= 0 and < 0.5");
  EXPECT_EQ(error_of("[test.circle]\novershoot_deg = 720\n"),
            "machine.toml:2:17: key 'test.circle.overshoot_deg': 720 must be within 0 .. 180 deg");
  EXPECT_EQ(error_of("[test.circle]\ncentre_mm = [0, 1e9, 0]\n"),
            "machine.toml:2:13: key 'test.circle.centre_mm': 1000000000 must be within -100000 .. "
            "100000 mm");
  EXPECT_EQ(error_of("[test.circle]\ncalibrated_radius_mm = -5\n"),
            "machine.toml:2:24: key 'test.circle.calibrated_radius_mm': -5 must be within 0 .. "
            "5000 mm");
  EXPECT_EQ(error_of("[trigger]\nwindow_mm = 1e300\n"),
            "machine.toml:2:13: key 'trigger.window_mm': 1e+300 must be > 0 and at most 1000 mm");
  EXPECT_EQ(error_of("[environment]\nfallback_humidity_pct = 150\n"),
            "machine.toml:2:25: key 'environment.fallback_humidity_pct': 150 must be within 0 .. "
            "100 %");
  EXPECT_EQ(error_of("[environment]\nwavelength_nm = 10\n"),
            "machine.toml:2:17: key 'environment.wavelength_nm': 10 must be within 300 .. 1700 nm");
  // The fallback air must suit the equation chosen (shop-floor is for 633 nm only).
  EXPECT_NE(error_of("[environment]\nequation = \"shop-floor\"\nwavelength_nm = 532\n")
                .find("machine.toml:2:12: key 'environment.equation': with the fallback air: "),
            std::string::npos);
  // A type error is named as before; a float is not an integer, however whole (3.3e49 was
  // converted to int64 inside toml++ without a range check: found by fuzz_config).
  EXPECT_EQ(error_of(lin + "runs = 2.5\n"),
            "machine.toml:3:8: key 'test.linear.runs': expected an integer");
  EXPECT_EQ(
      error_of("[test.linear]\ncount = 33333333333333333333333333333333333333333333333332.0\n"),
      "machine.toml:2:9: key 'test.linear.count': expected an integer");
}

TEST(Config, StandardNamesAreCheckedAtLoad) {
  // Misspelt, this was accepted and thrown only after every stop had been captured.
  const auto e = error_of("[test.linear]\ncount = 5\nstandard = \"iso230-2:2041\"\n");
  EXPECT_EQ(e.rfind("machine.toml:3:12: key 'test.linear.standard': ", 0), 0u) << e;
  EXPECT_NE(e.find("iso230-2:2041"), std::string::npos) << e;
  EXPECT_EQ(
      parse_config("[test.linear]\ncount = 5\nstandard = \"vdi3441\"\n", "m.toml").linear->standard,
      "vdi3441");
}

TEST(Config, NamesHaveNoControlCharacters) {
  EXPECT_EQ(error_of("[machine]\nname = \"VMC\\nM30\"\n"),
            "machine.toml:2:8: key 'machine.name': control characters are not allowed");
  EXPECT_EQ(error_of("campaign = \"a\\u0000b\"\n"),
            "machine.toml:1:12: key 'campaign': control characters are not allowed");
  EXPECT_EQ(error_of("[machine]\nname = \"\"\n"),
            "machine.toml:2:8: key 'machine.name': must not be empty");
  EXPECT_EQ(parse_config("[machine]\nname = \"M\"\ndescription = \"two\\nlines\"\n", "m.toml")
                .machine_description,
            "two\nlines");
}

// An axis over 2000 mm may leave out interval_mm and count (ISO 230-2's 250 mm average is
// then planned); a shorter one may not.
TEST(Config, LongAxisMayLeaveTheTargetsToTheStandard) {
  const auto c = parse_config("[test.linear]\nfirst_mm = 0\nlast_mm = 3000\nruns = 1\n", "m.toml");
  ASSERT_TRUE(c.linear.has_value());
  EXPECT_FALSE(c.linear->interval_mm.has_value());
  EXPECT_FALSE(c.linear->count.has_value());
  EXPECT_NE(error_of("[test.linear]\nfirst_mm = 0\nlast_mm = 2000\n").find("over 2000 mm"),
            std::string::npos);
}

// Issue 36 (c): a rotary axis (A, B, C) is measured by measure = "rotary", its targets in
// degrees; every other kind measures a linear axis, and a rotary axis no other kind.
TEST(Config, RotaryAxisOnlyByTheRotaryKind) {
  const auto c = parse_config(
      "[test.linear]\naxis = \"C\"\nmeasure = \"rotary\"\nfirst_mm = 0\nlast_mm = 360\n"
      "interval_mm = 30\n",
      "m.toml");
  ASSERT_TRUE(c.linear.has_value());
  EXPECT_EQ(c.linear->axis, "C");
  EXPECT_EQ(c.linear->measure.kind, "rotary");
  const std::string targets = "first_mm = 0\nlast_mm = 360\ninterval_mm = 30\n";
  EXPECT_NE(error_of("[test.linear]\naxis = \"B\"\n" + targets)
                .find("a rotary axis B is measured by measure = \"rotary\""),
            std::string::npos);
  EXPECT_NE(error_of("[test.linear]\naxis = \"X\"\nmeasure = \"rotary\"\n" + targets)
                .find("measure = \"rotary\" measures a rotary axis (A, B, C), not X"),
            std::string::npos)
      << error_of("[test.linear]\naxis = \"X\"\nmeasure = \"rotary\"\n" + targets);
}

// The report's identity tables and the machine specification: read as written, and every
// mistake (a non-finite or non-positive limit, an unknown axis or diagnostic, a bad date, a
// by_length table out of order) refused with its place.
TEST(Config, ReadsTheCustomerBlockAndTheTolerances) {
  const auto c = parse_config(R"(
operator = "J. Smith"

[customer]
name = "ACME Precision"
site = "Plant 2"

[machine]
name = "VMC-1"
make = "Hermle"
model = "C 42"
serial_number = "42-0815"

[conditions]
controller_compensation = false
warm_up = "20 min at 50 % rapid"
load = "no workpiece"
state = "as found"

[devices.laser]
driver = "ids3010"
transport = "tcp 10.0.0.5:9090"
role = "laser"
serial_number = "IDS-1234"
certificate = "DAkkS 4711"
calibration_due = "2027-02-28"

[tolerances.X]
E_um = 10
A_um = 14.5
P_um = 15
Ps_um = 6
[[tolerances.X.by_length]]
up_to_mm = 500
A_um = 8
[[tolerances.X.by_length]]
up_to_mm = 1000
A_um = 12

[tolerances.XY]
G_um = 15
[tolerances.XY.diagnostics]
squareness = 20
backlash_X = 3
stick_slip_Y = 0.5
vibration = 0.3
)",
                              "m.toml");
  EXPECT_EQ(c.operator_name, "J. Smith");
  EXPECT_EQ(c.customer.name, "ACME Precision");
  EXPECT_EQ(c.customer.site, "Plant 2");
  EXPECT_EQ(c.machine_make, "Hermle");
  EXPECT_EQ(c.machine_model, "C 42");
  EXPECT_EQ(c.machine_serial, "42-0815");
  EXPECT_EQ(c.conditions.controller_compensation, false);
  EXPECT_EQ(c.conditions.state, "as found");
  EXPECT_EQ(c.device_for("laser")->serial_number, "IDS-1234");
  EXPECT_EQ(c.device_for("laser")->certificate, "DAkkS 4711");
  EXPECT_EQ(c.device_for("laser")->calibration_due, "2027-02-28");
  const auto& x = c.axis_tolerances.at("X");
  EXPECT_EQ(x.limits.E_um, 10.0);
  EXPECT_EQ(x.limits.A_um, 14.5);
  EXPECT_FALSE(x.limits.R_um.has_value());
  EXPECT_EQ(x.limits.P_um, 15.0);  // VDI/DGQ 3441's limits beside ISO 230-2's (issue 30)
  EXPECT_EQ(x.limits.Ps_um, 6.0);
  EXPECT_FALSE(x.limits.U_um.has_value());
  ASSERT_EQ(x.by_length.size(), 2u);
  EXPECT_EQ(x.by_length[0].first, 500.0);
  EXPECT_EQ(x.by_length[1].second.A_um, 12.0);
  const auto& xy = c.plane_tolerances.at("XY");
  EXPECT_EQ(xy.G_um, 15.0);
  EXPECT_EQ(xy.diagnostics.at("backlash_X"), 3.0);
  EXPECT_EQ(xy.diagnostics.at("stick_slip_Y"), 0.5);
  EXPECT_EQ(xy.diagnostics.at("vibration"), 0.3);
}

// A rotary axis's limits are in arcsec, the unit of its values, named in each key (issue 36:
// the rotary run's verdict said "No tolerance configured", [tolerances.C] was refused); a
// length limit on a rotary axis, an angle limit on a linear one, are refused at their line.
TEST(Config, RotaryAxisLimitsInArcsec) {
  const auto c = cal::daq::parse_config(
      "[tolerances.C]\nE_arcsec = 12\nB_arcsec = 3.5\nPs_arcsec = 4\n[tolerances.X]\nE_um = 10\n",
      "m.toml");
  const auto& cl = c.axis_tolerances.at("C").limits;
  EXPECT_EQ(cl.E_arcsec, 12.0);
  EXPECT_EQ(cl.B_arcsec, 3.5);
  EXPECT_EQ(cl.Ps_arcsec, 4.0);
  EXPECT_FALSE(cl.E_um.has_value());
  EXPECT_FALSE(cl.R_arcsec.has_value());
  EXPECT_EQ(c.axis_tolerances.at("X").limits.E_um, 10.0);
  EXPECT_EQ(error_of("[tolerances.C]\nR_arcsec = 2\nE_um = 3\n"),
            "machine.toml:3:8: key 'tolerances.C.E_um': a rotary axis's limits are angles in "
            "arcsec (E_arcsec, R_arcsec, B_arcsec, A_arcsec, M_arcsec; P_arcsec, Pa_arcsec, "
            "Ps_arcsec, U_arcsec), not lengths; only its location errors take um and urad "
            "(location_um, location_urad; docs/config.md)");
  EXPECT_NE(error_of("[tolerances.A]\nangular_urad = 3\n")
                .find("machine.toml:2:16: key 'tolerances.A.angular_urad': a rotary axis's"),
            std::string::npos);
  EXPECT_EQ(error_of("[tolerances.Y]\nE_arcsec = 3\n"),
            "machine.toml:2:12: key 'tolerances.Y.E_arcsec': arcsec and location limits are a "
            "rotary axis's (A, B, C); a linear axis's are in um (E_um, R_um, B_um, A_um, M_um, "
            "...; docs/config.md)");
  EXPECT_NE(error_of("[tolerances.X]\nlocation_um = 3\n")
                .find("machine.toml:2:15: key 'tolerances.X.location_um': arcsec and location "
                      "limits are a rotary axis's"),
            std::string::npos);
  EXPECT_NE(error_of("[[tolerances.X.by_length]]\nup_to_mm = 500\nA_arcsec = 8\n")
                .find("machine.toml:3:12: key 'tolerances.X.by_length.A_arcsec': arcsec and "
                      "location limits"),
            std::string::npos);
  EXPECT_NE(error_of("[tolerances.B]\nE_arcsec = 3\n[[tolerances.B.by_length]]\nup_to_mm = 90\n"
                     "E_arcsec = 2\n")
                .find("key 'tolerances.B.by_length': a rotary axis's limits do not depend on a "
                      "travel"),
            std::string::npos);
  EXPECT_EQ(
      error_of("[tolerances.C]\nE_arcsec = 0\n"),
      "machine.toml:2:12: key 'tolerances.C.E_arcsec': a limit is a finite number > 0, not 0");
}

TEST(Config, RefusesBadLimitsDatesAndNames) {
  // nan and inf are refused where every number of the file is read (issue 15).
  EXPECT_EQ(error_of("[tolerances.X]\nE_um = nan\n"),
            "machine.toml:2:8: key 'tolerances.X.E_um': nan is not a finite number");
  EXPECT_EQ(error_of("[tolerances.X]\nA_um = inf\n"),
            "machine.toml:2:8: key 'tolerances.X.A_um': inf is not a finite number");
  EXPECT_EQ(error_of("[tolerances.X]\nR_um = 0\n"),
            "machine.toml:2:8: key 'tolerances.X.R_um': a limit is a finite number > 0, not 0");
  EXPECT_EQ(error_of("[tolerances.X]\nF_um = 3\n"),
            "machine.toml:2:8: key 'tolerances.X.F_um': unknown key (a typo?)");
  EXPECT_EQ(error_of("[tolerances.Q]\nE_um = 3\n"),
            "machine.toml:1:1: key 'tolerances.Q': expected an axis (X, Y, Z; A, B, C) or a "
            "plane (XY, YZ, ZX)");
  EXPECT_NE(
      error_of("[tolerances.XY.diagnostics]\nbacklash_Z = 3\n")
          .find("key 'tolerances.XY.diagnostics.backlash_Z': not a diagnostic of a circle in XY"),
      std::string::npos);
  EXPECT_NE(
      error_of("[test.circle]\nstandard = \"asme-b5.54\"\n")
          .find("key 'test.circle.standard': circular standard 'asme-b5.54': only the scopes"),
      std::string::npos);
  EXPECT_NE(error_of("[tolerances.ZX.diagnostics]\nstick_slip_Y = 3\n")
                .find("not a diagnostic of a circle in ZX"),
            std::string::npos);
  EXPECT_NE(error_of("[[tolerances.X.by_length]]\nup_to_mm = 500\nA_um = 8\n"
                     "[[tolerances.X.by_length]]\nup_to_mm = 300\nA_um = 6\n")
                .find("entries must ascend in up_to_mm"),
            std::string::npos);
  EXPECT_EQ(error_of("[devices.l]\ndriver = \"ids3010\"\ntransport = \"tcp a:1\"\n"
                     "calibration_due = \"2027-02-30\"\n"),
            "machine.toml:4:19: key 'devices.l.calibration_due': '2027-02-30' is not a date "
            "YYYY-MM-DD");
  EXPECT_EQ(error_of("[conditions]\nstate = \"as new\"\n"),
            "machine.toml:2:9: key 'conditions.state': 'as new' is not one of: as found, as left");
  EXPECT_EQ(error_of("[customer]\nname = \"A\"\ncity = \"B\"\n"),
            "machine.toml:3:8: key 'customer.city': unknown key (a typo?)");
}

TEST(Config, MissingFileIsNamed) {
  try {
    cal::daq::load_config("/nonexistent/machine.toml");
    FAIL();
  } catch (const cal::InputError& e) {
    EXPECT_STREQ(e.what(), "/nonexistent/machine.toml: cannot open");
  }
}

TEST(Config, BallbarSetKeys) {
  const auto c = cal::daq::parse_config(R"(
[test.circle]
planes = ["XY", "ZX", "YZ"]
feeds_mm_per_min = [500, 2000]
radii_mm = [100, 150]
partial_arc_deg = 200
partial_overshoot_deg = 5
bar = "QC20-1234"
)",
                                        "m.toml");
  ASSERT_TRUE(c.circle);
  EXPECT_EQ(c.circle->planes, (std::vector<std::string>{"XY", "ZX", "YZ"}));
  EXPECT_EQ(c.circle->feeds_mm_per_min, (std::vector<double>{500, 2000}));
  EXPECT_EQ(c.circle->radii_mm, (std::vector<double>{100, 150}));
  EXPECT_EQ(c.circle->partial_arc_deg, 200);
  EXPECT_EQ(c.circle->partial_overshoot_deg, 5);
  EXPECT_EQ(c.circle->bar, "QC20-1234");
  // Each word of the list refused at its own position.
  EXPECT_EQ(error_of("[test.circle]\nplanes = [\"XY\", \"XZ\"]\n"),
            "machine.toml:2:17: key 'test.circle.planes': 'XZ' is not one of: XY, YZ, ZX");
  EXPECT_EQ(error_of("[test.circle]\nplanes = [\"XY\", \"XY\"]\n"),
            "machine.toml:2:17: key 'test.circle.planes': 'XY' given twice");
  EXPECT_EQ(error_of("[test.circle]\nplanes = []\n"),
            "machine.toml:2:10: key 'test.circle.planes': expected an array of planes, e.g. "
            "[\"XY\", \"ZX\", \"YZ\"]");
  EXPECT_NE(error_of("[test.circle]\nplane = \"XY\"\nplanes = [\"XY\"]\n").find("not both"),
            std::string::npos);
  EXPECT_NE(error_of("[test.circle]\nfeeds_mm_per_min = [500, -1]\n").find("-1 must be > 0"),
            std::string::npos);
  EXPECT_NE(
      error_of("[test.circle]\npartial_arc_deg = 170\n").find("170 must be within 180 .. 360 deg"),
      std::string::npos);
  EXPECT_NE(error_of("[test.circle]\nfeed_in_mm = nan\n").find("feed_in_mm"), std::string::npos);
  EXPECT_NE(error_of("[test.circle]\nbar = \"A\\u0007\"\n").find("control characters"),
            std::string::npos);
  EXPECT_NE(error_of("[test.circle]\nradii_mm = [100, 150]\ncalibrated_radius_mm = 100.001\n")
                .find("one calibrated length cannot serve several radii"),
            std::string::npos);
}

}  // namespace
