// End to end, issue 26: the verification loop of cross-axis and volumetric compensations on the
// SIMULATED shop (a known truth). A straightness (squareness) run is measured as found, a table
// is written (SINUMERIK CEC and ISG cross compensation from the run, LinuxCNC matrixkins and ISG
// volumetric compensation from the injected model), stored with the machine, and loaded into
// the simulated control: as its vendor's text reads (caldaq's reading), and with the other
// sign. The as-left run of the same line is then checked as `daq verify` checks it: the right
// sign leaves a small residual "as predicted", the other sign about twice the error and the
// finding "inverted sign", with the corrected files on offer.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <string>
#include <vector>

#include "../support/daq_cli.hpp"
#include "../support/temp_db.hpp"
#include "cal/analysis/comp_formats.hpp"
#include "cal/analysis/comp_read.hpp"
#include "cal/analysis/iso230_2.hpp"
#include "cal/storage/store.hpp"
#include "compensation/compensation_check.hpp"
#include "sim_volumetric.hpp"

namespace {

namespace fs = std::filesystem;
namespace kin = cal::kinematics;
namespace ct = cal::comptable;
using Files = std::vector<std::pair<std::string, std::string>>;

constexpr auto kTopology = kin::Topology::yfxz;

daq::SimulatedAcquisition acquisition(const fs::path& db) {
  return {.truth = daq::volumetric_truth(kTopology),
          .database = db,
          .laser_poll_s = 0.02,
          .store_options = {.full_sync = false}};
}

std::int64_t acquire(const daq::SimulatedAcquisition& a, const std::string& component) {
  const auto out = daq::acquire_simulated(a, daq::volumetric_test(component));
  EXPECT_TRUE(out.complete) << component << ": " << out.reason;
  return out.run_id;
}

// The largest |mean deviation| of a run's targets and directions (um).
double largest_um(const fs::path& db, std::int64_t run) {
  cal::storage::Store store(db, {.read_only = true});
  std::vector<cal::iso230_2::Measurement> m;
  for (const auto& t : store.targets(run))
    m.push_back({t.nominal_mm, t.run_number,
                 t.direction == '+' ? cal::iso230_2::Direction::up : cal::iso230_2::Direction::down,
                 t.deviation_um});
  double worst = 0;
  for (const auto& s : cal::iso230_2::target_stats(m, 1))
    worst = std::max({worst, std::abs(s.mean_up_um), std::abs(s.mean_down_um)});
  return worst;
}

// The as-found run's profile along its axis (mean of each target), for a table made from it.
ct::CrossAxisTable table_from_run(const fs::path& db, std::int64_t run, const std::string& input,
                                  const std::string& output) {
  cal::storage::Store store(db, {.read_only = true});
  std::map<double, std::pair<double, int>> by;
  for (const auto& t : store.targets(run))
    by[t.nominal_mm].first += t.deviation_um, ++by[t.nominal_mm].second;
  std::vector<double> x, v;
  for (const auto& [p, s] : by) x.push_back(p), v.push_back(s.first / s.second);
  const ct::Spec grid{.start_mm = x.front(),
                      .interval_mm = (x.back() - x.front()) / static_cast<double>(x.size() - 1),
                      .points = static_cast<int>(x.size())};
  return ct::from_straightness(input, output, grid, x, v, false);
}

struct LoopResult {
  double before_um = 0, right_um = 0, inverted_um = 0;
  daq::LoopCheck right, inverted;
  Files corrected;
  double fixed_um = 0;
  daq::LoopCheck fixed;
};

// The loop: `files` (made by `make` from the as-found run) stored as a compensation of the
// machine, the control loading them right and inverted, each as-left run checked; then the
// corrected files loaded into the inverting control.
LoopResult loop(const char* name, const std::string& component, const std::string& format,
                const std::function<Files(const fs::path&, std::int64_t)>& make) {
  const auto db = cal::test::temp_path("caldaq-crossloop", name);
  auto a = acquisition(db);
  LoopResult r;
  const auto found = acquire(a, component);
  r.before_um = largest_um(db, found);
  const Files files = make(db, found);
  {
    cal::storage::Store store(db);
    const auto run = store.run(found);
    daq::store_cross_compensation(store, run->machine_id, found, fmt::format("run {}", found),
                                  {.format = format, .files = files});
  }
  std::vector<std::string> texts;
  for (const auto& f : files) texts.push_back(f.second);
  const auto check = [&](std::int64_t run) {
    cal::storage::Store store(db, {.read_only = true});
    auto c = daq::check_run(store, run);
    EXPECT_TRUE(c.has_value()) << name << ": run " << run << " was not checked";
    return c.value_or(daq::LoopCheck{});
  };
  a.compensation = daq::control_loads(format, texts, false);
  const auto right = acquire(a, component);
  r.right_um = largest_um(db, right);
  r.right = check(right);
  a.compensation = daq::control_loads(format, texts, true);
  const auto inverted = acquire(a, component);
  r.inverted_um = largest_um(db, inverted);
  r.inverted = check(inverted);
  r.corrected = daq::corrected_files(r.inverted);
  std::vector<std::string> fixed;
  for (const auto& f : r.corrected) fixed.push_back(f.second);
  // The corrected files in the control that inverts do what the stored files were predicted to
  // do (as daq verify of the next run says, against the same compensation).
  a.compensation = daq::control_loads(format, fixed, true);
  const auto again = acquire(a, component);
  r.fixed_um = largest_um(db, again);
  r.fixed = check(again);
  std::printf(
      "cross loop %s (%s, %s): largest |deviation| as found %.3f um; loaded as the vendor reads "
      "it %.3f um (%s); with the other sign %.3f um (%s); corrected files in that control "
      "%.3f um (%s)\n",
      format.c_str(), component.c_str(), name, r.before_um, r.right_um,
      std::string(ct::to_string(r.right.verification.finding)).c_str(), r.inverted_um,
      std::string(ct::to_string(r.inverted.verification.finding)).c_str(), r.fixed_um,
      std::string(ct::to_string(r.fixed.verification.finding)).c_str());
  cal::test::remove_db(db);
  return r;
}

// An as-left E_YX run in a control that applies the stored file otherwise than meant: its check
// must name `want`; the one corrected file daq verify --corrected writes.
struct Diagnosed {
  std::int64_t run = 0;
  daq::LoopCheck check;
  std::string corrected;
};
Diagnosed diagnose(const daq::SimulatedAcquisition& a, const fs::path& db, ct::Finding want) {
  Diagnosed d;
  d.run = acquire(a, "E_YX");
  cal::storage::Store store(db, {.read_only = true});
  d.check = daq::check_run(store, d.run).value();
  EXPECT_EQ(d.check.verification.finding, want) << d.check.verification.text;
  const auto files = daq::corrected_files(d.check);
  EXPECT_EQ(files.size(), 1u);
  if (!files.empty()) d.corrected = files[0].second;
  return d;
}

// `right_ratio`: what the right sign may leave of the as-found error.
void expect_loop(const LoopResult& r, const char* what, double right_ratio = 0.2) {
  EXPECT_GT(r.before_um, 3.0) << what;  // a table worth verifying
  EXPECT_EQ(r.right.verification.finding, ct::Finding::as_predicted) << what;
  EXPECT_LT(r.right_um, right_ratio * r.before_um) << what;
  EXPECT_EQ(r.inverted.verification.finding, ct::Finding::inverted_sign)
      << what << ": " << r.inverted.verification.text;
  // About twice the error: the table added it again.
  EXPECT_GT(r.inverted_um, 1.6 * r.before_um) << what;
  EXPECT_LT(r.inverted_um, 2.4 * r.before_um) << what;
  EXPECT_EQ(r.fixed.verification.finding, ct::Finding::as_predicted) << what;
  EXPECT_LT(r.fixed_um, right_ratio * r.before_um) << what;
}

// E_YX (the straightness of X read in Y against a square: it holds the squareness's slope) in a
// SINUMERIK CEC table of Y over X, from the as-found run.
TEST(CrossLoop, SinumerikCecInvertedSignIsDiagnosed) {
  const auto r = loop("cec", "E_YX", "siemens-cec", [](const fs::path& db, std::int64_t run) {
    const std::vector<ct::CrossAxisTable> t{table_from_run(db, run, "X", "Y")};
    return Files{{"", ct::write_sinumerik_cec(t, {{"X", 1}, {"Y", 2}, {"Z", 3}})}};
  });
  expect_loop(r, "siemens-cec");
  ASSERT_EQ(r.corrected.size(), 1u);
  EXPECT_NE(r.corrected[0].second.find("$AN_CEC[0,5]="), std::string::npos);
  EXPECT_EQ(r.inverted.component, "E_YX");
}

// A control that takes the CEC values in another unit (inch for mm: 25.4 times as large) and
// one whose Y is off by a constant (a reference point not the table's): each diagnosed and
// named, and the corrected file removes the error in that control.
TEST(CrossLoop, SinumerikCecUnitAndReferenceErrorsAreDiagnosed) {
  const auto db = cal::test::temp_path("caldaq-crossloop", "cecunit");
  auto a = acquisition(db);
  const auto found = acquire(a, "E_YX");
  const double before = largest_um(db, found);
  const std::vector<ct::CrossAxisTable> t{table_from_run(db, found, "X", "Y")};
  const std::vector<std::string> file{ct::write_sinumerik_cec(t, {{"X", 1}, {"Y", 2}, {"Z", 3}})};
  {
    cal::storage::Store store(db);
    daq::store_cross_compensation(store, store.run(found)->machine_id, found, "run",
                                  {.format = "siemens-cec", .files = {{"", file[0]}}});
  }
  const auto check = [&](std::int64_t run) {
    cal::storage::Store store(db, {.read_only = true});
    return daq::check_run(store, run).value();
  };
  // The control that applies the values of `text` 25.4 times as large, or adds 2 um to Y.
  using Control = std::function<kin::Vec3(const kin::Vec3&)>;
  const auto inch = [](const std::string& text) -> Control {
    const std::vector<std::string> one{text};
    return [loaded = daq::control_loads("siemens-cec", one, false)](const kin::Vec3& p) {
      auto c = loaded(p);
      for (auto& v : c) v *= 25.4;
      return c;
    };
  };
  const auto y_off = [](const std::string& text) -> Control {
    const std::vector<std::string> one{text};
    return [loaded = daq::control_loads("siemens-cec", one, false)](const kin::Vec3& p) {
      auto c = loaded(p);
      c[1] += 2.0;
      return c;
    };
  };
  a.compensation = inch(file[0]);
  const auto unit_d = diagnose(a, db, ct::Finding::unit_scale);
  const auto& unit = unit_d.check;
  const auto unit_run = unit_d.run;
  EXPECT_NEAR(unit.verification.scale, 25.4, 1e-9);
  a.compensation = y_off(file[0]);
  const auto shifted_d = diagnose(a, db, ct::Finding::constant_shift);
  const auto& shifted = shifted_d.check;
  const auto shifted_run = shifted_d.run;
  EXPECT_NEAR(shifted.verification.offset_um, 2.0, 0.1);
  // Each corrected file in the control that got it wrong: as predicted.
  a.compensation = inch(unit_d.corrected);
  const auto unit_again = acquire(a, "E_YX");
  EXPECT_EQ(check(unit_again).verification.finding, ct::Finding::as_predicted);
  a.compensation = y_off(shifted_d.corrected);
  const auto shift_again = acquire(a, "E_YX");
  EXPECT_EQ(check(shift_again).verification.finding, ct::Finding::as_predicted);
  std::printf(
      "cross loop siemens-cec (E_YX): as found %.3f um; 25.4 x as large %.3f um (%s, x%.2f), "
      "corrected %.3f um; Y off by +2 um %.3f um (%s, %+.3f um), corrected %.3f um\n",
      before, largest_um(db, unit_run),
      std::string(ct::to_string(unit.verification.finding)).c_str(), unit.verification.scale,
      largest_um(db, unit_again), largest_um(db, shifted_run),
      std::string(ct::to_string(shifted.verification.finding)).c_str(),
      shifted.verification.offset_um, largest_um(db, shift_again));
  cal::test::remove_db(db);
}

// A control that applies a CEC table at positions shifted by +50 mm (its X datum is not the
// table's): a table with a bump (10 um at X 200 mm, not a line, which a shift would turn into a
// constant) is stored and loaded there; daq verify names the position shift, and the corrected
// file (the table's positions moved by -50 mm) in that control acts as predicted. Before, the
// cross check had no table positions (no shift was ever found) and --corrected refused it.
TEST(CrossLoop, SinumerikCecPositionShiftIsDiagnosedAndCorrected) {
  const auto db = cal::test::temp_path("caldaq-crossloop", "cecshift");
  auto a = acquisition(db);
  const auto found = acquire(a, "E_YX");
  const std::vector<ct::CrossAxisTable> t{{"X", "Y", 0.0, 100.0, {0.0, 0.0, 0.010, 0.0, 0.0, 0.0}}};
  const std::map<std::string, int> numbers{{"X", 1}, {"Y", 2}, {"Z", 3}};
  const std::string file = ct::write_sinumerik_cec(t, numbers);
  {
    cal::storage::Store store(db);
    daq::store_cross_compensation(store, store.run(found)->machine_id, found, "run",
                                  {.format = "siemens-cec", .files = {{"", file}}});
  }
  const auto check = [&](std::int64_t run) {
    cal::storage::Store store(db, {.read_only = true});
    return daq::check_run(store, run).value();
  };
  // The control reads the table's positions 50 mm further out than they are written.
  const auto shifted_control = [&](const std::string& text) {
    const std::vector<ct::CompFile> one{{"", text}};
    return daq::control_loads(
        "siemens-cec", ct::shift_cross_positions("siemens-cec", one, "X", "Y", -50.0, numbers),
        false);
  };
  a.compensation = shifted_control(file);
  const auto d = diagnose(a, db, ct::Finding::position_shift);
  const auto& shifted = d.check;
  const auto shifted_run = d.run;
  EXPECT_NEAR(shifted.verification.shift_mm, 50.0, 5.0);
  EXPECT_NE(d.corrected.find("$AN_CEC_MIN[0]=-50.0000"), std::string::npos) << d.corrected;
  a.compensation = shifted_control(d.corrected);
  const auto again = acquire(a, "E_YX");
  const auto ok = check(again);
  EXPECT_EQ(ok.verification.finding, ct::Finding::as_predicted) << ok.verification.text;
  std::printf(
      "cross loop siemens-cec (E_YX, a 10 um bump at X 200): as found %.3f um; the control 50 mm "
      "off %.3f um (%s, %+.1f mm); corrected file there %.3f um (%s)\n",
      largest_um(db, found), largest_um(db, shifted_run),
      std::string(ct::to_string(shifted.verification.finding)).c_str(),
      shifted.verification.shift_mm, largest_um(db, again),
      std::string(ct::to_string(ok.verification.finding)).c_str());
  cal::test::remove_db(db);
}

// The same through the command line: `daq compensate --run` on the as-found straightness run
// writes the CEC table and stores it; the control loads it with the other sign; `daq verify`
// of the as-left run names the inverted sign and writes the corrected table, which that control
// then applies as predicted (`daq show` says the same).
TEST(CrossLoop, DaqVerifyOfAStraightnessRunNamesTheInvertedSign) {
  const auto db = cal::test::temp_path("caldaq-crossloop", "cli");
  const auto dir = cal::test::temp_path("caldaq-crossloop", "cli", "");
  fs::create_directories(dir);
  auto a = acquisition(db);
  const auto found = acquire(a, "E_YX");
  const std::string q = "'" + db.string() + "'";
  const auto table = (dir / "cec.mpf").string(), fixed = (dir / "fixed.mpf").string();
  const auto made = cal::test::daq_cli(
      fmt::format("compensate --run {} --db {} -f siemens-cec --start-mm 0 --interval-mm 100 "
                  "--points 6 -o '{}'",
                  found, q, table),
      dir / "compensate.txt");
  ASSERT_EQ(made.status, 0) << made.output;
  EXPECT_NE(made.output.find("stored as compensation 1: the next straightness run of X in Y"),
            std::string::npos)
      << made.output;
  EXPECT_NE(made.output.find("Verify before trusting it"), std::string::npos) << made.output;
  std::ifstream in(table);
  const std::vector<std::string> file{std::string(std::istreambuf_iterator<char>(in), {})};
  EXPECT_NE(file[0].find("$AN_CEC_OUTPUT_AXIS[0]=(AX2)"), std::string::npos) << file[0];
  EXPECT_NE(file[0].find("; VERIFY BEFORE TRUSTING"), std::string::npos) << file[0];
  a.compensation = daq::control_loads("siemens-cec", file, true);
  const auto inverted = acquire(a, "E_YX");
  const auto verify = cal::test::daq_cli(
      fmt::format("verify {} --db {} --corrected '{}'", inverted, q, fixed), dir / "verify.txt");
  EXPECT_EQ(verify.status, 0) << verify.output;
  EXPECT_NE(verify.output.find(fmt::format(
                "compensation 1 (siemens-cec, run {} of axis Y), E_YX against run {} (as found): "
                "inverted sign",
                found, found)),
            std::string::npos)
      << verify.output;
  const auto show =
      cal::test::daq_cli(fmt::format("show {} --db {}", inverted, q), dir / "show.txt");
  EXPECT_NE(show.output.find("inverted sign"), std::string::npos) << show.output;
  std::ifstream fin(fixed);
  const std::vector<std::string> corrected{std::string(std::istreambuf_iterator<char>(fin), {})};
  a.compensation = daq::control_loads("siemens-cec", corrected, true);
  const auto again = acquire(a, "E_YX");
  const auto ok = cal::test::daq_cli(fmt::format("verify {} --db {}", again, q), dir / "ok.txt");
  EXPECT_NE(ok.output.find(": as predicted"), std::string::npos) << ok.output;
  fs::remove_all(dir);
  cal::test::remove_db(db);
}

// The same line in an ISG cross compensation list of Y (slave, logical axis 2) over X (master 1).
TEST(CrossLoop, IsgCrossInvertedSignIsDiagnosed) {
  const auto r = loop("isgcross", "E_YX", "isg-cross", [](const fs::path& db, std::int64_t run) {
    return Files{{"", ct::write_isg_cross(table_from_run(db, run, "X", "Y"), 2, 1)}};
  });
  expect_loop(r, "isg-cross");
}

// The squareness E_C0Y in LinuxCNC matrixkins (carried by Y: C_xy, X corrected as a function of
// Y), from the injected model; E_XY (Y moving, X read against the square) sees it.
TEST(CrossLoop, LinuxcncMatrixkinsInvertedSignIsDiagnosed) {
  const auto r =
      loop("matrixkins", "E_XY", "linuxcnc-matrixkins", [](const fs::path&, std::int64_t) {
        const auto truth = daq::volumetric_truth_model(kTopology);
        return Files{{"matrixkins.hal",
                      ct::write_linuxcnc_matrixkins(truth.machine.squareness, truth.carriers)}};
      });
  // matrixkins holds the squareness only: E_XY's own straightness stays (about 1 um).
  EXPECT_EQ(r.right.verification.finding, ct::Finding::as_predicted);
  EXPECT_EQ(r.inverted.verification.finding, ct::Finding::inverted_sign)
      << r.inverted.verification.text;
  EXPECT_GT(r.inverted_um, r.before_um + 3.0);
  EXPECT_EQ(r.fixed.verification.finding, ct::Finding::as_predicted);
}

// The whole injected model in ISG volumetric compensation (the configuration list and the ISG
// CSV parameter file); E_YX along X at the campaign's stationary Y and Z.
TEST(CrossLoop, IsgVolumetricInvertedSignIsDiagnosed) {
  const auto r = loop("isgvol", "E_YX", "isg-volumetric", [](const fs::path&, std::int64_t) {
    const auto truth = daq::volumetric_truth_model(kTopology);
    const std::array<cal::volcomp::AxisGrid, 3> grid{
        {{0.0, 50.0, 11}, {0.0, 50.0, 9}, {0.0, 50.0, 7}}};
    return Files{{"volcomp.lis", ct::write_isg_volumetric_list(
                                     kTopology, {{"X", 1}, {"Y", 2}, {"Z", 3}}, "volcomp.csv")},
                 {"volcomp.csv", ct::write_isg_volumetric_csv(truth.machine, grid)}};
  });
  // The ISG file has no tool (P0X.. not written): the control corrects the spindle's point, and
  // the indicator 100 mm below it keeps the angular errors over that arm (about 1.5 um).
  expect_loop(r, "isg-volumetric", 0.4);
  EXPECT_EQ(r.corrected.size(), 2u);
}

}  // namespace
