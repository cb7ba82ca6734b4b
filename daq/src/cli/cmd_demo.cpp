// daq demo: the whole acquisition chain on the built-in SIMULATED shop. A simulated machine
// with known injected errors runs the ISO 230-2 program; the real drivers read the simulated
// IDS3010 (loopback TCP), PTU300 and material thermometer (pseudo-terminals); the pipeline
// compensates, detects the stops, labels them, stores everything in SQLite and evaluates the
// run; the simulated truth is printed beside the measured results.
#include <fmt/format.h>
#include <unistd.h>

#include <array>
#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>

#include "cal/analysis/comp_read.hpp"
#include "cal/analysis/error.hpp"
#include "cal/analysis/iso230_2.hpp"
#include "cal/daq/config.hpp"
#include "cal/drivers/instrument.hpp"
#include "cal/drivers/loop_time.hpp"
#include "cal/replay/capture.hpp"
#include "cal/replay/session.hpp"
#include "cal/storage/store.hpp"
#include "circle_output.hpp"
#include "circle_run.hpp"
#include "cli_checks.hpp"
#include "commands.hpp"
#include "database.hpp"
#include "iso230_2_output.hpp"
#include "linear_run.hpp"
#include "provenance.hpp"
#include "result_rows.hpp"
#include "roles.hpp"
#include "run_setup.hpp"
#include "session_spec.hpp"
#include "sim_shop.hpp"
#include "verdict.hpp"

