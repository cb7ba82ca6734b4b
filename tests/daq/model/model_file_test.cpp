// The model file caldaq.model.v1: what a file says is what is read (values, conventions,
// carriers), writing and reading again gives the same model, and every malformed or
// inconsistent file is refused with the file and the key named.
#include "model/model_file.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include "cal/analysis/error.hpp"

namespace {

namespace mdl = cal::daq::model;
namespace kin = cal::kinematics;
using cal::InputError;

const std::string kHead = R"("schema": "caldaq.model.v1",
  "units": {"position": "mm", "translation": "um", "angle": "urad"},
  "topology": "YFXZ")";

std::string file(const std::string& body) {
  return "{" + kHead + (body.empty() ? "" : ",\n" + body) + "}";
}

// The message names the file and the key.
void expect_refused(const std::string& text, const std::string& key, const std::string& what = "") {
  try {
    mdl::parse(text, "m.json");
    FAIL() << "not refused: " << text;
  } catch (const InputError& e) {
    const std::string w = e.what();
    EXPECT_EQ(w.rfind("m.json: ", 0), 0u) << w;
    EXPECT_NE(w.find(key), std::string::npos) << "key " << key << " not in: " << w;
    if (!what.empty()) {
      EXPECT_NE(w.find(what), std::string::npos) << w;
    }
  }
}

TEST(ModelFile, ReadsWhatTheFileSays) {
  const auto m = mdl::parse(file(R"("machine": "test",
    "tool_offset_mm": [1, 2, -100], "table_offset_mm": [-10, 0, 5],
    "travel_mm": {"X": [0, 500], "Y": [0, 400], "Z": [-300, 0]},
    "components": {
      "E_XX": {"polynomial": [0, 0.01]},
      "E_YX": {"table": {"position_mm": [0, 250, 500], "value": [0, 2, 0]}, "source": {"run": 12}}
    },
    "squareness": {
      "E_C0Y": {"iso230_1_urad": 12.5, "compensated_by": "X", "method": "diagonal",
                "placement": "global"},
      "E_B0Z": {"angle_over_90_urad": 8.0},
      "E_A0Z": {"angle_over_90_urad": -3.0, "placement": "local", "position_mm": [1, 2, 3]}
    })"),
                            "m.json");
  EXPECT_EQ(m.name, "test");
  EXPECT_EQ(m.machine.topology, kin::Topology::yfxz);
  EXPECT_EQ(m.machine.tool_offset_mm, (kin::Vec3{1, 2, -100}));
  EXPECT_EQ(m.machine.table_offset_mm, (kin::Vec3{-10, 0, 5}));
  EXPECT_DOUBLE_EQ(m.machine.axes[kin::X].ex_um(300.0), 3.0);  // 0.01 * 300
  EXPECT_DOUBLE_EQ(m.machine.axes[kin::X].ey_um(125.0), 1.0);  // halfway to 2
  EXPECT_TRUE(m.components[static_cast<std::size_t>(kin::Component::E_YX)].given);
  EXPECT_EQ(m.components[static_cast<std::size_t>(kin::Component::E_YX)].source.json,
            R"({"run":12})");
  EXPECT_FALSE(m.components[static_cast<std::size_t>(kin::Component::E_ZX)].given);
  // Conventions: E_C0Y as stated; E_B0Z from "angle over 90" changes sign (+8 -> -8); E_A0Z
  // keeps it (-3 -> -3).
  EXPECT_DOUBLE_EQ(m.machine.squareness.c0y_urad, 12.5);
  EXPECT_DOUBLE_EQ(m.machine.squareness.b0z_urad, -8.0);
  EXPECT_DOUBLE_EQ(m.machine.squareness.a0z_urad, -3.0);
  EXPECT_EQ(m.carriers.xy, kin::X);
  EXPECT_EQ(m.carriers.xz, kin::Z);  // the default
  EXPECT_EQ(m.squareness[0].method, "diagonal");
  EXPECT_EQ(m.squareness[1].stated_as, "angle_over_90_urad");
  ASSERT_TRUE(m.squareness[2].position_mm.has_value());
  EXPECT_EQ(*m.squareness[2].position_mm, (kin::Vec3{1, 2, 3}));
}

