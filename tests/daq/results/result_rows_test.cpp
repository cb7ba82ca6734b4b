// One presentation of each result (daq/src/results/result_rows.hpp, issue 30): numbers that
// never read "-0.000" on the terminal, ISO 230-2 values in the report grid's order, and the
// verdict of a VDI/DGQ 3441 evaluation against its own configured limits.
#include "result_rows.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "cal/analysis/circle.hpp"
#include "cal/analysis/iso230_2.hpp"
#include "circle_output.hpp"
#include "iso230_2_output.hpp"
#include "verdict.hpp"

namespace {

using nlohmann::json;
namespace iso = cal::iso230_2;

// The advice of each kind of diagnostic, word for word as the reports print it: a term of one
// axis names the axis (its key's last letter), a term of the plane does not; a value of the
// standard has none.
TEST(ResultRows, DiagnosticAdviceNamesTheAxisOfItsTerm) {
  EXPECT_EQ(daq::diagnostic_advice("backlash_X"),
            "check the X axis' backlash compensation and its drive (ball screw, nut)");
  EXPECT_EQ(daq::diagnostic_advice("lateral_play_Y"),
            "check the Y axis' guideway gibs and preload: it shifts sideways at reversal");
  EXPECT_EQ(daq::diagnostic_advice("reversal_spike_Z"),
            "tune the Z axis' reversal (friction) compensation and its servo gains");
  EXPECT_EQ(daq::diagnostic_advice("cyclic_X"),
            "check the X axis' ball screw and encoder for a periodic (pitch) error");
  EXPECT_EQ(daq::diagnostic_advice("straightness_Y"),
            "check the straightness of the Y axis' guideways (level, wear)");
  EXPECT_EQ(daq::diagnostic_advice("stick_slip_Z"),
            "check the Z axis' lubrication and friction compensation");
  EXPECT_EQ(daq::diagnostic_advice("squareness"),
            "check the squareness of the plane's axes (alignment, or the control's squareness "
            "compensation)");
  EXPECT_EQ(daq::diagnostic_advice("scale_mismatch"),
            "check the axes' pitch (scale) compensation and thermal growth of the screws");
  EXPECT_EQ(daq::diagnostic_advice("servo_mismatch"),
            "match the two axes' servo gains (position loop, feed-forward)");
  EXPECT_EQ(daq::diagnostic_advice("radius_error"),
            "check the bar's calibration and the axes' scale");
  EXPECT_EQ(daq::diagnostic_advice("vibration"),
            "look for the source of the vibration (spindle, fan, floor)");
  EXPECT_EQ(daq::diagnostic_advice("G_bi_um"), "");
  EXPECT_EQ(daq::diagnostic_advice("squareness_X"), "");  // no such term
}

TEST(ResultRows, NumbersNeverReadMinusZero) {
  EXPECT_EQ(daq::number_text(-0.0004), "0.000");
  EXPECT_EQ(daq::number_text(-0.0), "0.000");
  EXPECT_EQ(daq::number_text(-0.0006), "-0.001");
  EXPECT_EQ(daq::number_text(2.5, 1), "2.5");
  EXPECT_EQ(daq::signed_number_text(-0.0004), "0.000");
  EXPECT_EQ(daq::signed_number_text(0.0004), "0.000");
  EXPECT_EQ(daq::signed_number_text(1.5), "+1.500");
  EXPECT_EQ(daq::signed_number_text(-1.5), "-1.500");
}

// A document prints µm and °C where the terminal prints um and degC (the run quality, the
// uncertainty budget's models are caldaq's own sentences, written once for the terminal).
TEST(ResultRows, DocumentsPrintTheUnitsSymbols) {
  EXPECT_EQ(daq::units_html("ok: every stop within 0.168 um of its target's runs"),
            "ok: every stop within 0.168 µm of its target's runs");
  EXPECT_EQ(daq::units_html("L |T - 20 degC| u(alpha), 8 um/m, 3 urad"),
            "L |T - 20 °C| u(alpha), 8 µm/m, 3 µrad");
  // Only whole words: "umbra", "sum" and "drum/m" stay as they are.
  EXPECT_EQ(daq::units_html("umbra sum drum/m um"), "umbra sum drum/m µm");
}

// print_circle wrote "{:+9.3f}": a diagnostic or centre of -0.0001 printed as "-0.000".
TEST(ResultRows, PrintCircleNeverPrintsMinusZero) {
  cal::circle::Result r;
  r.iso.G_bi_um = 5.0;
  r.diagnostics.push_back({.key = "backlash_X",
                           .name = "Backlash X",
                           .value = -0.0001,
                           .unit = "um",
                           .pv_um = 0.0002,
                           .share_pct = -0.01,
                           .g_reduction_um = -0.0002});
  r.centre_u = {.key = "centre_X", .name = "Centre offset X", .value = -0.0003, .unit = "um"};
  r.centre_v = {.key = "centre_Y", .name = "Centre offset Y", .value = 0.0, .unit = "um"};
  r.iso.centre_u_um = -0.0003;
  testing::internal::CaptureStdout();
  daq::print_circle(r, 100.0, "XY", 1000.0);
  const std::string out = testing::internal::GetCapturedStdout();
  EXPECT_EQ(out.find("-0.000"), std::string::npos) << out;
  EXPECT_EQ(out.find("-0.0 %"), std::string::npos) << out;
  EXPECT_NE(out.find("Backlash X"), std::string::npos) << out;
}

std::vector<iso::Measurement> bidirectional_data() {
  std::vector<iso::Measurement> m;
  for (int run = 1; run <= 5; ++run)
    for (int t = 0; t <= 5; ++t)
      for (auto d : {iso::Direction::up, iso::Direction::down})
        m.push_back({.target_mm = 100.0 * t,
                     .run = run,
                     .direction = d,
                     .deviation_um = 0.8 * t + (d == iso::Direction::up ? 1.0 : -1.0) +
                                     0.1 * std::sin(run * 1.7 + t)});
  return m;
}

TEST(ResultRows, LinearValuesInTheGridsOrder) {
  const auto doc = daq::to_json(iso::evaluate(bidirectional_data(), iso::Standard::iso230_2_2014));
  std::vector<std::string> keys;
  for (const auto& r : daq::linear_rows(doc)) keys.push_back(r.key);
  const std::vector<std::string> grid{"E_up", "E_down", "E_bi", "R_up", "R_down", "R_bi",
                                      "A_up", "A_down", "A_bi", "M",    "B",      "B_mean"};
  EXPECT_EQ(keys, grid);
  // The JSON's "values" in the same order, and a document stored before it (no "values") too.
  ASSERT_TRUE(doc.contains("values"));
  ASSERT_EQ(doc["values"].size(), grid.size());
  for (std::size_t i = 0; i < grid.size(); ++i) EXPECT_EQ(doc["values"][i]["key"], grid[i]);
  json old = doc;
  old.erase("values");
  keys.clear();
  for (const auto& r : daq::linear_rows(old)) keys.push_back(r.key);
  EXPECT_EQ(keys, grid);
}

// VDI/DGQ 3441's configured limits are applied (the report said "No tolerance").
TEST(Verdict, Vdi3441IsJudgedByItsOwnLimits) {
  const auto doc = daq::to_json(iso::evaluate(bidirectional_data(), iso::Standard::vdi_3441_1977));
  const json both = {{"E_um", 10.0}, {"P_um", 100.0}, {"Ps_um", 0.001}, {"U_um", 5.0}};
  const auto v = daq::linear_verdict(both, doc);
  EXPECT_TRUE(v.configured);
  EXPECT_FALSE(v.pass);  // Ps max is above 0.001 um
  ASSERT_EQ(v.checks.size(), 3u);
  EXPECT_EQ(v.checks[0].key, "P");
  EXPECT_TRUE(v.checks[0].pass);
  EXPECT_EQ(v.checks[1].key, "Ps_max");
  EXPECT_FALSE(v.checks[1].pass);
  EXPECT_EQ(v.checks[2].key, "U_max");
  EXPECT_EQ(daq::summary(v), "FAIL");
  EXPECT_TRUE(v.notes.empty());  // E is ISO 230-2's, not a limit this evaluation missed
  // Only ISO 230-2's limits: none applies, and the note says which keys would.
  const auto iso_only = daq::linear_verdict(json{{"E_um", 10.0}, {"B_um", 3.0}}, doc);
  EXPECT_FALSE(iso_only.configured);
  EXPECT_EQ(daq::summary(iso_only), "no tolerance applies");
  ASSERT_EQ(iso_only.notes.size(), 1u);
  EXPECT_NE(iso_only.notes[0].find("P_um"), std::string::npos) << iso_only.notes[0];
  // And ISO 230-2 is not judged by VDI limits.
  const auto iso_doc =
      daq::to_json(iso::evaluate(bidirectional_data(), iso::Standard::iso230_2_2014));
  const auto v2 = daq::linear_verdict(both, iso_doc);
  ASSERT_EQ(v2.checks.size(), 1u);
  EXPECT_EQ(v2.checks[0].key, "E_bi");
}

// A rotary axis's values (caldaq.rotary.v1, arcsec) against its [tolerances.C] limits in arcsec
// (issue 36: the verdict said "no tolerance configured" whatever was configured), and never
// against a linear axis's µm limits.
TEST(Verdict, RotaryAxisIsJudgedInArcsec) {
  const json doc = {{"schema", "caldaq.rotary.v1"},
                    {"title", "ISO 230-2:2014"},
                    {"standard", "iso230-2:2014"},
                    {"bidirectional", true},
                    {"axis",
                     {{"E_bi", {{"symbol", "E"}, {"value", 8.25}}},
                      {"B", {{"symbol", "B"}, {"value", -4.5}}},
                      {"M", {{"symbol", "M"}, {"value", 3.0}}}}}};
  const auto settings = [](json tolerances) {
    return json{{"context", {{"tolerances", std::move(tolerances)}}}};
  };
  const auto v = daq::verdict_of(
      settings({{"E_arcsec", 10.0}, {"B_arcsec", 4.0}, {"source", "tolerances.C"}}), doc);
  EXPECT_TRUE(v.configured);
  EXPECT_FALSE(v.pass);  // |B| 4.5" above 4"
  EXPECT_EQ(v.basis, "tolerances.C");
  ASSERT_EQ(v.checks.size(), 2u);
  EXPECT_EQ(v.checks[0].key, "E_bi");
  EXPECT_DOUBLE_EQ(v.checks[0].value, 8.25);
  EXPECT_EQ(v.checks[0].unit, "arcsec");
  EXPECT_TRUE(v.checks[0].pass);
  EXPECT_EQ(v.checks[1].key, "B");
  EXPECT_FALSE(v.checks[1].pass);
  EXPECT_EQ(daq::summary(v), "FAIL");
  // A limit the evaluation does not give (R of a result without it) is named in arcsec.
  const auto r = daq::verdict_of(settings({{"R_arcsec", 2.0}, {"M_arcsec", 5.0}}), doc);
  EXPECT_TRUE(r.pass);
  ASSERT_EQ(r.notes.size(), 1u);
  EXPECT_NE(r.notes[0].find("R limit 2 arcsec not applied"), std::string::npos) << r.notes[0];
  // µm limits (a linear axis's) are not compared with arcsec: none applies, and said so.
  const auto um = daq::verdict_of(settings({{"E_um", 10.0}, {"B_um", 3.0}}), doc);
  EXPECT_FALSE(um.configured);
  EXPECT_EQ(daq::summary(um), "no tolerance applies");
  ASSERT_FALSE(um.notes.empty());
  EXPECT_NE(um.notes[0].find("E_arcsec"), std::string::npos) << um.notes[0];
  // And a linear axis is not judged by arcsec limits.
  const auto iso_doc =
      daq::to_json(iso::evaluate(bidirectional_data(), iso::Standard::iso230_2_2014));
  EXPECT_FALSE(daq::linear_verdict(json{{"E_arcsec", 1e-3}}, iso_doc).configured);
}

}  // namespace
