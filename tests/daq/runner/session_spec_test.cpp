// The instruments of a capture header: today's entries round-trip, entries written before the
// option tables (tests/data/captures/legacy_instruments.json) rebuild the same settings, and a
// header this build cannot honour is refused naming the instrument and what is wrong.
#include "session_spec.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "cal/analysis/error.hpp"
#include "linear_run.hpp"

namespace {

using nlohmann::json;

json legacy() {
  std::ifstream in(CALDAQ_CAPTURES_DIR "/legacy_instruments.json");
  return json::parse(in);
}

TEST(SessionSpec, LegacyEntriesGiveTheSettingsTheyWereRecordedWith) {
  const auto j = legacy();
  std::vector<daq::InstrumentSpec> s;
  for (const auto& e : j) s.push_back(daq::instrument_spec_from_json(e));
  ASSERT_EQ(s.size(), 6u);
  // ids_axes [false, true, false]: axis 1.
  EXPECT_EQ(s[0].options.integers("axes"), std::vector<std::int64_t>{1});
  EXPECT_TRUE(s[0].options.boolean("environment"));
  // The gauge: "?\r" polled, degC, its range.
  EXPECT_EQ(s[2].options.text("request"), "?\r");
  EXPECT_EQ(s[2].options.text("unit"), "degC");
  EXPECT_EQ(s[2].options.number("min_si"), -40.0);
  EXPECT_EQ(s[2].options.number("max_si"), 150.0);
  EXPECT_EQ(s[3].options.text("family"), "ds75");
  EXPECT_EQ(s[4].options.text("key"), "Xcom");
  EXPECT_EQ(s[4].options.text("unit"), "mm");
  EXPECT_EQ(s[4].test_axis, 0);
  // The halsampler read sample numbers then; its test axis was Y, column 2, inches.
  EXPECT_TRUE(s[5].options.boolean("tagged"));
  EXPECT_EQ(s[5].options.integer("column"), 2);
  EXPECT_EQ(s[5].options.text("unit"), "in");
  EXPECT_EQ(s[5].test_axis, 1);
  // The gauge's unit of a position feed's entry is not the feed's.
  EXPECT_EQ(s[1].options.text("checksum"), "none");
}

TEST(SessionSpec, TodaysEntriesRoundTrip) {
  for (const auto& e : legacy()) {
    const auto s = daq::instrument_spec_from_json(e);
    auto t = s;
    t.serial_number = "SN 4711";
    t.calibration_due = "2027-03-31";
    const auto back = daq::instrument_spec_from_json(daq::to_json(t));
    EXPECT_EQ(back.driver, s.driver);
    EXPECT_EQ(back.role, s.role);
    EXPECT_EQ(back.transport, s.transport);
    EXPECT_EQ(back.test_axis, s.test_axis);
    EXPECT_EQ(back.options.values(), s.options.values()) << s.driver;
    EXPECT_EQ(back.serial_number, "SN 4711");
    EXPECT_EQ(back.calibration_due, "2027-03-31");
  }
}

std::string error_of(const json& j) {
  try {
    daq::instrument_spec_from_json(j);
  } catch (const cal::InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(SessionSpec, AHeaderThisBuildCannotHonourIsRefusedByName) {
  EXPECT_EQ(error_of({{"device", 3}, {"driver", "xl80"}, {"options", json::object()}}),
            "capture header: instrument 3: driver 'xl80' is not in this build (it has: ids3010, "
            "ptu300, gauge, temper, halsampler, shdr)");
  EXPECT_EQ(error_of({{"device", 2}, {"driver", "gauge"}, {"options", {{"dither", true}}}}),
            "capture header: instrument 2 (gauge): option 'dither' is not known to this build");
  EXPECT_EQ(error_of({{"device", 2}, {"driver", "gauge"}, {"options", {{"unit", "furlong"}}}}),
            "capture header: instrument 2 (gauge): option 'unit' = \"furlong\": 'furlong' is not "
            "one of: mm, um, in, m, degC, urad, mrad, mm/m, arcsec");
}

TEST(MaterialSensors, EachUsedChannelIsItsOwnSensorNeverMerged) {
  // A serial thermometer (one sensor, its channel unlisted), a TEMPer2 read on both channels,
  // a TEMPer2 read on its probe only: sensors 0; 1, 2; 3.
  const daq::MaterialSensors m(3, {{}, {0, 1}, {1}});
  EXPECT_EQ(m.count(), 4);
  EXPECT_EQ(m.sensor(0, 0), 0);
  EXPECT_EQ(m.sensor(0, 5), 0);  // unlisted: whatever its channel
  EXPECT_EQ(m.sensor(1, 0), 1);  // the stick ...
  EXPECT_EQ(m.sensor(1, 1), 2);  // ... and the probe are two series
  EXPECT_EQ(m.sensor(2, 1), 3);
  EXPECT_EQ(m.sensor(2, 0), -1);  // the stick of the third is not used
  EXPECT_EQ(m.sensor(3, 0), -1);
}

}  // namespace
