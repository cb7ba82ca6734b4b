// The set-up of the operator's page (serve/setup_form.hpp): a configuration survives the trip
// set-up -> TOML -> loader unchanged; the loader's problems come back keyed by the field at
// fault, several at once; what the text must look like is written out here by hand.
#include "serve/setup_form.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

#include "cal/analysis/error.hpp"

namespace {

using daq::serve::check_setup;
using daq::serve::setup_of;
using daq::serve::setup_toml;
using nlohmann::json;

// Every table of docs/config.md, with values away from the defaults.
constexpr const char* kFull = R"(campaign = "2026-11 annual"
operator = "J. Smith"
[customer]
name = "ACME \"Precision\" Ltd"
site = "Plant 2\nhall B"
[machine]
name = "VMC-1"
description = "3-axis vertical machining centre"
make = "Hermle"
model = "C 42"
serial_number = "42-0815"
topology = "YFXZ"
tool_offset_mm = [0, 0, 120]
table_offset_mm = [10, -5, 0]
[conditions]
controller_compensation = false
warm_up = "20 min"
state = "as found"
[devices.laser]
driver = "ids3010"
transport = "tcp 192.168.1.5:9090"
axes = [0, 2]
role = "laser"
serial_number = "IDS-1234"
calibration_due = "2027-02-28"
[devices.air]
driver = "ptu300"
transport = "serial /dev/ttyUSB0 4800 7E1"
poll_s = 0.5
role = "air"
[devices.table]
driver = "gauge"
transport = "serial /dev/ttyUSB1 9600 8N1"
request = "?\r"
pattern = 'T=([-0-9.]+)'
unit = "degC"
role = "material"
[devices.position]
driver = "shdr"
transport = "tcp 192.168.1.20:7878"
key = "Xact"
role = "position"
origin = "simulated"
[environment]
equation = "edlen"
stale_after_s = 20
on_stale = "fallback"
fallback_temperature_degc = 21
expansion_ppm_per_k = 11.7
[trigger]
tolerance_um = 2
dwell_s = 1.2
window_mm = 0.3
[test.linear]
axis = "Y"
first_mm = -10
last_mm = 490
count = 11
random_fraction = 0.25
cycle = "pendulum"
runs = 5
bidirectional = false
overrun_mm = 4
feed_mm_per_min = 3000
dwell_s = 3.5
standard = "vdi3441"
[test.circle]
plane = "ZX"
radius_mm = 150
feed_mm_per_min = 500
sample_rate_hz = 250
overshoot_deg = 30
centre_mm = [1, 2, 3]
calibrated_radius_mm = 150.0012
[tolerances.Y]
E_um = 10
B_um = 3.5
[[tolerances.Y.by_length]]
up_to_mm = 500
E_um = 8
[tolerances.ZX]
G_um = 15
[tolerances.ZX.diagnostics]
squareness = 20
backlash_Z = 3
)";