TEST(ModelFile, WritingAndReadingAgainGivesTheSameModel) {
  const auto a = mdl::parse(file(R"("travel_mm": {"X": [0, 500], "Y": [0, 400], "Z": [-300, 0]},
    "components": {"E_XX": {"polynomial": [0.1, 0.012345678901234567, -3e-9]},
                   "E_CY": {"table": {"position_mm": [0, 200, 400], "value": [1.5, -0.25, 3]}}},
    "squareness": {"E_B0Z": {"angle_over_90_urad": 8.0, "compensated_by": "X"}},
    "provenance": {"by": "test"})"),
                            "a.json");
  const std::string text = mdl::to_json(a);
  const auto b = mdl::parse(text, "b.json");
  EXPECT_EQ(mdl::to_json(b), text);
  // Written in the model's convention: E_B0Z = -8 as iso230_1_urad.
  EXPECT_NE(text.find("\"iso230_1_urad\": -8.0"), std::string::npos) << text;
  for (double q : {0.0, 123.4, 400.0}) {
    EXPECT_EQ(a.machine.axes[kin::X].ex_um(q), b.machine.axes[kin::X].ex_um(q));  // bit for bit
    EXPECT_EQ(a.machine.axes[kin::Y].ec_urad(q), b.machine.axes[kin::Y].ec_urad(q));
  }
  EXPECT_EQ(b.carriers.xz, kin::X);
  EXPECT_EQ(b.machine.squareness.b0z_urad, -8.0);
  // Through a file on disk.
  const auto path = std::filesystem::temp_directory_path() / "caldaq_model_file_test.json";
  mdl::write(b, path.string());
  EXPECT_EQ(mdl::to_json(mdl::read(path.string())), text);
  std::filesystem::remove(path);
}

TEST(ModelFile, MalformedAndInconsistentFilesAreRefused) {
  expect_refused("{\"schema\": ", "not valid JSON");
  expect_refused("[1, 2]", "expected a JSON object");
  expect_refused(R"({"schema": "caldaq.model.v3"})", "schema", "caldaq.model.v1 nor caldaq.model.v2");
  expect_refused(file(R"("topology": "FXYZ")"), "topology", "twice");  // duplicate key
  expect_refused(R"({"schema": "caldaq.model.v1", "topology": "FXYZ",
    "units": {"position": "mm", "translation": "nm", "angle": "urad"}})",
                 "units.translation", "'nm'");
  expect_refused(R"({"schema": "caldaq.model.v1", "units": {"position": "mm", "translation": "um",
    "angle": "urad"}, "topology": "FXXZ"})",
                 "topology");
  expect_refused(file(R"("colour": "red")"), "colour", "unknown key");
  expect_refused(file(R"("components": {"E_QX": {"polynomial": [1]}})"), "components.E_QX");
  expect_refused(file(R"("components": {"ECX": {"polynomial": [1]}})"), "components.ECX", "E_CX");
  expect_refused(file(R"("components": {"E_XX": {"polynomial": [1], "table": {}}})"),
                 "components.E_XX", "exactly one");
  expect_refused(file(R"("components": {"E_XX": {"polynomial": [1, "2"]}})"),
                 "components.E_XX.polynomial[1]", "expected a number");
  expect_refused(file(R"("components": {"E_XX": {"polynomial": [1e999]}})"), "1e999",
                 "not valid JSON");  // out of range for a double: refused, never infinity
  expect_refused(
      file(R"("components": {"E_YY": {"table": {"position_mm": [0, 0], "value": [1, 2]}}})"),
      "components.E_YY.table", "increasing");
  expect_refused(
      file(R"("components": {"E_YY": {"table": {"position_mm": [0, 1, 2], "value": [1, 2]}}})"),
      "components.E_YY.table");
  expect_refused(file(R"("travel_mm": {"X": [0, 500], "Y": [0, 400], "Z": [-300, 0]},
    "components": {"E_YY": {"table": {"position_mm": [0, 300], "value": [1, 2]}}})"),
                 "components.E_YY.table", "travel");
  expect_refused(file(R"("travel_mm": {"X": [0, 500], "Y": [400, 0], "Z": [-300, 0]})"),
                 "travel_mm.Y");
  expect_refused(file(R"("squareness": {"E_C0Y": {"iso230_1_urad": 1, "angle_over_90_urad": 1}})"),
                 "squareness.E_C0Y", "exactly one");
  expect_refused(file(R"("squareness": {"E_C0Y": {"iso230_1_urad": 1, "compensated_by": "Z"}})"),
                 "squareness.E_C0Y.compensated_by", "XY");
  expect_refused(file(R"("squareness": {"E_A0Z": {"iso230_1_urad": 1, "placement": "local"}})"),
                 "squareness.E_A0Z", "position_mm");
  expect_refused(file(R"("squareness": {"E_B0Y": {"iso230_1_urad": 1}})"), "squareness.E_B0Y");
  expect_refused(file(R"("tool_offset_mm": [0, 0])"), "tool_offset_mm", "3");
  expect_refused(file(R"("note": [1])"), "note", "expected a string");
  expect_refused(file(R"("components": {"E_XX": {"polynomial": [1], "note": 2}})"),
                 "components.E_XX.note");
  expect_refused("{\"schema\": \"caldaq.model.v1\", \"machine\": \"\xff\"}", "not valid JSON");
  EXPECT_THROW(mdl::read("/nonexistent/model.json"), InputError);
}

}  // namespace
