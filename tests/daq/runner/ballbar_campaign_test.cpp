// The three-plane table and the history gathered from stored circle runs: which tests each
// plane uses (the slowest feed, averaged), the signs carried into the model's location errors,
// the model block a caldaq.model.v1 file accepts, and the history's series and verdicts. The
// stored results are written by hand here (values chosen so that every expectation below can
// be checked by eye); the analysis behind such values is tested in ballbar_planes_test.cpp.
#include "ballbar_campaign.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>

#include "../../support/temp_dir.hpp"
#include "cal/analysis/error.hpp"
#include "model/model_file.hpp"

namespace {

using nlohmann::json;
namespace st = cal::storage;

struct TempDir : cal::test::TempDir {
  TempDir() : cal::test::TempDir("caldaq-bb") {}
};

struct Stored {
  std::string plane;
  double feed, g, squareness, mismatch;
  std::optional<double> radius_error;  // a calibrated bar
  std::int64_t day;
  std::string campaign = "2026-11";
};

// A circle run with a caldaq.circle.v2 result; tolerances G 5 um, squareness 15 um/m.
std::int64_t store_test(st::Store& s, std::int64_t machine, const Stored& t) {
  const json settings{{"radius_mm", 150.0},
                      {"centre_mm", {100.0, 200.0, -300.0}},
                      {"context",
                       {{"tolerances",
                         {{"G_um", 5.0},
                          {"diagnostics", {{"squareness", 15.0}}},
                          {"source", "tolerances." + t.plane}}}}}};
  const auto run = s.begin_run({.machine_id = machine,
                                .campaign = t.campaign,
                                .kind = "circle",
                                .axis = t.plane,
                                .settings_json = settings.dump(),
                                .started_unix_ms = t.day * 86'400'000});
  json diagnostics = json::array(
      {{{"key", "squareness"},
        {"name", "Squareness " + t.plane},
        {"value", t.squareness},
        {"unit", "um/m"}},
       {{"key", "scale_mismatch"},
        {"name", "Scale mismatch"},
        {"value", t.mismatch},
        {"unit", "um/m"}},
       {{"key", "servo_mismatch"}, {"name", "Servo mismatch"}, {"value", 0.1}, {"unit", "ms"}}});
  if (t.radius_error)
    diagnostics.push_back({{"key", "radius_error"}, {"value", *t.radius_error}, {"unit", "um"}});
  const json result{{"schema", "caldaq.circle.v2"},
                    {"standard", "ISO 230-4:2005"},
                    {"plane", t.plane},
                    {"radius_mm", 150.0},
                    {"feed_mm_per_min", t.feed},
                    {"iso230_4", {{"G_bi_um", t.g}, {"arc_deg", t.plane == "XY" ? 360 : 220}}},
                    {"diagnostics", diagnostics}};
  s.add_result({.run_id = run, .standard = "ISO 230-4:2005", .json = result.dump()});
  s.finish_run(run, st::RunStatus::complete);
  return run;
}

}  // namespace

TEST(BallbarCampaign, TheTableTakesEachPlanesSlowestFeedAndTheModelsSigns) {
  TempDir dir;
  st::Store s(dir.path / "site.sqlite");
  const auto m = s.add_machine({.name = "VMC"});
  // XY at two feeds: the slow one has the geometry; the fast one adds a servo ellipse.
  const auto xy_slow = store_test(s, m, {"XY", 500, 4.0, 12.0, 6.0, std::nullopt, 1});
  store_test(s, m, {"XY", 3000, 7.0, 19.0, 9.0, std::nullopt, 1});
  // ZX twice at the slow feed (averaged: alpha -8, mismatch -4), once fast.
  const auto zx1 = store_test(s, m, {"ZX", 500, 3.0, -7.0, -3.0, std::nullopt, 1});
  const auto zx2 = store_test(s, m, {"ZX", 500, 3.0, -9.0, -5.0, std::nullopt, 1});
  store_test(s, m, {"ZX", 3000, 6.0, -2.0, 0.0, std::nullopt, 1});
  const auto yz = store_test(s, m, {"YZ", 500, 3.5, 5.0, -2.0, std::nullopt, 1});
  const auto runs = daq::ballbar_runs(s, "VMC");
  ASSERT_EQ(runs.size(), 6u);
  const auto tests = daq::ballbar_tests(s, runs);
  const auto v = daq::volumetric_table(tests);
  const auto& p = v.combined.planes;
  ASSERT_TRUE(p[0] && p[1] && p[2]);  // xy, yz, zx
  EXPECT_EQ(v.used[0].runs, std::vector<std::int64_t>{xy_slow});
  EXPECT_EQ(v.used[2].runs, (std::vector<std::int64_t>{zx1, zx2}));
  EXPECT_EQ(v.used[1].runs, std::vector<std::int64_t>{yz});
  EXPECT_DOUBLE_EQ(p[2]->squareness_um_per_m, -8.0);
  EXPECT_DOUBLE_EQ(p[2]->scale_mismatch_um_per_m, -4.0);
  // E_C0Y = +alpha XY, E_B0Z = -alpha ZX, E_A0Z = +alpha YZ.
  const json block = daq::model_squareness(v);
  EXPECT_DOUBLE_EQ(block["E_C0Y"]["iso230_1_urad"].get<double>(), 12.0);
  EXPECT_DOUBLE_EQ(block["E_B0Z"]["iso230_1_urad"].get<double>(), 8.0);
  EXPECT_DOUBLE_EQ(block["E_A0Z"]["iso230_1_urad"].get<double>(), 5.0);
  EXPECT_EQ(block["E_B0Z"]["method"], "circles");
  EXPECT_EQ(block["E_C0Y"]["method"], "circle");
  // Closure of the mismatches 6 + (-2) + (-4) = 0; relative scales (x - y = 6, y - z = -2,
  // z - x = -4, mean 0): x = (6 - -4)/3 = 10/3, y = (-2 - 6)/3 = -8/3, z = (-4 - -2)/3 = -2/3.
  EXPECT_NEAR(*v.combined.closure_um_per_m, 0.0, 1e-12);
  ASSERT_TRUE(v.combined.scale_um_per_m);
  EXPECT_FALSE(v.combined.scale_absolute);
  EXPECT_NEAR((*v.combined.scale_um_per_m)[0], 10.0 / 3, 1e-9);
  EXPECT_NEAR((*v.combined.scale_um_per_m)[1], -8.0 / 3, 1e-9);
  EXPECT_NEAR((*v.combined.scale_um_per_m)[2], -2.0 / 3, 1e-9);
  // The block is what a model file takes: read back with the ISO 230-1 values and the position.
  const json model{{"schema", "caldaq.model.v1"},
                   {"topology", "FXYZ"},
                   {"units", {{"position", "mm"}, {"translation", "um"}, {"angle", "urad"}}},
                   {"squareness", block}};
  const auto read = cal::daq::model::parse(model.dump(), "test");
  EXPECT_DOUBLE_EQ(read.machine.squareness.b0z_urad, 8.0);
  EXPECT_DOUBLE_EQ(read.machine.squareness.a0z_urad, 5.0);
  EXPECT_EQ(read.squareness[1].placement, "local");
  EXPECT_EQ((*read.squareness[1].position_mm)[2], -300.0);
}