TEST(SetupForm, AConfigurationSurvivesTheTripThroughTheForm) {
  const auto original = cal::daq::parse_config(kFull, "full.toml");
  const json setup = setup_of(original);
  const auto text = setup_toml(setup);
  const auto again = cal::daq::parse_config(text, "again.toml");
  EXPECT_EQ(setup_of(again), setup) << text;
  // Spot checks against the file itself, not against the code's own output.
  EXPECT_EQ(again.customer.name, "ACME \"Precision\" Ltd");
  EXPECT_EQ(again.customer.site, "Plant 2\nhall B");
  // The kinematic chain and its offsets (the volumetric model's), as the file gives them: a
  // set-up applied from the page lost them and the page's model asked for --topology.
  EXPECT_EQ(again.machine_topology, "YFXZ");
  EXPECT_EQ(again.machine_tool_offset_mm, (std::array<double, 3>{0, 0, 120}));
  EXPECT_EQ(again.machine_table_offset_mm, (std::array<double, 3>{10, -5, 0}));
  EXPECT_EQ(again.devices.size(), 4u);
  // A simulated twin stays one through the page's form (else a run of the simulated shop set
  // up on the page would be stored as measured on real instruments).
  EXPECT_EQ(again.device_for("position")->origin, "simulated");
  EXPECT_EQ(again.device_for("laser")->origin, "real");
  // The drivers' own options (their registry tables) come through with the values given.
  EXPECT_EQ(again.device_for("material")->options.text("request"), "?\r");
  EXPECT_EQ(again.device_for("material")->options.text("pattern"), "T=([-0-9.]+)");
  EXPECT_EQ(again.device_for("laser")->options.integers("axes"), (std::vector<std::int64_t>{0, 2}));
  EXPECT_EQ(again.linear->count, 11);
  EXPECT_FALSE(again.linear->interval_mm);
  EXPECT_EQ(again.linear->cycle, "pendulum");
  EXPECT_FALSE(again.linear->bidirectional);
  EXPECT_DOUBLE_EQ(again.circle->calibrated_radius_mm, 150.0012);
  EXPECT_EQ(again.circle->centre_mm, (std::vector<double>{1, 2, 3}));
  EXPECT_EQ(again.environment.on_stale, cal::daq::StalePolicy::fallback);
  ASSERT_EQ(again.axis_tolerances.at("Y").by_length.size(), 1u);
  EXPECT_DOUBLE_EQ(*again.axis_tolerances.at("Y").by_length[0].second.E_um, 8.0);
  EXPECT_DOUBLE_EQ(again.plane_tolerances.at("ZX").diagnostics.at("backlash_Z"), 3.0);
  EXPECT_FALSE(again.conditions.controller_compensation.value_or(true));
}

TEST(SetupForm, TheTextIsWhatAPersonWouldWrite) {
  json s{{"machine", {{"name", "M"}}},
         {"trigger", {{"dwell_s", 1.5}, {"window_mm", 0.05}}},
         {"test", {{"linear", {{"first_mm", 0}, {"last_mm", 100.0}, {"runs", 2}}}}}};
  const auto text = setup_toml(s);
  // Shortest exact numbers (0.05, not 0.050000000000000003); integers stay integers.
  EXPECT_NE(text.find("\ndwell_s = 1.5\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\nwindow_mm = 0.05\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\nlast_mm = 100.0\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\nruns = 2\n"), std::string::npos) << text;
  EXPECT_NE(text.find("\n[test.linear]\n"), std::string::npos) << text;
  // A field left empty (null) is left out: the loader's default.
  s["test"]["linear"]["runs"] = nullptr;
  EXPECT_EQ(setup_toml(s).find("runs"), std::string::npos);
}

TEST(SetupForm, HostileTextStaysOneString) {
  // Quotes, backslashes, a TOML table header and a control character in a name.
  json s{{"machine", {{"name", "x\" ]\n[devices.evil]\ndriver = \"ids3010\" \\"}}}};
  const auto check = check_setup(s);
  // The newline is refused by the loader (names have no control characters), keyed by field.
  ASSERT_EQ(check.problems.size(), 1u) << check.toml;
  EXPECT_EQ(check.problems[0].key, "machine.name");
  EXPECT_NE(check.problems[0].message.find("control characters"), std::string::npos);
  // Without the newline it is one name, read back exactly; no device appeared.
  s["machine"]["name"] = "x\" ] [devices.evil] driver = \"ids3010\" \\";
  const auto ok = check_setup(s);
  ASSERT_TRUE(ok.config) << ok.toml;
  EXPECT_EQ(ok.config->machine_name, "x\" ] [devices.evil] driver = \"ids3010\" \\");
  EXPECT_TRUE(ok.config->devices.empty());
}

