// daq sim: the built-in SIMULATED shop as a separate process, for practising and for testing
// `daq run linear|circle` and `daq serve` end to end: the twins listen on a loopback TCP port
// and on pseudo-terminals, and a configuration file naming them is written. The simulated
// machine runs a test's program when a run of that test starts in the run database (as an
// operator presses Cycle Start once the acquisition waits), or once after --start-after-s. The
// acquiring process only sees devices.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <optional>

#include "cal/analysis/error.hpp"
#include "cal/analysis/volumetric_comp.hpp"
#include "cal/drivers/loop_time.hpp"
#include "cal/storage/store.hpp"
#include "circle_run.hpp"
#include "cli_checks.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "config_tolerances.hpp"
#include "database.hpp"
#include "linear_run.hpp"
#include "model/model_file.hpp"
#include "model_cli.hpp"
#include "run_setup.hpp"
#include "sim_shop.hpp"
#include "sim_volumetric.hpp"

namespace daq {
namespace {

using namespace std::chrono_literals;

struct SimOptions {
  std::string config_out = "caldaq-sim.toml";
  std::string test;  // empty: circle, or linear with --measure (resolved by test_of)
  double speed = 1.0;
  std::optional<double> start_after_s;  // unset: wait for a run in the database
  std::string db;
  bool position_feed = false;
  int runs = 5;                   // the linear program's size (ShopConfigOptions)
  std::optional<int> targets;     // unset: 11 (the linear program's; the rotary test has 9)
  double feed_mm_per_min = 1000;  // the circle's
  double ballbar_rate_hz = 1000;  // the simulated bar's output rate
  // A vibration of Y (ShopTruth::vibration_y_um, _hz): a ballbar circle in XY with a vibration
  // to find (issue 32: its line fit is paid only when one is found).
  double vibration_y_um = 0, vibration_y_hz = 0;
  std::string measure;  // a component of the volumetric campaign, e.g. E_YX
  std::string topology = "YFXZ";
  std::string compensate;  // a model whose volumetric correction the control applies
  std::string model_db;    // where --compensate is kept when not a file (default: --db)
  // Or the files of a cross-axis or volumetric compensation the control loads (control_loads),
  // read as its vendor says or with the other sign (docs/compensation-tables.md,
  // "Verification").
  std::vector<std::string> control_table;
  std::string control_format;
  bool control_inverted = false;
  bool acquire = false;    // run the acquisition in this process, on simulated time
  std::string capture;     // with acquire: the run's capture file
  bool json = false;       // with acquire: the result as JSON on stdout (as daq run --json)
  std::string truth_out;   // write the volumetric machine's injected errors as a model, exit
  std::string tolerances;  // with measure: a file of [tolerances] tables added to the config
  std::vector<double> truth_tool_offset_mm;  // with truth_out: the tool the model is for
  // With --test rotary: the SIMULATED control's correction of the C axis (an as left run after
  // it): its backlash compensation (arcsec) and its scale (pitch) correction (arcsec per turn),
  // taken off the injected lost motion and scale error (ShopTruth::Rotary).
  std::optional<double> control_backlash_arcsec, control_scale_arcsec_per_turn;
};

// The rotary axis as the control moves it with its corrections (--control-backlash-arcsec,
// --control-scale-arcsec-per-turn): the injected backlash and scale error less them. The
// simulated servo's lost motion cannot be negative, so a backlash compensation larger than the
// injected 6" is refused rather than clamped.
void apply_rotary_correction(const SimOptions& o, ShopTruth::Rotary& r) {
  if (o.control_backlash_arcsec) {
    if (*o.control_backlash_arcsec > r.backlash_arcsec)
      throw cal::InputError(fmt::format(
          "--control-backlash-arcsec {}: more than the SIMULATED C axis's backlash ({}\"): the "
          "simulated servo cannot over-compensate",
          *o.control_backlash_arcsec, r.backlash_arcsec));
    r.backlash_arcsec -= *o.control_backlash_arcsec;
  }
  if (o.control_scale_arcsec_per_turn) r.scale_arcsec_per_turn -= *o.control_scale_arcsec_per_turn;
}

std::string numbers(const std::array<double, 3>& v) {
  return fmt::format("[{}, {}, {}]", v[0], v[1], v[2]);
}

// The [test.linear] of a volumetric campaign test (kinds/kind.hpp; docs/config.md).
std::string linear_toml(const cal::daq::LinearTestConfig& l) {
  const auto& m = l.measure;
  std::string t = fmt::format(
      "[test.linear]\naxis = \"{}\"\nfirst_mm = {}\nlast_mm = {}\ncount = {}\nruns = {}\n"
      "overrun_mm = {}\nfeed_mm_per_min = {}\ndwell_s = {}\nmeasure = \"{}\"\n"
      "stationary_mm = {}\nprobe_offset_mm = {}\n",
      l.axis, l.first_mm, l.last_mm, l.count.value_or(6), l.runs, l.overrun_mm, l.feed_mm_per_min,
      l.dwell_s, m.kind, numbers(m.stationary_mm), numbers(m.probe_offset_mm));
  if (!m.direction.empty()) t += fmt::format("direction = \"{}\"\n", m.direction);
  if (m.kind == "angular")
    t += fmt::format("beams = [{}, {}]\nseparation_mm = {}\n", m.beams[0], m.beams[1],
                     numbers(m.separation_mm));
  if (m.square) t += "square = true\n";
  return t;
}

// The configuration of a volumetric campaign test: the shop's devices and the test of one
// component on the machine with all 21 errors (times divided by the speed as for the others).
std::string volumetric_config(const SimulatedShop& shop, double speed,
                              const cal::daq::LinearTestConfig& test) {
  return fmt::format(
      R"TOML(# Written by `daq sim --measure`: the devices of the built-in SIMULATED shop (running
# {speed}x faster than real time) and the test of one component. Valid while that process runs.
campaign = "volumetric (simulated)"

[machine]
name = "SIMULATED {topology}"
description = "built-in simulated machine with all 21 geometric errors injected (daq sim)"
topology = "{topology}"

{devices}
[environment]
equation = "ciddor"
expansion_ppm_per_k = {alpha}

[trigger]
tolerance_um = 1
dwell_s = {trigger_dwell}
window_mm = 0.5

{linear})TOML",
      fmt::arg("devices", shop.devices_toml(0.01 / speed, false, false)), fmt::arg("speed", speed),
      fmt::arg("alpha", shop.truth().expansion_ppm_per_k), fmt::arg("trigger_dwell", 1.5 / speed),
      fmt::arg("topology", cal::kinematics::to_string(shop.truth().geometry->topology)),
      fmt::arg("linear", linear_toml(test)));
}

// The [tolerances] tables of a file, as text to add to the configuration `daq sim --measure`
// writes (which has none: the volumetric machine has no specification of its own). Anything
// else in the file is refused, naming it: the rest of the configuration is the shop's.
std::string tolerances_toml(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw cal::InputError(fmt::format("--tolerances {}: cannot read", file));
  std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  cal::daq::parse_tolerances(text, file);  // checked, naming file:line:column
  return "\n# Added by daq sim --tolerances\n" + text + "\n";
}

// The rotary test's specification: a file of [tolerances.A|B|C] tables only (the shop's
// configuration has the demo's linear axes' and planes' tables already).
std::string rotary_tolerances_toml(const std::string& file) {
  const std::string text = tolerances_toml(file);
  const auto c = cal::daq::parse_tolerances(text, file);
  for (const auto& [name, t] : c.axis_tolerances)
    if (name != "A" && name != "B" && name != "C")
      throw cal::InputError(fmt::format(
          "--tolerances {}: [tolerances.{}]: with --test rotary only a rotary axis's table "
          "(A, B, C) is added (the shop's configuration has its own linear limits)",
          file, name));
  if (!c.plane_tolerances.empty())
    throw cal::InputError(fmt::format(
        "--tolerances {}: [tolerances.{}]: with --test rotary only a rotary axis's table (A, B, "
        "C) is added",
        file, c.plane_tolerances.begin()->first));
  return text;
}

// A run that has started in the database since `after` (its id), or nullopt. The database may
// be busy with the acquiring process's writes: a failed look is retried at the next poll.
std::optional<cal::storage::RunRecord> new_run(const std::filesystem::path& db,
                                               std::int64_t after) {
  try {
    cal::storage::Store store(db);
    for (const auto& r : store.runs())
      if (r.id > after && r.status == cal::storage::RunStatus::running) return r;
  } catch (const cal::storage::StoreError&) {
  }
  return std::nullopt;
}

std::int64_t newest_run(const std::filesystem::path& db) {
  cal::storage::Store store(db);
  std::int64_t id = 0;
  for (const auto& r : store.runs()) id = std::max(id, r.id);
  return id;
}

// The test to run: --test, else a --measure component's (a linear one), else circle. An
// option the chosen test would not use is refused, not ignored.
std::string test_of(const SimOptions& o) {
  if (!o.measure.empty() && !o.test.empty() && o.test != "linear")
    throw cal::InputError(fmt::format(
        "--measure {} with --test {}: a component of the volumetric campaign is measured by a "
        "linear test; leave out --test (or give --test linear)",
        o.measure, o.test));
  if (o.test == "rotary" && o.targets)
    throw cal::InputError(
        "--targets with --test rotary: the rotary test's targets are fixed (0 .. 360 deg every "
        "45 deg); --targets sizes the linear program");
  return !o.test.empty() ? o.test : !o.measure.empty() ? "linear" : "circle";
}

void run_sim(SimOptions o) {
  if (!o.truth_out.empty()) {
    auto truth = volumetric_truth_model(cal::kinematics::topology_from_string(o.topology));
    if (!o.truth_tool_offset_mm.empty())
      truth.machine.tool_offset_mm = {o.truth_tool_offset_mm[0], o.truth_tool_offset_mm[1],
                                      o.truth_tool_offset_mm[2]};
    cal::daq::model::write(truth, o.truth_out);
    return fmt::print("The SIMULATED volumetric machine's injected errors ({}) written to {}\n",
                      o.topology, o.truth_out);
  }
  o.test = test_of(o);
  if (o.test != "linear" && o.test != "circle" && o.test != "circle-set" && o.test != "rotary")
    throw cal::InputError(
        fmt::format("--test '{}' (expected linear, circle, circle-set or rotary)", o.test));
  const bool set = o.test == "circle-set";  // the standard set on the three-plane machine
  const bool rotary = o.test == "rotary";   // a C axis read by its angular reference
  if (rotary && (!o.measure.empty() || o.position_feed))
    throw cal::InputError("--test rotary: without --measure or --position-feed");
  if (!rotary && (o.control_backlash_arcsec || o.control_scale_arcsec_per_turn))
    throw cal::InputError(
        "--control-backlash-arcsec and --control-scale-arcsec-per-turn correct the SIMULATED "
        "rotary axis: give --test rotary");
  std::optional<cal::daq::LinearTestConfig> volumetric;
  ShopTruth truth = set ? ShopTruth::three_planes() : ShopTruth{};
  truth.ballbar_rate_hz = o.ballbar_rate_hz;
  if (o.vibration_y_um > 0 || o.vibration_y_hz > 0) {
    if (!(o.vibration_y_um > 0 && o.vibration_y_hz > 0))
      throw cal::InputError("--vibration-y-um and --vibration-y-hz go together, both above 0");
    // The analysis looks for a vibration below 0.45 of the sample rate (0.9 x Nyquist,
    // docs/circle.md); a faster one would be sampled as an alias and reported at a false
    // frequency.
    if (o.vibration_y_hz >= 0.45 * o.ballbar_rate_hz)
      throw cal::InputError(fmt::format(
          "--vibration-y-hz {} Hz: at or above {} Hz (0.45 x --ballbar-rate-hz {}), where the "
          "ballbar's samples would alias it; give a lower frequency or a faster ballbar",
          o.vibration_y_hz, 0.45 * o.ballbar_rate_hz, o.ballbar_rate_hz));
    truth.vibration_y_um = o.vibration_y_um;
    truth.vibration_y_hz = o.vibration_y_hz;
  }
  apply_rotary_correction(o, truth.rotary);
  if (!o.measure.empty()) {
    volumetric = volumetric_test(o.measure);
    truth = volumetric_truth(cal::kinematics::topology_from_string(o.topology), 0.02);
  } else if (!o.compensate.empty() || !o.control_table.empty()) {
    throw cal::InputError(
        "--compensate and --control-table apply to the volumetric machine: give --measure too");
  }
  if (!o.compensate.empty() && !o.control_table.empty())
    throw cal::InputError("--compensate or --control-table: the control applies one of them");
  if (o.acquire && (o.start_after_s || o.speed != 1.0))
    throw cal::InputError(
        "--acquire runs the program when its own run starts, on simulated time: without "
        "--start-after-s or --speed");
  boost::asio::io_context io;
  // --acquire: the shop, the instruments and the run on one simulated time line that jumps
  // from event to event (cal/drivers/loop_time.hpp), as in daq demo.
  if (o.acquire) cal::drivers::VirtualTime::install(io);
  SimulatedShop shop(
      io, truth, o.speed,
      rotary ? simulated_rotary_test(o.runs) : volumetric.value_or(cal::daq::LinearTestConfig{}));
  if (!o.compensate.empty()) {
    // The control applies the model's full volumetric correction (cal::volcomp::correction_um,
    // what `daq model compensate -f isg-volumetric` writes for a controller), with each
    // position held within the model's tables (the overrun moves go a few mm past them).
    auto in = read_model_input(o.compensate, model_db_of(o.model_db, o.db));
    const auto model = std::move(in.model);
    cal::daq::model::require_no_rotary(model, in.label, "daq sim --compensate");
    if (!model.travel_mm) throw cal::InputError(fmt::format("{}: no travel_mm", in.label));
    shop.set_compensation([model](const cal::kinematics::Vec3& p) {
      cal::kinematics::Vec3 q = p;
      for (std::size_t k = 0; k < 3; ++k)
        q[k] = std::clamp(q[k], (*model.travel_mm)[k][0], (*model.travel_mm)[k][1]);
      return cal::volcomp::correction_um(model.machine, q, model.carriers);
    });
  }
  if (!o.control_table.empty()) {
    // With their names: a HEIDENHAIN *.CMA assigns the *.COM tables by name.
    std::vector<cal::comptable::CompFile> texts;
    for (const auto& f : o.control_table) {
      std::ifstream in(f, std::ios::binary);
      if (!in) throw cal::InputError(fmt::format("{}: cannot read", f));
      texts.push_back({std::filesystem::path(f).filename().string(),
                       {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()}});
    }
    shop.set_compensation(control_loads(o.control_format, texts, o.control_inverted));
    fmt::print("daq sim: the SIMULATED control applies {} ({}{})\n",
               fmt::join(o.control_table, ", "), o.control_format,
               o.control_inverted ? ", read with the other sign" : "");
  }
  if (!o.tolerances.empty() && !volumetric && !rotary)
    throw cal::InputError(
        "--tolerances applies to --measure and --test rotary (the other tests' configurations "
        "have the demo's specification)");
  const std::string text =
      volumetric
          ? volumetric_config(shop, o.speed, *volumetric) +
                (o.tolerances.empty() ? "" : tolerances_toml(o.tolerances))
          : simulated_shop_config(shop, {.speed = o.speed,
                                         .position_feed = o.position_feed,
                                         .in_process = false,
                                         .runs = o.runs,
                                         .targets = o.targets.value_or(11),
                                         .circle_set = set,
                                         .rotary = rotary,
                                         .circle_feed_mm_per_min = o.feed_mm_per_min}) +
                (rotary && !o.tolerances.empty() ? rotary_tolerances_toml(o.tolerances) : "");
  {
    std::ofstream out(o.config_out);
    if (!(out << text)) throw cal::InputError(fmt::format("{}: cannot write", o.config_out));
  }
  const auto config = cal::daq::parse_config(text, o.config_out);
  // The shop's clock advances when it is read (a starved process slows the simulation down
  // rather than skipping it), so the loop reads it every few milliseconds itself: the twins
  // alone read it only when a client asks.
  const auto run_until = [&](double sim_s) {
    while (shop.now_s() < sim_s) io.run_for(2ms);
  };
  // The machine starts the test's program (it ends at shop.program_end_s()).
  const auto start_program = [&](const std::string& test) {
    if (test == "circle" && set) {  // the whole set in one program, as daq gcode writes it
      std::vector<cal::daq::BallbarSetTest> program;
      for (const auto& t : circle_tests(config)) program.push_back({t.plane, t.program});
      shop.run_circle_set(program);
    } else if (test == "circle") {
      shop.run_circle(circle_test(config).first);
    } else {
      const auto& l = *config.linear;
      shop.run_linear(linear_plan(l), l.feed_mm_per_min, l.dwell_s);
    }
  };
  if (o.acquire) {
    // `daq run TEST --config FILE` in this process: the same configuration, instruments, run,
    // output and capture.
    const std::string test = o.test == "linear" || rotary ? "linear" : "circle";
    std::FILE* out = o.json ? stderr : stdout;  // stdout carries only the JSON then
    fmt::print(out,
               "daq sim: SIMULATED shop on simulated time in this process; acquiring as `daq run "
               "{} --config {}` does\n",
               test, o.config_out);
    std::fflush(out);
    RunOptions ro{
        .config = o.config_out, .db = o.db, .capture = o.capture, .json = o.json, .check_s = 0};
    ro.clock = shop.clock_ns();
    auto& vt = *cal::drivers::VirtualTime::of(io);
    const RunDriver drive = [&](const std::function<bool()>& finished) {
      // The instruments connect and the machine rests on its first target (a rest is no stop)
      // for 5 simulated seconds before the program starts, as after an operator's Cycle Start.
      vt.run_for(5s, finished);
      start_program(test);
      shop.run_program(finished, 3.0);
    };
    return test == "linear" ? run_linear_test(ro, io, drive) : run_circle_test(ro, io, drive);
  }
  const auto run_program = [&](const std::string& test) {
    const double t0_s = shop.now_s();
    start_program(test);
    fmt::print("daq sim: {} program started ({:.0f} s of simulated time)\n", test,
               shop.program_end_s() - t0_s);
    std::fflush(stdout);
    // The program, then a little more so the acquiring side can finish reading.
    run_until(shop.program_end_s() + 3.0 * o.speed);
    fmt::print("daq sim: program ended\n");
    std::fflush(stdout);
  };
  if (o.start_after_s) {
    fmt::print(
        "daq sim: SIMULATED shop running {}x faster than real time; devices in {}\n"
        "  start `daq run {} --config {}` now: the machine starts the program in {} s\n",
        o.speed, o.config_out, o.test, o.config_out, *o.start_after_s);
    std::fflush(stdout);
    run_until(shop.now_s() + *o.start_after_s * o.speed);
    return run_program(set ? "circle" : rotary ? "linear" : o.test);
  }
  // As an operator would: the program is started once the acquisition waits for it (a run has
  // begun in the database), and it is the program of that run's test.
  const auto db = database_path(o.db);
  std::int64_t seen = newest_run(db);
  fmt::print(
      "daq sim: SIMULATED shop running {}x faster than real time; devices in {}\n"
      "  start a run (`daq run linear|circle --config {}`, or from `daq serve`) with the run\n"
      "  database {}: the machine runs that test's program once the run has started\n",
      o.speed, o.config_out, o.config_out, db.string());
  std::fflush(stdout);
  for (;;) {
    std::optional<cal::storage::RunRecord> run;
    while (!(run = new_run(db, seen))) {
      const auto until = std::chrono::steady_clock::now() + 200ms;
      while (std::chrono::steady_clock::now() < until) io.run_for(2ms), shop.now_s();
    }
    seen = run->id;
    const std::string test = run->kind == "circle" ? "circle" : "linear";
    if ((test == "linear" && !config.linear) || (test == "circle" && !config.circle)) continue;
    // The instruments of the run connect first (a program started while the laser still
    // connects would lose its first approach): a second of simulated settling.
    fmt::print("daq sim: run {} ({}) started\n", run->id, test);
    std::fflush(stdout);  // seen at once by whoever watches the log (a pipe is block-buffered)
    run_until(shop.now_s() + 1.0 * o.speed);
    run_program(test);
    if (volumetric) return;  // set up for one component's test: one run
    // A set's later tests are runs of their own, started while its one program ran: not
    // programs to start again.
    if (set) seen = newest_run(db);
  }
}

}  // namespace

