// daq model ballbar5x | ballbar5x-sim | ballbar5x-program: the ballbar on a rotary table axis in
// simultaneous motion. ballbar5x fits the axis's four location errors (with their uncertainty)
// to the bar's readings; ballbar5x-sim is the simulated shop's bar (the readings a model, the
// machine's truth, gives when it runs the control's program); ballbar5x-program writes that
// program for Fanuc/ISO, HEIDENHAIN or SINUMERIK. The maths: cal::kinematics (ballbar5x.hpp),
// docs/kinematics.md "The ballbar on a rotary axis".
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>

#include "cal/analysis/ballbar5x.hpp"
#include "cal/analysis/error.hpp"
#include "cal/analysis/text.hpp"
#include "cal/daq/gcode.hpp"
#include "cli_checks.hpp"
#include "command.hpp"
#include "config_tolerances.hpp"
#include "csv_columns.hpp"
#include "database.hpp"
#include "model_cli.hpp"
#include "output_file.hpp"
#include "probe_cli.hpp"
#include "sim_ballbar5x.hpp"

namespace daq {

namespace {

constexpr const char* kColumns =
    "test,axis,setup,ball_x_mm,ball_y_mm,ball_z_mm,length_mm,angle_deg,reading_um";

// The columns as help and man pages print them: a space after each comma, so a line can break
// there (one 78-character word made groff warn "cannot adjust line" in the man page).
std::string columns_text() {
  std::string s;
  for (const char c : std::string_view(kColumns)) {
    s += c;
    if (c == ',') s += ' ';
  }
  return s;
}

// The options that define one test (sim and program).
struct TestOptions {
  std::string axis, setup = "radial", name;
  std::vector<double> ball_mm, angles_deg;
  double length_mm = 100.0;