TEST(BallbarCampaign, CalibratedBarsGiveAbsoluteScalesAndMissingPlanesAreNamed) {
  TempDir dir;
  st::Store s(dir.path / "site.sqlite");
  const auto m = s.add_machine({.name = "VMC"});
  // Scales X +10, Y -5, Z +3 um/m: XY mismatch 15, radius error 150 mm x 2.5 um/m = 0.375 um;
  // ZX mismatch -7. No YZ test.
  store_test(s, m, {"XY", 500, 4.0, 1.0, 15.0, 0.375, 1});
  store_test(s, m, {"ZX", 500, 4.0, 1.0, -7.0, std::nullopt, 1});
  const auto tests = daq::ballbar_tests(s, daq::ballbar_runs(s, "VMC"));
  const auto v = daq::volumetric_table(tests);
  ASSERT_TRUE(v.combined.scale_absolute);
  EXPECT_NEAR((*v.combined.scale_um_per_m)[0], 10.0, 1e-9);
  EXPECT_NEAR((*v.combined.scale_um_per_m)[1], -5.0, 1e-9);
  EXPECT_NEAR((*v.combined.scale_um_per_m)[2], 3.0, 1e-9);
  EXPECT_FALSE(v.combined.planes[1]);
  ASSERT_EQ(v.notes.size(), 1u);
  EXPECT_NE(v.notes[0].find("no test in YZ"), std::string::npos);
  EXPECT_FALSE(daq::model_squareness(v).contains("E_A0Z"));
}

TEST(BallbarCampaign, HistoryPerPlaneFeedAndRadiusWithVerdicts) {
  TempDir dir;
  st::Store s(dir.path / "site.sqlite");
  const auto m = s.add_machine({.name = "VMC"});
  const auto other = s.add_machine({.name = "LATHE"});
  store_test(s, m, {"XY", 500, 4.0, 12.0, 6.0, std::nullopt, 10, "2026-01"});
  store_test(s, m, {"XY", 500, 6.0, 16.0, 6.0, std::nullopt, 100, "2026-04"});  // G, sq. fail
  store_test(s, m, {"ZX", 500, 3.0, -7.0, -3.0, std::nullopt, 100, "2026-04"});
  store_test(s, other, {"XY", 500, 1.0, 1.0, 1.0, std::nullopt, 50});
  const auto all = daq::ballbar_runs(s, "VMC");
  ASSERT_EQ(all.size(), 3u);
  EXPECT_EQ(daq::ballbar_runs(s, "VMC", "2026-04").size(), 2u);
  const json h = daq::history_json(daq::ballbar_tests(s, all));
  ASSERT_EQ(h["series"].size(), 2u);  // XY at 500, ZX at 500
  const auto& xy = h["series"][0];
  EXPECT_EQ(xy["plane"], "XY");
  ASSERT_EQ(xy["tests"].size(), 2u);
  EXPECT_EQ(xy["tests"][0]["campaign"], "2026-01");  // oldest first
  EXPECT_EQ(xy["tests"][0]["verdict"]["summary"], "PASS");
  EXPECT_EQ(xy["tests"][1]["verdict"]["summary"], "FAIL");
  EXPECT_EQ(xy["tests"][1]["verdict"]["checks"].size(), 2u);  // G and squareness
  // Refused: an unknown machine, a run that is not a ballbar test.
  EXPECT_THROW(daq::ballbar_runs(s, "NONE"), cal::InputError);
  const auto lin = s.begin_run({.machine_id = m, .kind = "linear", .started_unix_ms = 1});
  EXPECT_THROW(daq::ballbar_tests(s, std::vector<std::int64_t>{lin}), cal::InputError);
}