TEST(SetupForm, EveryProblemIsFoundAndKeyedByItsField) {
  auto s = setup_of(cal::daq::parse_config(kFull, "full.toml"));
  s["test"]["linear"]["runs"] = 0;              // 1 .. 1000
  s["test"]["linear"]["feed_mm_per_min"] = -5;  // > 0
  s["trigger"]["dwell_s"] = "x";                // a number
  s["devices"]["air"]["poll_s"] = -1;           // >= 0
  s["test"]["circle"]["feed_mm_min"] = 1000;    // a typo
  const auto c = check_setup(s);
  EXPECT_FALSE(c.config);
  std::map<std::string, std::string> by_key;
  for (const auto& p : c.problems) by_key[p.key] = p.message;
  EXPECT_EQ(by_key.size(), 5u) << daq::serve::to_json(c).dump(1);
  EXPECT_EQ(by_key["test.linear.runs"], "0 must be within 1 .. 1000");
  EXPECT_EQ(by_key["test.linear.feed_mm_per_min"], "-5 must be > 0 and at most 200000 mm/min");
  EXPECT_EQ(by_key["trigger.dwell_s"], "expected a number");
  EXPECT_EQ(by_key["devices.air.poll_s"], "must be >= 0");
  EXPECT_EQ(by_key["test.circle.feed_mm_min"], "unknown key (a typo?)");
  // A problem of the table as a whole (the plan: last before first) is keyed by the table.
  auto t = setup_of(cal::daq::parse_config(kFull, "full.toml"));
  t["test"]["linear"]["last_mm"] = -20;
  const auto table = check_setup(t);
  ASSERT_EQ(table.problems.size(), 1u);
  EXPECT_EQ(table.problems[0].key, "test.linear");
}

TEST(SetupForm, TestsNeedTheirDevicesAndTransportsMustParse) {
  json s{{"machine", {{"name", "M"}}},
         {"devices",
          {{"laser",
            {{"driver", "ids3010"}, {"transport", "tcp 10.0.0.5:99999"}, {"role", "laser"}}}}},
         {"test",
          {{"linear", {{"first_mm", 0}, {"last_mm", 100}, {"count", 3}}},
           {"circle", {{"radius_mm", 100}}}}}};
  const auto c = check_setup(s);
  ASSERT_EQ(c.problems.size(), 1u);
  EXPECT_EQ(c.problems[0].key, "devices.laser.transport");
  EXPECT_NE(c.problems[0].message.find("65535"), std::string::npos) << c.problems[0].message;
  s["devices"]["laser"]["transport"] = "tcp 10.0.0.5:9090";
  const auto d = check_setup(s);
  EXPECT_TRUE(d.problems.empty());
  ASSERT_TRUE(d.linear.problem);  // the air station is missing
  EXPECT_NE(d.linear.problem->find("no device with role = \"air\""), std::string::npos);
  ASSERT_TRUE(d.circle.problem);
  EXPECT_NE(d.circle.problem->find("no device with role = \"ballbar\""), std::string::npos);
}

TEST(SetupForm, TheSavedFileIsReadByLoadConfig) {
  const auto setup = setup_of(cal::daq::parse_config(kFull, "full.toml"));
  const auto path = std::filesystem::temp_directory_path() / "caldaq-setup-form-test.toml";
  std::ofstream(path) << setup_toml(setup);
  EXPECT_EQ(setup_of(cal::daq::load_config(path)), setup);
  std::filesystem::remove(path);
}

TEST(SetupForm, ValuesTomlCannotHoldAreRefusedWithTheirPlace) {
  EXPECT_THROW(setup_toml(json::array()), cal::InputError);
  try {
    setup_toml(json{{"test", {{"circle", {{"centre_mm", {1, nullptr, 3}}}}}}});
    FAIL() << "a list with a null was written";
  } catch (const cal::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("test.circle.centre_mm"), std::string::npos) << e.what();
  }
  const auto c = check_setup(json{{"machine", "VMC"}});  // a table written as a string
  ASSERT_EQ(c.problems.size(), 1u);
  EXPECT_EQ(c.problems[0].key, "machine");
  EXPECT_EQ(c.problems[0].message, "expected a table");
}

}  // namespace