  kin::RotaryBallbarTest test() const {
    kin::RotaryBallbarTest t;
    t.axis = kin::rotary_letter_from_string(axis);
    t.setup = kin::bar_setup_from_string(setup);
    t.name = name.empty() ? fmt::format("{}-{}", kin::to_string(t.axis), setup) : name;
    t.table_ball_mm = {ball_mm.at(0), ball_mm.at(1), ball_mm.at(2)};
    t.length_mm = length_mm;
    t.angles_deg = angles_deg;
    return t;
  }
};

void add_test_options(CLI::App* cmd, TestOptions& t) {
  cmd->add_option("--axis", t.axis, "The table axis turned (the other rotary axes stay at 0)")
      ->required()
      ->check(CLI::IsMember({"A", "B", "C", "a", "b", "c"}));
  cmd->add_option("--setup", t.setup,
                  "The bar relative to the axis: radial (from the axis line through the table "
                  "ball), tangential (across it) or axial (along the axis)")
      ->check(CLI::IsMember({"radial", "tangential", "axial"}))
      ->capture_default_str();
  cmd->add_option(
         "--ball-mm", t.ball_mm,
         "The table ball's centre on the workpiece X Y Z (home coordinates, all axes at 0)")
      ->required()
      ->expected(3)
      ->check(finite_in(-kMaxPositionMm, kMaxPositionMm));
  cmd->add_option("--length-mm", t.length_mm, "The bar's nominal length")
      ->check(finite_in(1.0, 2000.0))
      ->capture_default_str();
  cmd->add_option("--angles-deg", t.angles_deg, "The angles at which the bar is read")
      ->required()
      ->check(finite_in(-3600.0, 3600.0));
  cmd->add_option("--name", t.name,
                  "The test's name in the readings file (default AXIS-SETUP, e.g. C-radial; "
                  "letters, digits, '-' and '_')");
}

// The simulated machine and its control (ballbar5x-sim, ballbar5x-run).
void add_machine_options(CLI::App& cmd, TruthControlOptions& o, bool writes_runs) {
  add_truth_control_options(cmd, o,
                            {.control = "Model the control's kinematics holds (the program is "
                                        "computed with it): a file or a stored model",
                             .control_required = true,
                             .writes_runs = writes_runs});
}

void check_test_name(const std::string& name) {
  const bool ok = !name.empty() && name.size() <= 40 &&
                  std::all_of(name.begin(), name.end(), [](unsigned char c) {
                    return std::isalnum(c) || c == '-' || c == '_';
                  });
  if (!ok)
    throw cal::InputError(
        fmt::format("test name '{}': letters, digits, '-' and '_' only, at most 40",
                    cal::text::terminal_safe(name)));
}

// --- ballbar5x-sim ----------------------------------------------------------------------------

struct SimOptions : TruthControlOptions {
  std::string output;
  TestOptions t;
  double noise_um = 0.0, offset_um = 0.0;
  unsigned seed = 1;
};

void run_sim(const SimOptions& given) {
  const auto models = read_truth_control(given);
  SimOptions o = given;  // the files, or the stored models' labels: what the output names
  o.truth = models.truth.label;
  o.control = models.control->label;
  const auto truth = mdl::five_axis(models.truth.model);
  const auto control = mdl::five_axis(models.control->model);
  const kin::RotaryBallbarTest t = o.t.test();
  check_test_name(t.name);
  auto readings = kin::rotary_ballbar_readings_um(truth, control, t);
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> noise(0.0, o.noise_um);
  std::string text = fmt::format(
      "# simulated ballbar: machine {} running the program of {}; {} set-up, table ball ({:g}, "
      "{:g}, {:g}) mm, bar {:g} mm; bar zero {:g} um, noise {:g} um (seed {})\n{}\n",
      o.truth, o.control, kin::to_string(t.setup), t.table_ball_mm[0], t.table_ball_mm[1],
      t.table_ball_mm[2], t.length_mm, o.offset_um, o.noise_um, o.seed, kColumns);
  for (std::size_t k = 0; k < readings.size(); ++k) {
    const double r = readings[k] + o.offset_um + (o.noise_um > 0.0 ? noise(rng) : 0.0);
    text += fmt::format("{},{},{},{:g},{:g},{:g},{:g},{:g},{:.4f}\n", t.name,
                        kin::to_string(t.axis), kin::to_string(t.setup), t.table_ball_mm[0],
                        t.table_ball_mm[1], t.table_ball_mm[2], t.length_mm, t.angles_deg[k], r);
  }
  if (o.output.empty()) return fmt::print("{}", text);
  write_output_file(o.output, text, "readings");
  fmt::print(stderr, "{} readings of test {} written to {}\n", readings.size(), t.name, o.output);
}

// --- ballbar5x-program ------------------------------------------------------------------------

struct ProgramOptions {
  std::string model, db, output, dialect = "fanuc", program_name = "BB5X";
  TestOptions t;
  double feed = 500.0, dwell_s = 2.0, max_step_deg = 1.0;
};

void run_program(const ProgramOptions& o) {
  const auto control = mdl::five_axis(read_model_input(o.model, o.db).model);
  const kin::RotaryBallbarTest t = o.t.test();
  check_test_name(t.name);
  const kin::Vec3 ball = kin::tool_ball_mm(control, t);
  std::vector<cal::daq::RotaryProgramPoint> points;
  const auto add = [&](double deg, bool measure) {
    const kin::Vec3 p = kin::rotary_ballbar_command_mm(control, t, deg);
    points.push_back({p[0], p[1], p[2], deg, measure});
  };
  add(t.angles_deg.front(), true);
  for (std::size_t k = 1; k < t.angles_deg.size(); ++k) {
    const double from = t.angles_deg[k - 1], to = t.angles_deg[k];
    const int n =
        std::max(1, static_cast<int>(std::ceil(std::abs(to - from) / o.max_step_deg - 1e-9)));
    for (int i = 1; i <= n; ++i) add(from + (to - from) * i / n, i == n);
  }
  // Between two points the tool runs along a chord while the ball on the table runs along an
  // arc: the bar shortens by at most the sag R (1 - cos(step / 2)), R the spindle ball's distance
  // from the axis line.
  kin::Vec3 rho{};
  for (const auto& r : control.rotary)
    if (r.letter == t.axis)
      for (std::size_t i = 0; i < 3; ++i) rho[i] = ball[i] - r.pivot_mm[i];
  rho[kin::direction_index(t.axis)] = 0.0;
  const double radius = std::hypot(rho[0], rho[1], rho[2]);
  const double sag_um = 1e3 * radius * (1.0 - std::cos(o.max_step_deg * std::numbers::pi / 360.0));
  cal::daq::RotaryProgramSetup s;
  s.name = o.program_name;
  s.rotary = kin::to_string(t.axis)[0];
  s.feed_mm_per_min = o.feed;
  s.dwell_s = o.dwell_s;
  s.what =
      fmt::format("ballbar {} {} test, table ball {:.3f} {:.3f} {:.3f}, bar {:.3f} mm, {} stops",
                  kin::to_string(t.axis), kin::to_string(t.setup), t.table_ball_mm[0],
                  t.table_ball_mm[1], t.table_ball_mm[2], t.length_mm, t.angles_deg.size());
  const std::string text =
      cal::daq::rotary_ballbar_program(points, s, cal::daq::dialect_from_string(o.dialect));
  fmt::print(stderr,
             "{} blocks, {} stops; between stops the bar leaves its length by at most {:.1f} um "
             "(steps of {:g} deg at {:.1f} mm from the {} line)\n",
             points.size(), t.angles_deg.size(), sag_um, o.max_step_deg, radius,
             kin::to_string(t.axis));
  if (o.output.empty()) return fmt::print("{}", text);
  write_output_file(o.output, text, "program");
  fmt::print(stderr, "program written to {}\n", o.output);
}

// --- ballbar5x: the fit -----------------------------------------------------------------------

struct FitOptions {
  std::string readings, model, db, write;
  double reading_u_um = 0.0;
  bool json = false;
};

struct ReadRun {
  kin::RotaryBallbarRun run;
  int first_line = 0;
};

// The runs of the file, by test name in file order; each test's set-up must be the same on
// all its rows.
std::map<kin::RotaryLetter, std::vector<ReadRun>> read_runs(const std::string& path) {
  const auto csv = read_csv_columns(
      path, {"ball_x_mm", "ball_y_mm", "ball_z_mm", "length_mm", "angle_deg", "reading_um"},
      {"test", "axis", "setup"});
  std::vector<ReadRun> runs;
  std::map<std::string, std::size_t> index;
  for (std::size_t r = 0; r < csv.rows(); ++r) {
    const auto where = [&](std::string_view what) {
      return fmt::format("{}:{}: {}", path, csv.line[r], what);
    };
    kin::RotaryBallbarTest t;
    try {
      t.name = csv.texts.at("test")[r];
      check_test_name(t.name);
      t.axis = kin::rotary_letter_from_string(csv.texts.at("axis")[r]);
      t.setup = kin::bar_setup_from_string(csv.texts.at("setup")[r]);
    } catch (const cal::InputError& e) {
      throw cal::InputError(where(e.what()));
    }
    t.table_ball_mm = {csv.numbers.at("ball_x_mm")[r], csv.numbers.at("ball_y_mm")[r],
                       csv.numbers.at("ball_z_mm")[r]};
    t.length_mm = csv.numbers.at("length_mm")[r];
    auto [it, fresh] = index.try_emplace(t.name, runs.size());
    if (fresh) runs.push_back({{t, {}}, csv.line[r]});
    auto& run = runs[it->second].run;
    if (run.test.axis != t.axis || run.test.setup != t.setup ||
        run.test.table_ball_mm != t.table_ball_mm || run.test.length_mm != t.length_mm)
      throw cal::InputError(where(fmt::format(
          "test {}: its axis, set-up, ball or length differ from its first row (line {})", t.name,
          runs[it->second].first_line)));
    run.test.angles_deg.push_back(csv.numbers.at("angle_deg")[r]);
    run.reading_um.push_back(csv.numbers.at("reading_um")[r]);
  }
  std::map<kin::RotaryLetter, std::vector<ReadRun>> out;
  for (auto& r : runs) out[r.run.test.axis].push_back(std::move(r));
  return out;
}

json fit_json(const kin::RotaryBallbarFit& f, const std::vector<ReadRun>& runs) {
  const auto names = kin::location_error_names(f.axis);
  json loc = json::object();
  for (std::size_t k = 0; k < 4; ++k)
    loc[names[k]] = {
        {"value", f.value[k]},
        {"uncertainty", std::isnan(f.uncertainty[k]) ? json(nullptr) : json(f.uncertainty[k])},
        {"unit", k < 2 ? "um" : "urad"}};
  json tests = json::array();
  for (std::size_t n = 0; n < runs.size(); ++n) {
    const auto& t = runs[n].run.test;
    json rows = json::array();
    for (std::size_t k = 0; k < t.angles_deg.size(); ++k)
      rows.push_back({{"angle_deg", t.angles_deg[k]},
                      {"reading_um", runs[n].run.reading_um[k]},
                      {"residual_um", f.residual_um[n][k]}});
    tests.push_back({{"test", t.name},
                     {"setup", kin::to_string(t.setup)},
                     {"offset_um", f.offset_um[n]},
                     {"readings", rows}});
  }
  return {{"axis", kin::to_string(f.axis)}, {"location", loc}, {"rms_um", f.rms_um},
          {"sigma_um", f.sigma_um},         {"dof", f.dof},    {"tests", tests}};
}

void print_fit(const kin::RotaryBallbarFit& f, const std::vector<ReadRun>& runs) {
  const auto names = kin::location_error_names(f.axis);
  fmt::print("Axis {}: {} ballbar test(s)\n", kin::to_string(f.axis), runs.size());
  for (std::size_t k = 0; k < 4; ++k)
    fmt::print("  {:6} {:+10.3f} {:4}  u = {}\n", names[k], f.value[k], k < 2 ? "um" : "urad",
               std::isnan(f.uncertainty[k]) ? std::string("not estimated (no redundancy: give "
                                                          "--reading-u-um)")
                                            : fmt::format("{:.3f}", f.uncertainty[k]));
  for (std::size_t n = 0; n < runs.size(); ++n)
    fmt::print("  test {} ({}, {} readings): bar offset {:+.3f} um\n", runs[n].run.test.name,
               kin::to_string(runs[n].run.test.setup), runs[n].run.reading_um.size(),
               f.offset_um[n]);
  fmt::print("  residuals: RMS {:.3f} um, sigma {:.3f} um, {} degrees of freedom\n", f.rms_um,
             f.sigma_um, f.dof);
}

void run_fit(const FitOptions& given) {
  auto in = read_model_input(given.model, given.db);
  FitOptions o = given;
  o.model = in.label;  // the file, or the stored model: what the output names
  mdl::Model m = std::move(in.model);
  const auto control = mdl::five_axis(m);
  json fits = json::array();
  for (const auto& [letter, read] : read_runs(o.readings)) {
    std::vector<kin::RotaryBallbarRun> runs;
    for (const auto& r : read) runs.push_back(r.run);
    kin::RotaryBallbarFit f;
    try {
      f = kin::fit_rotary_ballbar(control, letter, runs, o.reading_u_um);
    } catch (const cal::InputError& e) {
      throw cal::InputError(fmt::format("{} with {}: {}", o.readings, o.model, e.what()));
    }
    if (o.json)
      fits.push_back(fit_json(f, read));
    else
      print_fit(f, read);
    for (auto& r : m.rotary) {
      if (r.axis.letter != letter) continue;
      kin::FiveAxisMachine one;
      one.rotary = {r.axis};
      r.axis = kin::with_location_errors(one, letter, f.value).rotary.front();
      for (std::size_t k = 0; k < 4; ++k) {
        r.location[k].given = true;
        r.location[k].uncertainty = std::isnan(f.uncertainty[k])
                                        ? std::optional<double>{}
                                        : std::optional<double>{f.uncertainty[k]};
        r.location[k].source = {json{
            {"kind", "ballbar, rotary axis"},
            {"readings_file", o.readings},
            {"tests", runs.size()},
            {"rms_um", f.rms_um}}.dump()};
      }
    }
  }
  if (o.json)
    fmt::print("{}\n", json{{"schema", "caldaq.rotary-ballbar-fit.v1"},
                            {"readings_file", o.readings},
                            {"model", o.model},
                            {"reading_u_um", o.reading_u_um},
                            {"axes", fits}}
                           .dump(2));
  if (!o.write.empty()) {
    mdl::write(m, o.write);
    fmt::print(stderr, "model with the fitted location errors written to {}\n", o.write);
  }
}

// --- ballbar5x-run: the tests as a stored run on the simulated shop ----------------------------

struct RunOptions5x : TruthControlOptions {
  std::string hal, swivel, db, write;  // db: where the run is written (models: --model-db)
  std::string tolerances;  // a file of [tolerances.C] ... tables: location_um, location_urad
  std::vector<double> ball_mm, offsets_um;
  std::vector<std::string> setups{"radial", "tangential", "axial"};
  std::map<std::string, std::vector<double>> angles_deg{
      {"C", {0, 30, 60, 90, 120, 150, 180, 210, 240, 270, 300, 330}},
      {"A", {-90, -75, -60, -45, -30, -15, 0, 15, 30, 45, 60, 75, 90}},
      {"B", {-90, -75, -60, -45, -30, -15, 0, 15, 30, 45, 60, 75, 90}}};
  double length_mm = 100.0, noise_um = 0.5;
  unsigned seed = 1;
  bool json = false;
};

// The tests of the run: each table axis of the control in each set-up, in the model's order
// (the trunnion's: C, then A).
std::vector<kin::RotaryBallbarTest> run_tests(const kin::FiveAxisMachine& control,
                                              const RunOptions5x& o) {
  std::vector<kin::RotaryBallbarTest> out;
  for (const auto& r : control.rotary) {
    if (r.side != kin::Side::table) continue;
    const std::string letter(kin::to_string(r.letter));
    for (const auto& setup : o.setups) {
      kin::RotaryBallbarTest t;
      t.axis = r.letter;
      t.setup = kin::bar_setup_from_string(setup);
      t.name = fmt::format("{}-{}", letter, setup);
      t.table_ball_mm = {o.ball_mm.at(0), o.ball_mm.at(1), o.ball_mm.at(2)};
      t.length_mm = o.length_mm;
      t.angles_deg = o.angles_deg.at(letter);
      (void)kin::bar_direction(control, t);  // refused here, naming the test, when unusable
      out.push_back(std::move(t));
    }
  }
  if (out.empty())
    throw cal::InputError(fmt::format(
        "{}: no rotary table axis: the five-axis ballbar tests here are of table axes", o.control));
  return out;
}

void print_run_result(const json& doc, std::int64_t run_id, bool corrected) {
  fmt::print("run {}: five-axis ballbar, location errors{}\n", run_id,
             corrected ? " (left: the fitted less the control's own)" : "");
  for (const auto& a : doc["axes"]) {
    fmt::print(
        "Axis {}: {} tests, residual RMS {:.3f} um, sigma {:.3f} um, {} degrees of freedom\n",
        a["axis"].get<std::string>(), a["tests"].size(), a["rms_um"].get<double>(),
        a["sigma_um"].get<double>(), a["dof"].get<int>());
    for (const auto& name : a["names"]) {
      const auto& v = a["location"][name.get<std::string>()];
      fmt::print("  {:6} {:+10.3f} {:4}  u = {:.3f}{}\n", name.get<std::string>(),
                 v["value"].get<double>(), v["unit"].get<std::string>(),
                 v["uncertainty"].get<double>(),
                 corrected ? fmt::format("  left {:+.3f}", v["left"].get<double>()) : "");
    }
    for (const auto& t : a["tests"])
      fmt::print("  test {} ({} stops): bar offset {:+.3f} um\n", t["test"].get<std::string>(),
                 t["stops"].size(), t["offset_um"].get<double>());
  }
}

// The location limits of the rotary axes tested, from a file of [tolerances] tables only
// (docs/config.md); a file with none for these axes is refused (it would judge nothing).
std::map<std::string, cal::daq::AxisTolerance> location_tolerances(
    const std::string& file, const std::vector<kin::RotaryBallbarTest>& tests) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw cal::InputError(fmt::format("--tolerances {}: cannot read", file));
  const std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  auto c = cal::daq::parse_tolerances(text, file);  // checked, naming file:line:column
  std::vector<std::string> axes;
  for (const auto& t : tests) {
    const std::string a(kin::to_string(t.axis));
    if (std::find(axes.begin(), axes.end(), a) != axes.end()) continue;
    axes.push_back(a);
    const auto it = c.axis_tolerances.find(a);
    if (it != c.axis_tolerances.end() &&
        (it->second.limits.location_um || it->second.limits.location_urad))
      return std::move(c.axis_tolerances);
  }
  throw cal::InputError(fmt::format(
      "--tolerances {}: no location_um or location_urad in [tolerances.{}]: nothing would judge "
      "the location errors of the axes tested (docs/config.md)",
      file, fmt::join(axes, "] or [tolerances.")));
}

void run_run(const RunOptions5x& given) {
  auto models = read_truth_control(given, given.db);
  RunOptions5x o = given;  // the files, or the stored models' labels: what the run records
  o.truth = models.truth.label;
  o.control = models.control->label;
  const auto truth = mdl::five_axis(models.truth.model);
  mdl::Model nominal = std::move(models.control->model);
  const kin::FiveAxisMachine control = control_machine(nominal, o.control, o.hal, o.swivel);
  const bool corrected = !o.hal.empty() || !o.swivel.empty() || [&] {
    for (const auto& r : control.rotary)
      for (std::size_t i = 0; i < 3; ++i)
        if (r.location_position_um.at(i) != 0.0 || r.location_orientation_urad.at(i) != 0.0)
          return true;
    return false;
  }();
  RotaryBallbarRunSetup setup;
  setup.config.machine_name = fmt::format("SIMULATED five-axis ({})", o.truth);
  setup.config.machine_description =
      "built-in simulated five-axis machine with injected location errors (daq model "
      "ballbar5x-run)";
  setup.config.campaign = "five-axis ballbar (simulated)";
  setup.control = control;
  setup.tests = run_tests(control, o);
  if (!o.tolerances.empty()) {
    setup.config.axis_tolerances = location_tolerances(o.tolerances, setup.tests);
    setup.tolerances_file = std::filesystem::absolute(o.tolerances).string();
  }
  setup.database = database_path(o.db);
  const std::string database = setup.database.string();
  setup.extra_settings_json =
      json{{"simulated", true}, {"truth_model", o.truth},    {"control_model", o.control},
           {"hal", o.hal},      {"swivel", o.swivel},        {"noise_um", o.noise_um},
           {"seed", o.seed},    {"offsets_um", o.offsets_um}}
          .dump();
  std::FILE* log = o.json ? stderr : stdout;
  setup.on_event = [log](const std::string& e) { fmt::print(log, "{}\n", e); };
  fmt::print(log,
             "SIMULATED five-axis ballbar: {} running the control's program ({}{}), {} tests, "
             "{:g} um of noise per sample\n",
             o.truth, o.control,
             o.hal.empty() ? o.swivel.empty() ? "" : " with " + o.swivel : " with " + o.hal,
             setup.tests.size(), o.noise_um);
  const auto out = run_simulated_ballbar5x(
      {.truth = truth, .noise_um = o.noise_um, .offset_um = o.offsets_um, .seed = o.seed},
      std::move(setup));
  const json doc = json::parse(out.result_json);
  if (o.json)
    fmt::print("{}\n",
               json{{"run_id", out.run_id}, {"readings", out.readings}, {"result", doc}}.dump(2));
  else
    print_run_result(doc, out.run_id, corrected);
  if (o.write.empty()) return;
  if (corrected)
    throw cal::InputError(
        "--write against a corrected control: the fit is what the correction left; write the "
        "model from a run against the nominal kinematics");
  const auto fitted = fitted_locations(doc);
  for (auto& r : nominal.rotary) {
    const auto names = kin::location_error_names(r.axis.letter);
    std::array<const FittedLocation*, 4> found{};
    for (std::size_t k = 0; k < 4; ++k)
      for (const auto& f : fitted)
        if (f.name == names[k]) found.at(k) = &f;
    if (!found[0]) continue;  // an axis the run did not measure (a head axis)
    std::array<double, 4> value{};
    for (std::size_t k = 0; k < 4; ++k) value.at(k) = found.at(k)->value;
    kin::FiveAxisMachine one;
    one.rotary = {r.axis};
    r.axis = kin::with_location_errors(one, r.axis.letter, value).rotary.front();
    for (std::size_t k = 0; k < 4; ++k) {
      r.location[k].given = true;
      r.location[k].uncertainty = found.at(k)->uncertainty;
      r.location[k].source = {json{
          {"kind", "ballbar, rotary axis"},
          {"run", out.run_id},
          {"database", database}}.dump()};
    }
  }
  mdl::write(nominal, o.write);
  fmt::print(stderr, "model with the fitted location errors written to {}\n", o.write);
}
}  // namespace