namespace daq {
namespace {

namespace d = cal::drivers;
using namespace std::chrono_literals;

struct DemoOptions {
  std::string db = "caldaq-demo.sqlite";
  std::string capture = "caldaq-demo.cdq";
  double speed = 0.0;  // 0: simulated time that jumps from event to event (loop_time.hpp)
  bool quiet = false;
  bool linear_only = false;
  // A compensation table the simulated control loads for the X axis (docs/compensation-
  // tables.md, "Verification"): read as its vendor says, or with the other sign (inverted).
  std::string control_table, control_format;
  bool control_inverted = false;
};

cal::daq::Config demo_config() {
  cal::daq::Config c;
  c.machine_name = "SIMULATED VMC";
  c.machine_description = "built-in simulated 3-axis machine with injected errors";
  c.machine_make = "caldaq (simulated)";
  c.machine_model = "3-axis VMC simulator";
  c.machine_serial = "SIM-0001";
  c.campaign = "demo (simulated)";
  // What a customer report states, filled in for the simulated shop (docs/config.md). The
  // thermometer's calibration is past due on purpose: the report shows how that is warned.
  c.operator_name = "demo operator";
  c.customer = {.name = "Demo customer (simulated)", .site = "caldaq built-in simulated shop"};
  c.conditions = {.controller_compensation = false,
                  .warm_up = "none: the simulated machine is at a steady 21.5 °C",
                  .load = "no workpiece",
                  .state = "as found"};
  const auto device = [](std::string id, std::string driver, std::string role, std::string serial,
                         std::string due) {
    cal::daq::DeviceConfig d;
    d.id = std::move(id);
    d.driver = std::move(driver);
    d.role = std::move(role);
    d.transport = "simulated twin";
    d.serial_number = std::move(serial);
    d.certificate = "none (simulated instrument)";
    d.calibration_due = std::move(due);
    d.origin = "simulated";
    return d;
  };
  c.devices = {device("laser", "ids3010", "laser", "SIM-IDS-0001", "2099-12-31"),
               device("air", "ptu300", "air", "SIM-PTU-0001", "2099-12-31"),
               device("material", "gauge", "material", "SIM-TH-0001", "2020-01-31"),
               device("ballbar", "gauge", "ballbar", "SIM-BB-0001", "2099-12-31")};
  // A machine specification for the demo's 500 mm X axis and its XY circle: the injected
  // backlash (4 um) and servo mismatch exceed it, the rest is within. The axis is specified
  // by ISO 230-2 and by VDI/DGQ 3441 (`daq report 1 -s vdi3441` judges the run by the latter).
  c.axis_tolerances["X"] = {.limits = {.E_um = 10,
                                       .R_um = 6,
                                       .B_um = 3,
                                       .A_um = 12,
                                       .M_um = 8,
                                       .P_um = 15,
                                       .Pa_um = 10,
                                       .Ps_um = 6,
                                       .U_um = 3}};
  c.plane_tolerances["XY"] = {.G_um = 10,
                              .diagnostics = {{"squareness", 30.0}, {"backlash_X", 3.0}}};
  c.environment.equation = "ciddor";
  c.environment.expansion_ppm_per_k = 11.5;
  // In simulated seconds: the shop runs ~60x faster than the wall clock, and the instruments
  // poll on wall-clock timers, so a loaded machine's scheduling jitter is 60x larger in
  // simulated time; a real installation keeps the 10 s default.
  c.environment.stale_after_s = 60.0;
  c.trigger = {.tolerance_um = 1.0, .dwell_s = 1.5, .window_mm = 0.5};
  c.linear = cal::daq::LinearTestConfig{.axis = "X",
                                        .first_mm = 0,
                                        .last_mm = 500,
                                        .interval_mm = 50.0,
                                        .random_fraction = 0.2,
                                        .runs = 5,
                                        .overrun_mm = 3,
                                        .feed_mm_per_min = 6000,
                                        .dwell_s = 3};
  return c;
}

// The simulated control loads a table for X: it adds the correction the file holds as its
// vendor's text says (or with the other sign), forward values only (the demo's tables carry the
// reversal in the control's backlash parameter, which the simulated control does not have).
void load_control_table(SimulatedShop& shop, const DemoOptions& o) {
  if (o.control_table.empty()) return;
  std::ifstream in(o.control_table, std::ios::binary);
  if (!in) throw cal::InputError(fmt::format("{}: cannot read", o.control_table));
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  cal::comptable::Applied a;
  try {
    a = cal::comptable::read_applied(o.control_format, text, o.control_inverted);
  } catch (const cal::InputError& e) {
    throw cal::InputError(fmt::format("{}: {}", o.control_table, e.what()));
  }
  shop.set_compensation([a](const cal::kinematics::Vec3& p) {
    return cal::kinematics::Vec3{
        cal::comptable::correction_at_um(a.position_mm, a.forward_um, p[0]), 0.0, 0.0};
  });
  fmt::print("daq demo: the SIMULATED control applies {} ({} table{})\n", o.control_table,
             o.control_format, o.control_inverted ? ", read with the other sign" : "");
}

// One line of progress, rewritten in place on a terminal.
void progress_line(const LiveState& s, bool tty) {
  if (!s.progress.next_position_mm) return;
  const auto line = fmt::format(
      "run {} of {} {}  target {:2} of {}  {:+9.2f} um  air {:.2f} degC {:.0f} Pa {:.0f} %RH  "
      "material {:.2f} degC  {:+.2f} ppm",
      s.progress.run, s.progress.runs,
      s.progress.direction == cal::iso230_2::Direction::up ? "up  " : "down", s.progress.target,
      s.progress.targets, s.deviation_um, s.air_temperature_degc, s.pressure_pa, s.humidity_pct,
      s.material_degc, s.factor_ppm);
  if (tty) fmt::print("\r{}", line), std::fflush(stdout);
}

void print_comparison(const cal::iso230_2::Evaluation& measured,
                      const cal::iso230_2::Evaluation& truth, const ShopTruth& t) {
  fmt::print("\nSimulated truth vs measured ({}):\n", measured.standard.title);
  fmt::print("  {:<8} {:>10} {:>10} {:>9}\n", "", "truth um", "measured", "diff");
  for (const char* key : {"B_mean", "E_up", "E_down", "E_bi", "M"}) {
    const double a = truth.at(key).value_um, b = measured.at(key).value_um;
    fmt::print("  {:<8} {:>10} {:>10} {:>9}\n", measured.at(key).symbol, number_text(a),
               number_text(b), signed_number_text(b - a));
  }
  fmt::print(
      "  {:<8} {:>10} {:>10}   (repeatability: 4 s of the stop means; the noise-free\n"
      "  {:<8} {:>10} {:>10}    truth has none, the {:.2f} um noise is averaged over each stop)\n",
      measured.at("R_up").symbol, "-", number_text(measured.at("R_up").value_um), "", "", "",
      t.noise_um);
  fmt::print(
      "  Injected: scale {:+.1f} um/m, backlash {:.1f} um, pitch error {:.1f} um / {:.0f} mm,\n"
      "  noise {:.2f} um; machine at {:.1f} degC ({:.1f} ppm/K), so an uncompensated reading\n"
      "  would have been off by about {:+.0f} ppm (air) and {:+.0f} ppm (material).\n",
      t.scale_um_per_m, t.backlash_um, t.cyclic_amplitude_um, t.cyclic_period_mm, t.noise_um,
      t.machine_degc, t.expansion_ppm_per_k, 270.0, t.expansion_ppm_per_k * (t.machine_degc - 20));
}

// The circle's capture beside the linear run's: caldaq-demo.cdq -> caldaq-demo-circle.cdq.
std::string circle_capture_path(const std::string& linear_capture) {
  const std::filesystem::path p(linear_capture);
  return (p.parent_path() / (p.stem().string() + "-circle" + p.extension().string())).string();
}

// The ballbar part of the demo: a circle in XY about the table ball, the bar streaming at
// 1 kHz through the real gauge driver; the injected squareness, servo mismatch, backlash,
// scale and pitch errors beside what the diagnostics find.
int run_circle_demo(boost::asio::io_context& io, SimulatedShop& shop, cal::daq::Config config,
                    const DemoOptions& o) {
  const auto& t = shop.truth();
  // [test.circle] as its defaults configure it (XY, 1000 mm/min, 1 kHz, 45° overshoot, 1.5 mm
  // feed-in, 1 s dwell) about the shop's bar: in the run's context and the capture's header,
  // so `daq replay` of the capture runs the same program.
  config.circle = cal::daq::CircleTestConfig{.radius_mm = t.ballbar_mm};
  const auto program = circle_test(config).first;
  fmt::print("\ndaq demo: ballbar circle in XY, R {} mm at {} mm/min, on {} (simulated)\n",
             program.radius_mm, program.feed_mm_per_min, shop.ballbar_device());
  const auto& dc = need(config, "ballbar");
  const auto spec = spec_of(dc, 0);
  // The circle's bytes in a capture of their own (a capture holds one session's instruments),
  // so the circle replays as the linear run does.
  const auto capture_file = circle_capture_path(o.capture);
  SessionCapture capture(capture_file, config, {spec});
  CircleRunSetup setup{.config = config,
                       .program = program,
                       .database = o.db,
                       .ballbar = make_instrument(io, spec, make_transport(io, dc),
                                                  {.name = "ballbar (simulated)",
                                                   .clock = shop.clock_ns(),
                                                   .recorder = capture.recorder.get()}),
                       .capture_path = capture.absolute_path(capture_file),
                       .origins = {{"ballbar", origin_of(spec.origin, "")}},
                       .on_event = [&o](const std::string& e) {
                         if (!o.quiet) fmt::print("  {}\n", e);
                       }};
  CircleRun run(io, std::move(setup));
  // A capture that cannot be written (a full disk) aborts the circle as it does the linear run
  // (posted: the failure is seen inside the bar's handler).
  capture.recorder->on_failure([&io, &run](const std::string& e) {
    boost::asio::post(io, [&run, e] { run.stop("capture failed: " + e); });
  });
  run.start();
  shop.run_circle(program);
  shop.run_program([&] { return run.finished(); }, 20.0);
  if (!run.finished()) run.stop("the simulated circle ended before both traces were complete");
  capture.recorder->close();
  const auto& out = run.outcome();
  if (const auto& failure = capture.recorder->failure())
    throw cal::InputError(fmt::format(
        "the circle (run {}) {}: its capture {} failed: {}", out.run_id,
        out.complete ? "is complete and stored" : "was aborted", capture_file, *failure));
  if (!out.complete) {
    fmt::print(stderr, "daq demo: the circle did not complete: {}\n", out.reason);
    return 1;
  }
  const auto& r = *out.result;
  fmt::print("run {} stored ({} readings)\n", out.run_id, out.readings);
  // The same block as daq show and daq analyse print of it (one presentation of each result).
  const auto doc = circle_json(r, program.radius_mm, "XY", program.feed_mm_per_min);
  print_result(doc, "  ");
  std::map<std::string, double> found;
  for (const auto& dg : r.diagnostics) found[dg.key] = dg.value;
  print_verdict(circle_verdict(run_tolerances(config, "circle", "XY"), doc));
  fmt::print("\nSimulated truth vs measured (ballbar):\n");
  const double lag_ms = (1.0 / t.kv_y_per_s - 1.0 / t.kv_x_per_s) * 1e3;
  const auto row = [&](const char* name, double truth, const char* key, const char* unit) {
    fmt::print("  {:<26} {:>9} {:>9} {}\n", name, number_text(truth),
               number_text(found.count(key) ? found[key] : 0.0), unit);
  };
  row("squareness XY", t.squareness_um_per_m, "squareness", "um/m");
  row("servo mismatch (Y lags X)", lag_ms, "servo_mismatch", "ms");
  row("backlash X", t.backlash_um, "backlash_X", "um");
  row("scale mismatch X - Y", t.scale_um_per_m, "scale_mismatch", "um/m");
  row("cyclic error X", t.cyclic_amplitude_um, "cyclic_X", "um");
  fmt::print(
      "  (the scale mismatch also holds the servo loops' unequal attenuation on a circle,\n"
      "   (w/Kv_y)^2/2 - (w/Kv_x)^2/2 = +0.3 um/m here; backlash shares its step with the\n"
      "   reversal-spike term)\n");
  return 0;
}

int run_demo(const DemoOptions& o) {
  const bool tty = !o.quiet && ::isatty(STDOUT_FILENO);
  boost::asio::io_context io;
  // By default the shop and every timer of the session run on simulated time that jumps to
  // the next event: as fast as the CPU allows, and the same readings on a loaded machine.
  // --speed N paces it by the wall clock instead (N times faster), as `daq sim` does.
  if (o.speed == 0) d::VirtualTime::install(io);
  const double pace = o.speed > 0 ? o.speed : 1.0;  // simulated seconds per loop second
  SimulatedShop shop(io, ShopTruth{}, pace);

  const auto clock = shop.clock_ns();
  const auto poll = [&](double sim_s) {
    return std::chrono::microseconds(static_cast<std::int64_t>(sim_s / pace * 1e6));
  };
  // The shop's devices, configured as `daq sim` writes them; the instruments as the capture
  // header records them, so `daq replay` rebuilds them.
  auto config = demo_config();
  // The shop's devices (transports, drivers' options), with the demo's records of them.
  auto devices = cal::daq::parse_config(shop.devices_toml(0.01, false), "(simulated shop)").devices;
  for (auto& dc : devices)
    for (const auto& record : config.devices)
      if (record.id == dc.id) {
        dc.serial_number = record.serial_number;
        dc.certificate = record.certificate;
        dc.calibration_due = record.calibration_due;
      }
  config.devices = std::move(devices);
  const auto specs = linear_specs(config);
  cal::replay::CaptureWriter capture(o.capture,
                                     capture_header(config, specs, "daq 0.1.0 demo (simulated)"));
  cal::replay::CaptureRecorder recorder(capture);
  // The database and the capture open before the banner: a bad --db or --capture is the only
  // thing printed (the banner after the error read as if the demo had started). database_path:
  // a postgresql:// URI is refused saying why (the demo writes the local store), not as a file
  // SQLite cannot open.
  cal::storage::Store{database_path(o.db)};
  fmt::print("daq demo: ISO 230-2 test of the X axis of a SIMULATED machine (0 .. 500 mm)\n");
  fmt::print("  laser: simulated IDS3010 on tcp 127.0.0.1:{}\n", shop.laser_port());
  fmt::print("  air: simulated PTU300 on {} (4800 7E1)\n", shop.air_device());
  fmt::print("  material: simulated serial thermometer on {}\n", shop.material_device());
  if (o.speed > 0)
    fmt::print("  simulated time runs {}x faster than real time\n\n", o.speed);
  else
    fmt::print("  simulated time jumps from event to event (as fast as the CPU allows)\n\n");
  LinearRun* running = nullptr;  // a capture that cannot be written aborts the run
  recorder.on_failure([&io, &running](const std::string& e) {
    boost::asio::post(io, [&running, e] {
      if (running) running->stop("capture failed: " + e);
    });
  });
  // Poll periods in simulated seconds: the laser 0.01 s, the air and material sensors 1 s.
  const auto options = [&](const InstrumentSpec& s) {
    const double poll_s = s.role == "laser" ? 0.01 : 1.0;
    return d::InstrumentOptions{.name = s.role + " (simulated)",
                                .poll_period = poll(poll_s),
                                .clock = clock,
                                .recorder = &recorder};
  };
  LinearRunSetup setup;
  setup.config = config;
  setup.database = o.db;
  setup.capture_path = std::filesystem::absolute(o.capture).string();
  for (const auto& s : specs) {
    const auto& dc = *std::find_if(config.devices.begin(), config.devices.end(),
                                   [&](const auto& x) { return x.role == s.role; });
    place_linear_instrument(s, make_instrument(io, s, make_transport(io, dc), options(s)), setup);
  }
  setup.on_live = [tty](const LiveState& s) { progress_line(s, tty); };
  setup.on_event = [tty, &o](const std::string& e) {
    if (o.quiet) return;
    if (tty) fmt::print("\r\033[K");
    fmt::print("  {}\n", e);
    std::fflush(stdout);  // into a file or a pipe too, as it happens
  };
  StartupReadings read(setup.material.size());
  setup.on_reading = [&read](const cal::drivers::Reading& r) { read.add(r); };
  LinearRun run(io, std::move(setup));
  running = &run;
  run.start();
  if (!shop.wait_until([&] { return read.all(); })) {
    run.stop("the simulated instruments did not all answer within 10 s");
    fmt::print(stderr, "daq demo: the simulated instruments did not all answer within 10 s\n");
    return 1;
  }
  load_control_table(shop, o);
  shop.run_linear(run.plan(), config.linear->feed_mm_per_min, config.linear->dwell_s);
  // What is flushed survives a crash of this process.
  shop.run_program([&] { return run.finished(); }, 20.0, [&] { recorder.flush(); });
  if (!run.finished()) run.stop("the simulated program ended without all stops captured");
  if (tty) fmt::print("\r\033[K");
  recorder.close();
  running = nullptr;
  const auto& out = run.outcome();
  fmt::print("\nrun {} stored in {} ({} readings)\n", out.run_id,
             std::filesystem::absolute(o.db).string(), out.readings);
  // A full disk (store or capture) is the user's to fix: status 2, the file named.
  if (!out.complete &&
      (out.reason.starts_with("storage failed") || out.reason.starts_with("capture failed")))
    throw cal::InputError(fmt::format("run {} aborted: {}", out.run_id, out.reason));
  if (!out.complete) {
    fmt::print(stderr, "daq demo: the run did not complete: {}\n", out.reason);
    return 1;
  }
  if (recorder.failure())
    throw cal::InputError(fmt::format("run {} is complete and stored, but its capture failed: {}",
                                      out.run_id, *recorder.failure()));
  if (!out.missed.empty()) {
    fmt::print("INCOMPLETE: {}; evaluated from the stops captured:\n", out.reason);
    for (const auto& m : out.missed)
      fmt::print("  missed run {} {} target {} ({:.3f} mm)\n", m.run_number,
                 m.direction == '+' ? "up" : "down", m.target_index + 1, m.nominal_mm);
  }
  print(*out.evaluation);
  print_verdict(linear_verdict(run_tolerances(config, "linear", "X"), to_json(*out.evaluation)));
  const auto truth =
      cal::iso230_2::evaluate(shop.true_measurements(run.plan()), out.evaluation->standard.id);
  print_comparison(*out.evaluation, truth, shop.truth());
  if (o.linear_only) return 0;
  if (const int rc = run_circle_demo(io, shop, config, o); rc != 0) return rc;
  fmt::print("\nSee it again: daq runs --db {0}; daq show {1} --db {0}; daq export {1} --db {0}\n",
             o.db, out.run_id);
  fmt::print("Replay the wire-level capture: daq replay {} --db {}\n", o.capture, o.db);
  if (!o.linear_only)
    fmt::print("  and the circle's: daq replay {} --db {}\n", circle_capture_path(o.capture), o.db);
  if (const auto* vt = d::VirtualTime::of(io))
    fmt::print(
        "Simulated time: {:.1f} s in {} jumps, {} timer events; {} waits for bytes that never "
        "came\n",
        vt->now_s(), vt->stats().jumps, vt->stats().timers, vt->stats().settle_timeouts);
  return 0;
}

}  // namespace

void add_demo_command(CLI::App& app) {
  auto o = std::make_shared<DemoOptions>();
  auto* cmd = app.add_subcommand(
      "demo", "Run the whole chain on the built-in SIMULATED machine and instrument twins");
  cmd->add_option("--db", o->db, "Run database for the demo runs")->capture_default_str();
  cmd->add_option("--capture", o->capture,
                  "Wire-level capture file of the linear run (the circle's: NAME-circle.cdq)")
      ->capture_default_str();
  cmd->add_option("--speed", o->speed,
                  "Simulated time per real time (1 .. 200); 0: simulated time jumps from event "
                  "to event, as fast as the CPU allows")
      ->capture_default_str()
      ->check(finite_in(0.0, 200.0));
  cmd->add_flag("--quiet", o->quiet, "Print only the results");
  cmd->add_flag("--linear-only", o->linear_only, "Run the linear test only (no ballbar circle)");
  cmd->add_option("--control-table", o->control_table,
                  "A compensation table (daq compensate) the simulated control applies to X");
  cmd->add_option("--control-format", o->control_format,
                  "Its format: siemens, linuxcnc, isg, heidenhain or fanuc")
      ->check(CLI::IsMember({"siemens", "linuxcnc", "isg", "heidenhain", "fanuc"}));
  cmd->add_flag("--control-inverted", o->control_inverted,
                "The simulated control reads the table with the other sign than its vendor "
                "states (to see daq verify diagnose it)");
  cmd->callback([o] {
    if (o->speed > 0 && o->speed < 1)
      throw CLI::ValidationError("--speed", "must be 0 (simulated time) or 1 .. 200");
    if (const int rc = run_demo(*o); rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace daq