void add_sim_command(CLI::App& app) {
  const auto [cmd, o] = add_command<SimOptions>(
      app, "sim", run_sim,
      "Run the built-in SIMULATED machine and instruments for `daq run` in another process");
  cmd->add_option("--test", o->test,
                  "linear, circle, circle-set (the ballbar set on a machine with errors in all "
                  "three planes) or rotary (a C axis's angular positioning, read by a SIMULATED "
                  "angular reference): the program run after --start-after-s (waiting for runs, "
                  "the run's own test is run). Default: circle; linear with --measure, which "
                  "takes no other test");
  cmd->add_option("-o,--config-out", o->config_out, "Where to write the devices' configuration")
      ->capture_default_str();
  cmd->add_option("--speed", o->speed, "Simulated time per real time")
      ->capture_default_str()
      ->check(finite_in(1.0, 100.0));
  cmd->add_option("--start-after-s", o->start_after_s,
                  "Run the --test program once, this many wall-clock seconds after the start "
                  "(default: wait for each run to start in the database, and run its test)")
      ->check(finite_non_negative());
  add_db_option(*cmd, o->db);
  cmd->add_option("--runs", o->runs, "Runs of the linear program (ISO 230-2: 5)")
      ->capture_default_str()
      ->check(whole_in(2, 10));
  cmd->add_option("--targets", o->targets,
                  "Targets of the linear program, 50 mm apart from 0 mm (ISO 230-2: 11; default "
                  "11; not with --test rotary, whose targets are fixed)")
      ->check(whole_in(2, 11));
  // Down to 10 mm/min: a slow circle is the ballbar's static test (the servo's errors vanish,
  // stick-slip grows: docs/circle.md); at 26 mm/min the 100 mm bar's circle takes an hour.
  cmd->add_option("--feed-mm-per-min", o->feed_mm_per_min,
                  "The circle test's feed (--test circle; the set has its own two)")
      ->capture_default_str()
      ->check(finite_in(10.0, 10000.0));
  cmd->add_option("--ballbar-rate-hz", o->ballbar_rate_hz,
                  "The SIMULATED ballbar's output rate and [test.circle] sample_rate_hz (a QC20-W "
                  "streams 1000 Hz; a faster gauge for long high-rate runs)")
      ->capture_default_str()
      ->check(finite_in(100.0, 20000.0));
  cmd->add_option("--vibration-y-um", o->vibration_y_um,
                  "A vibration of the SIMULATED Y axis: its amplitude (peak, um; a ballbar circle "
                  "in XY reads half of it as rms); with --vibration-y-hz")
      ->check(finite_in(0.0, 1000.0));
  cmd->add_option("--vibration-y-hz", o->vibration_y_hz,
                  "The SIMULATED Y axis' vibration's frequency (Hz)")
      ->check(finite_in(0.0, 100000.0));
  cmd->add_flag("--position-feed", o->position_feed,
                "Configure the MTConnect SHDR position feed (position-assisted trigger)");
  cmd->add_option("--measure", o->measure,
                  "A component of the SIMULATED volumetric campaign (E_XX ... E_CZ): the machine "
                  "with all 21 errors, set up to measure it, for one run "
                  "(docs/volumetric-walkthrough.md)");
  cmd->add_option("--topology", o->topology, "The simulated machine's chain with --measure")
      ->capture_default_str();
  cmd->add_option("--compensate", o->compensate,
                  "With --measure: the control applies this model's volumetric correction (a "
                  "file, or a stored model's UUID or number: see --model-db)");
  add_model_db_option(*cmd, o->model_db, true);
  cmd->add_option("--control-table", o->control_table,
                  "With --measure: the files of a cross-axis or volumetric compensation the "
                  "control loads (daq compensate --run on a straightness run, daq model "
                  "compensate)")
      ->take_all();
  cmd->add_option("--control-format", o->control_format,
                  "Their format: siemens-cec, isg-cross, linuxcnc-matrixkins, isg-volumetric, "
                  "heidenhain (the *.COM tables and their *.CMA) or csv")
      ->check(CLI::IsMember({"siemens-cec", "isg-cross", "linuxcnc-matrixkins", "isg-volumetric",
                             "heidenhain", "csv"}));
  cmd->add_flag("--control-inverted", o->control_inverted,
                "The control reads the values with the other sign than caldaq's reading of the "
                "vendor's text (to see daq verify diagnose it)");
  cmd->add_flag("--acquire", o->acquire,
                "Acquire the --test (or the --measure component's test) here instead of waiting "
                "for `daq run` in another process: "
                "`daq run TEST --config FILE` runs in this process on SIMULATED time (as fast as "
                "the CPU allows, the same on a loaded machine), prints what it prints and stores "
                "into --db");
  cmd->add_option("--tolerances", o->tolerances,
                  "With --measure: a TOML file of [tolerances.AXIS] tables (docs/config.md) "
                  "added to the configuration written, so the run is judged against them; "
                  "with --test rotary: its [tolerances.C] (limits in arcsec)");
  cmd->add_option("--truth-out", o->truth_out,
                  "Write the SIMULATED volumetric machine's injected errors (of --topology) as a "
                  "model file and exit: compare a built model with it (`daq model compare`)");
  cmd->add_option("--tool-offset-mm", o->truth_tool_offset_mm,
                  "--truth-out: the tool tip the truth is for, from the tool reference point (as "
                  "`daq model build --tool-offset-mm`)")
      ->expected(3)
      ->check(finite_in(-kMaxPositionMm, kMaxPositionMm));
  cmd->add_option("--control-backlash-arcsec", o->control_backlash_arcsec,
                  "With --test rotary: the SIMULATED control's backlash compensation of the C "
                  "axis (as set from an as-found run's B), taken off its injected 6\" of lost "
                  "motion (at most that)")
      ->check(finite_in(0.0, 3600.0));
  cmd->add_option("--control-scale-arcsec-per-turn", o->control_scale_arcsec_per_turn,
                  "With --test rotary: the SIMULATED control's scale (pitch) correction of the C "
                  "axis, taken off its injected 10\" per turn")
      ->check(finite_in(-3600.0, 3600.0));
  cmd->add_option("--capture", o->capture, "--acquire: record the run's wire-level capture here");
  cmd->add_flag(
      "--json", o->json,
      "--acquire: the result as JSON on stdout, as `daq run --json` (progress on stderr)");
}

}  // namespace daq