void add_model_ballbar5x_commands(CLI::App& model) {
  const auto [fit, f] = add_command<FitOptions>(
      model, "ballbar5x", run_fit,
      "Fit each rotary table axis's four location errors (with their uncertainty) to ballbar "
      "readings taken while the axis turned and the linear axes followed (a CSV as "
      "ballbar5x-sim writes)");
  fit->add_option("readings", f->readings,
                  "CSV of readings with the columns " + columns_text() +
                      " (one test per name; several tests and axes in one file)")
      ->required();
  fit->add_option("--model", f->model,
                  "Model file (caldaq.model.v2), or a stored model's UUID or number with --db: "
                  "the machine as the control believes it, the kinematics the test's program was "
                  "computed with")
      ->required();
  add_model_db_option(*fit, f->db);
  fit->add_option("--reading-u-um", f->reading_u_um,
                  "Standard uncertainty of one reading (0: from the residuals)")
      ->check(finite_in(0.0, 1e4));
  fit->add_option("--write", f->write,
                  "Write the model with the fitted location errors (and their uncertainty and "
                  "source) to this file");
  fit->add_flag("--json", f->json, "Print caldaq.rotary-ballbar-fit.v1 JSON");

  const auto [run, r] = add_command<RunOptions5x>(
      model, "ballbar5x-run", run_run,
      "SIMULATED five-axis ballbar run: the simulated machine (its truth) runs the control's "
      "five-axis ballbar program for each table axis and set-up while the bar's gauge twin "
      "streams; the gauge driver reads the stream, the run stores it (kind ballbar5x, see daq "
      "runs / daq show) and fits each axis's location errors with their uncertainty");
  add_machine_options(*run, *r, true);
  run->add_option("--hal", r->hal,
                  "The control holds these LinuxCNC trunnion pins (daq model kinematics) over "
                  "--control's rotary lines");
  run->add_option("--swivel", r->swivel,
                  "The control holds this SINUMERIK CYCLE800 swivel data record over --control's "
                  "rotary lines");
  add_db_option(*run, r->db);
  run->add_option("--ball-mm", r->ball_mm,
                  "The table ball's centre on the workpiece X Y Z (home coordinates)")
      ->required()
      ->expected(3)
      ->check(finite_in(-kMaxPositionMm, kMaxPositionMm));
  run->add_option("--length-mm", r->length_mm, "The bar's nominal length")
      ->check(finite_in(1.0, 2000.0))
      ->capture_default_str();
  run->add_option("--setups", r->setups, "The set-ups of the bar, each a test of each table axis")
      ->check(CLI::IsMember({"radial", "tangential", "axial"}))
      ->capture_default_str();
  for (const char* letter : {"C", "A", "B"})
    run->add_option(fmt::format("--{}-angles-deg", char(std::tolower(letter[0]))),
                    r->angles_deg[letter],
                    fmt::format("The angles at which the {} axis's tests read the bar", letter))
        ->check(finite_in(-3600.0, 3600.0))
        ->capture_default_str();
  run->add_option("--offsets-um", r->offsets_um,
                  "Each test's bar zero (the bar's length calibration and the set-up), in the "
                  "order of the tests")
      ->check(finite_in(-1e3, 1e3));
  run->add_option("--noise-um", r->noise_um, "Gaussian noise of each bar sample (100 Hz)")
      ->check(finite_in(0.0, 100.0))
      ->capture_default_str();
  run->add_option("--seed", r->seed, "Seed of the noise")->capture_default_str();
  run->add_option("--write", r->write,
                  "Write the control's model with the fitted location errors (a run against the "
                  "nominal kinematics only)");
  run->add_option("--tolerances", r->tolerances,
                  "A file of [tolerances.C] ... tables: location_um and location_urad limit each "
                  "location error left (stored with the run: its verdict in daq show and the "
                  "report; docs/config.md)");
  run->add_flag("--json", r->json, "Print the run id and its result (caldaq.ballbar5x.v1)");

  const auto [sim, s] = add_command<SimOptions>(
      model, "ballbar5x-sim", run_sim,
      "Simulated ballbar on a rotary table axis: the readings a model (the simulated machine's "
      "truth) gives when it runs the program the control's model computed, as a CSV for daq "
      "model ballbar5x");
  add_machine_options(*sim, *s, false);
  add_test_options(sim, s->t);
  sim->add_option("--offset-um", s->offset_um,
                  "A constant added to every reading (the bar's zero and the balls' set-up)")
      ->check(finite_in(-1e3, 1e3));
  sim->add_option("--noise-um", s->noise_um, "Gaussian noise per reading, standard deviation")
      ->check(finite_in(0.0, 1e3));
  sim->add_option("--seed", s->seed, "Seed of the noise")->capture_default_str();
  sim->add_option("-o,--output", s->output, "Write the CSV here (default: standard output)");

  const auto [prog, p] = add_command<ProgramOptions>(
      model, "ballbar5x-program", run_program,
      "Part program of a ballbar test on a rotary table axis: the axis turns, X Y Z follow the "
      "ball (computed with the model's kinematics), a dwell at each angle read");
  prog->add_option("--model", p->model,
                   "Model file, or a stored model's UUID or number with --db: the machine as the "
                   "control believes it")
      ->required();
  add_model_db_option(*prog, p->db);
  add_test_options(prog, p->t);
  prog->add_option("--dialect", p->dialect, "fanuc, iso, heidenhain, siemens or sinumerik")
      ->check(CLI::IsMember({"fanuc", "iso", "heidenhain", "siemens", "sinumerik"}))
      ->capture_default_str();
  prog->add_option("--feed", p->feed, "Feed word of every block (the control's units)")
      ->check(finite_in(1.0, 1e5))
      ->capture_default_str();
  prog->add_option("--dwell-s", p->dwell_s, "Dwell at each angle read")
      ->check(finite_in(0.1, 3600.0))
      ->capture_default_str();
  prog->add_option("--max-step-deg", p->max_step_deg,
                   "Largest turn of one block (the bar leaves its length by the sag between)")
      ->check(finite_in(0.01, 30.0))
      ->capture_default_str();
  prog->add_option("--program-name", p->program_name, "Program name (letters, digits, '_')")
      ->capture_default_str();
  prog->add_option("-o,--output", p->output, "Write the program here (default: standard output)");
}

}  // namespace daq
