// The model file with rotary axes (caldaq.model.v2): each location error lands where the model
// holds it, the component errors are functions of the angle, a v1 file still loads, writing and
// reading again gives the same model, and every malformed rotary axis is refused with the file
// and the key named.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "cal/analysis/error.hpp"
#include "cal/analysis/rotary.hpp"
#include "model/model_file.hpp"

namespace {

namespace mdl = cal::daq::model;
namespace kin = cal::kinematics;
using cal::InputError;

std::string file(const std::string& rotary, const std::string& schema = "caldaq.model.v2") {
  return R"({"schema": ")" + schema + R"(",
  "units": {"position": "mm", "translation": "um", "angle": "urad"},
  "topology": "FXYZ", "rotary": )" +
         rotary + "}";
}

const std::string kTrunnion = R"([
  {"axis": "C", "side": "table", "pivot_mm": [1, 2, -250], "range_deg": [0, 360],
   "location": {"E_X0C": 12.0, "E_Y0C": -5.0,
                "E_A0C": {"value": 20.0, "uncertainty": 2.5, "source": {"run": 3}},
                "E_B0C": -8.0},
   "components": {"E_ZC": {"polynomial": [0, 0, 1e-5]},
                  "E_CC": {"table": {"angle_deg": [0, 90, 180, 270, 360],
                                     "value": [0, 10, 0, -10, 0]}}}},
  {"axis": "A", "side": "table", "pivot_mm": [0, 0, -250], "range_deg": [-90, 90],
   "location": {"E_Y0A": 7.0, "E_Z0A": -15.0, "E_C0A": 30.0}}])";

void expect_refused(const std::string& text, const std::string& key, const std::string& what) {
  try {
    mdl::parse(text, "r.json");
    FAIL() << "not refused: " << text;
  } catch (const InputError& e) {
    const std::string w = e.what();
    EXPECT_EQ(w.rfind("r.json: ", 0), 0u) << w;
    EXPECT_NE(w.find(key), std::string::npos) << "key " << key << " not in: " << w;
    EXPECT_NE(w.find(what), std::string::npos) << "'" << what << "' not in: " << w;
  }
}

TEST(ModelFileRotary, EachLocationErrorLandsInItsPlace) {
  const auto m = mdl::parse(file(kTrunnion), "r.json");
  ASSERT_EQ(m.rotary.size(), 2u);
  const auto& c = m.rotary[0];
  const auto& a = m.rotary[1];
  EXPECT_EQ(c.axis.letter, kin::RotaryLetter::c);
  EXPECT_EQ(a.axis.letter, kin::RotaryLetter::a);
  EXPECT_EQ(c.axis.side, kin::Side::table);
  EXPECT_EQ(c.axis.pivot_mm, (kin::Vec3{1, 2, -250}));
  // C: E_X0C, E_Y0C are positions in X and Y; E_A0C, E_B0C rotations about X and Y.
  EXPECT_EQ(c.axis.location_position_um, (kin::Vec3{12, -5, 0}));
  EXPECT_EQ(c.axis.location_orientation_urad, (kin::Vec3{20, -8, 0}));
  // A: E_Y0A, E_Z0A positions in Y and Z; E_B0A, E_C0A rotations about Y and Z.
  EXPECT_EQ(a.axis.location_position_um, (kin::Vec3{0, 7, -15}));
  EXPECT_EQ(a.axis.location_orientation_urad, (kin::Vec3{0, 0, 30}));
  EXPECT_TRUE(c.location[2].given);
  ASSERT_TRUE(c.location[2].uncertainty.has_value());
  EXPECT_EQ(*c.location[2].uncertainty, 2.5);
  EXPECT_FALSE(c.location[0].uncertainty.has_value());
  EXPECT_FALSE(a.location[2].given);  // E_B0A not in the file
  EXPECT_EQ(c.range_deg, (std::array<double, 2>{0, 360}));
  // Component errors are functions of the angle in degrees.
  EXPECT_DOUBLE_EQ(c.axis.motion.ec_urad(45.0), 5.0);
  EXPECT_DOUBLE_EQ(c.axis.motion.ez_um(100.0), 0.1);
  EXPECT_TRUE(c.components[5].given);
  EXPECT_FALSE(c.components[0].given);
  EXPECT_EQ(mdl::rotary_component_name(kin::RotaryLetter::c, 2), "E_ZC");
  const auto five = mdl::five_axis(m);
  ASSERT_EQ(five.rotary.size(), 2u);
  EXPECT_EQ(five.rotary[1].location_orientation_urad[2], 30.0);
}

// The model's tool error at C = 180 deg with only E_X0C: the table mirrored through a line
// 12 um off its nominal place moves the workpiece by 24 um under the tool (docs/kinematics.md).
TEST(ModelFileRotary, TheFileDrivesTheFiveAxisModel) {
  const auto m = mdl::parse(file(R"([{"axis": "C", "side": "table", "pivot_mm": [0, 0, 0],
    "range_deg": [0, 360], "location": {"E_X0C": 12}}])"),
                            "r.json");
  const std::array angles{180.0};
  const auto e = kin::five_axis_error(mdl::five_axis(m), {50, 0, -100}, angles, kin::Method::htm);
  EXPECT_NEAR(e.translation_um[0], 24.0, 1e-6);
  EXPECT_NEAR(e.translation_um[1], 0.0, 1e-6);
}

TEST(ModelFileRotary, VersionOneStillLoadsAndIsWrittenAsVersionOne) {
  const std::string v1 = R"({"schema": "caldaq.model.v1",
    "units": {"position": "mm", "translation": "um", "angle": "urad"}, "topology": "FXYZ",
    "components": {"E_XX": {"polynomial": [0, 0.01]}}})";
  const auto m = mdl::parse(v1, "v1.json");
  EXPECT_TRUE(m.rotary.empty());
  EXPECT_NE(mdl::to_json(m).find("\"schema\": \"caldaq.model.v1\""), std::string::npos);
  EXPECT_NO_THROW(mdl::require_no_rotary(m, "v1.json", "daq model compensate"));
  const auto r = mdl::parse(file(kTrunnion), "r.json");
  EXPECT_THROW(mdl::require_no_rotary(r, "r.json", "daq model compensate"), InputError);
}

TEST(ModelFileRotary, WritingAndReadingAgainGivesTheSameModel) {
  const auto a = mdl::parse(file(kTrunnion), "r.json");
  const std::string text = mdl::to_json(a);
  EXPECT_NE(text.find("\"schema\": \"caldaq.model.v2\""), std::string::npos);
  EXPECT_NE(text.find("\"uncertainty\": 2.5"), std::string::npos) << text;
  EXPECT_NE(text.find("\"angle_deg\""), std::string::npos) << text;
  const auto b = mdl::parse(text, "b.json");
  EXPECT_EQ(mdl::to_json(b), text);
  ASSERT_EQ(b.rotary.size(), 2u);
  EXPECT_EQ(b.rotary[1].axis.location_position_um, a.rotary[1].axis.location_position_um);
  for (double q : {0.0, 33.3, 359.0})
    EXPECT_EQ(a.rotary[0].axis.motion.ec_urad(q), b.rotary[0].axis.motion.ec_urad(q));
}

TEST(ModelFileRotary, MalformedRotaryAxesAreRefused) {
  const std::string c =
      R"("axis": "C", "side": "table", "pivot_mm": [0, 0, 0], "range_deg": [0, 360])";
  expect_refused(file("[{" + c + "}]", "caldaq.model.v1"), "rotary", "caldaq.model.v2");
  expect_refused(file("{}"), "rotary", "expected an array");
  expect_refused(file("[{" + c + "}, {" + c + "}]"), "rotary[1].axis", "a second C axis");
  expect_refused(file("[{" + c + "}, {" + c + "}, {" + c + "}]"), "rotary", "at most 2");
  expect_refused(
      file(R"([{"axis": "D", "side": "table", "pivot_mm": [0, 0, 0], "range_deg": [0, 1]}])"),
      "rotary[0].axis", "'D'");
  expect_refused(
      file(R"([{"axis": "C", "side": "head", "pivot_mm": [0, 0, 0], "range_deg": [0, 1]}])"),
      "rotary[0].side", "table or spindle");
  expect_refused(file(R"([{"axis": "C", "side": "table", "range_deg": [0, 1]}])"),
                 "rotary[0].pivot_mm", "missing");
  expect_refused(
      file(R"([{"axis": "C", "side": "table", "pivot_mm": [0, 0, 0], "range_deg": [90, 0]}])"),
      "rotary[0].range_deg", "max > min");
  expect_refused(
      file(R"([{"axis": "B", "side": "spindle", "pivot_mm": [0, 0, 0], "range_deg": [0, 90]},
                          {)" +
           c + "}]"),
      "rotary[1].side", "table axes first");
  // A location error along or about the axis's own direction is not one.
  expect_refused(file("[{" + c + R"(, "location": {"E_Z0C": 3}}])"), "rotary[0].location.E_Z0C",
                 "expected E_X0C, E_Y0C, E_A0C or E_B0C");
  expect_refused(file("[{" + c + R"(, "location": {"E_X0C": {"value": 1, "uncertainty": -1}}}])"),
                 "rotary[0].location.E_X0C.uncertainty", ">= 0");
  expect_refused(file("[{" + c + R"(, "location": {"E_X0C": {"u": 1}}}])"),
                 "rotary[0].location.E_X0C.u", "unknown key");
  expect_refused(file("[{" + c + R"(, "location": {"E_A0C": 2e6}}])"), "rotary[0].location.E_A0C",
                 "beyond");
  expect_refused(file("[{" + c + R"(, "components": {"E_XA": {"polynomial": [1]}}}])"),
                 "rotary[0].components.E_XA", "not a component error of the C axis");
  expect_refused(
      file("[{" + c +
           R"(, "components": {"E_CC": {"table": {"position_mm": [0, 360], "value": [0, 0]}}}}])"),
      "rotary[0].components.E_CC.table", "angle_deg");
  expect_refused(
      file("[{" + c +
           R"(, "components": {"E_CC": {"table": {"angle_deg": [0, 180], "value": [0, 0]}}}}])"),
      "rotary[0].components.E_CC.table", "covers 0 .. 180 deg but the range is 0 .. 360");
  expect_refused(
      file("[{" + c + R"(, "components": {"E_ZC": {"polynomial": [0, 0, 0, 0, 1e3]}}}])"),
      "rotary[0].components.E_ZC.polynomial", "beyond");
  expect_refused(file("[{" + c + R"(, "spin": 1}])"), "rotary[0].spin", "unknown key");
}

}  // namespace
