// daq run linear|circle --config FILE: acquisition against the configured devices;
// daq gcode linear|circle --config FILE: the part program for the test.
#include <fmt/format.h>
#include <unistd.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/posix/stream_descriptor.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/read_until.hpp>
#include <boost/asio/signal_set.hpp>
#include <boost/asio/streambuf.hpp>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "cal/analysis/error.hpp"
#include "cal/daq/config.hpp"
#include "cal/daq/gcode.hpp"
#include "cal/replay/capture.hpp"
#include "cal/replay/session.hpp"
#include "circle_output.hpp"
#include "circle_run.hpp"
#include "cli_checks.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "database.hpp"
#include "iso230_2_output.hpp"
#include "json_input.hpp"
#include "linear_run.hpp"
#include "part_program.hpp"
#include "progress.hpp"
#include "provenance.hpp"
#include "result_rows.hpp"
#include "run_setup.hpp"
#include "session_spec.hpp"
#include "verdict.hpp"

namespace daq {
namespace {

namespace d = cal::drivers;
namespace t = cal::drivers::transport;
using namespace std::chrono_literals;

// Enter on the keyboard is the manual trigger ("capture now").
void watch_keyboard(boost::asio::io_context& io, std::function<void()> on_enter) {
  if (!::isatty(STDIN_FILENO)) return;
  auto in = std::make_shared<boost::asio::posix::stream_descriptor>(io, ::dup(STDIN_FILENO));
  auto buf = std::make_shared<boost::asio::streambuf>();
  auto next = std::make_shared<std::function<void()>>();
  *next = [in, buf, on_enter, next] {
    boost::asio::async_read_until(*in, *buf, '\n',
                                  [in, buf, on_enter, next](auto ec, std::size_t n) {
                                    if (ec) return;
                                    buf->consume(n);
                                    on_enter();
                                    (*next)();
                                  });
  };
  (*next)();
}

// Runs the event loop until the run ends (Ctrl-C or SIGTERM stop it as the operator's
// abort), closes the capture, and throws with the reason if the run did not complete. A
// capture that cannot be written (a full disk) aborts the run, naming the file; what was
// written before stays readable in both the store and the capture.
template <class Run>
const auto& run_to_end(boost::asio::io_context& io, Run& run, SessionCapture& capture,
                       const RunDriver& drive) {
  boost::asio::signal_set signals(io, SIGINT, SIGTERM);
  signals.async_wait([&](auto ec, int) {
    if (!ec) run.stop("stopped by the operator");
  });
  if (capture.recorder)  // posted: the failure is seen inside an instrument's handler
    capture.recorder->on_failure([&io, &run](const std::string& e) {
      boost::asio::post(io, [&run, e] { run.stop("capture failed: " + e); });
    });
  if (drive) {
    drive([&run] { return run.finished(); });
    if (!run.finished()) run.stop("the simulated program ended before the run was complete");
  } else {
    while (!run.finished()) io.run_for(100ms);
  }
  if (capture.recorder) capture.recorder->close();
  const auto& out = run.outcome();
  if (!out.complete)
    throw cal::InputError(fmt::format("run {} aborted: {}", out.run_id, out.reason));
  if (capture.recorder && capture.recorder->failure())
    throw cal::InputError(fmt::format("run {} is complete and stored, but its capture failed: {}",
                                      out.run_id, *capture.recorder->failure()));
  return out;
}

// Every device opens and speaks before the run starts, or the run is refused naming it.
void check_at_start(const cal::daq::Config& config, const std::vector<InstrumentSpec>& specs,
                    const RunOptions& o) {
  if (o.check_s <= 0) return;
  std::FILE* out = o.json ? stderr : stdout;  // stdout carries only the JSON then
  fmt::print(out, "Checking the devices (up to {} s):\n", o.check_s);
  check_devices(config, specs, std::chrono::duration<double>(o.check_s),
                [out](const std::string& line) { fmt::print(out, "{}\n", line); });
  std::fflush(out);
}

// Where progress and events go: stdout, or stderr when stdout carries --json. On a terminal
// the live line is rewritten in place; into a file or a pipe each line is written whole and
// flushed as it happens (a log that is read while the run goes on). With --json the progress
// is JSON lines on stderr (caldaq.live.v1 and caldaq.event.v1, docs/cli.md), one at each change
// of state, on a terminal too: a program reads them.
struct ProgressOut {
  std::FILE* out;
  bool json;
  bool tty;
  std::string last;  // the key of the last progress line written to a file or pipe
  explicit ProgressOut(bool as_json)
      : out(as_json ? stderr : stdout),
        json(as_json),
        tty(!as_json && ::isatty(::fileno(out)) != 0) {}
  void event(const std::string& e) {
    if (json)
      fmt::print(out, "{}\n", nlohmann::json{{"schema", "caldaq.event.v1"}, {"message", e}}.dump());
    else
      fmt::print(out, "{}  {}\n", tty ? "\r\033[K" : "", e);
    std::fflush(out);
  }
  // `key` names the state: a file gets a line only when it changes (run, target, phase).
  void live(const std::string& key, const std::string& line) {
    if (tty) {
      fmt::print(out, "\r\033[K{}", line);
    } else {
      if (key == last) return;
      last = key;
      fmt::print(out, "{}\n", line);
    }
    std::fflush(out);
  }
};

// A piped or logged run gets a line per stop, and one when the first laser reading arrives.
std::string live_key(const LiveState& s) {
  return fmt::format("{} {} {}", s.stop_number, s.has_reading, s.state);
}

// The live line of a linear run: where in the plan (run, target, stop k of N), the number the
// page shows (the position while the axis moves, the deviation within a target's capture
// window), the air and material once sampled, the time so far and left. No number before the
// device has given one: a zero there would read as a measurement.
std::string live_line(const LiveState& s) {
  const auto& p = s.progress;
  std::string line =
      fmt::format("run {} of {} {}  target {} of {}  stop {} of {}", p.run, p.runs,
                  p.direction == cal::iso230_2::Direction::up ? "up" : "down", p.target, p.targets,
                  std::min(s.stop_number, s.stop_count), s.stop_count);
  if (!s.has_reading)
    return line + fmt::format("  waiting for the {}'s first reading", s.reference);
  if (!s.valid)
    line += "  laser signal lost";
  else if (s.at_target_mm)  // a straightness, angular or roll stop's value is its event's, not this
    line += fmt::format("  {:<8} {}{:+8.2f} {} at {:.3f} {}", s.motion,
                        s.stop_value == "deviation" ? "" : "laser ", s.at_target_deviation_um,
                        s.units.deviation, *s.at_target_mm, s.units.position);
  else
    line += fmt::format("  {:<8} at {:.3f} {}", s.motion, s.position_mm, s.units.position);
  if (s.pressure_pa > 0)  // the first air sample has come (env_stage.hpp)
    line += fmt::format("  air {:.2f} degC  material {:.2f} degC{}", s.air_temperature_degc,
                        s.material_degc, s.fallback ? " (fallback)" : "");
  line += fmt::format("  {} elapsed", clock_text(s.time_s));
  const auto done =
      static_cast<double>(std::max<std::size_t>(std::min(s.stop_number, s.stop_count + 1), 1) - 1);
  if (const auto left = remaining_s(s.time_s, done, static_cast<double>(s.stop_count)))
    line += fmt::format(", about {} left", clock_text(*left));
  return line;
}

// A circle's verdict by the limits of its plane; with none, where they are given.
Verdict verdict_circle(const cal::daq::Config& c, const std::string& plane,
                       const nlohmann::json& result) {
  auto v = circle_verdict(run_tolerances(c, "circle", plane), result);
  if (!v.configured && v.notes.empty()) {
    auto where = limits_where("circle", plane, nlohmann::json::object(), result);
    where.configuration = c.source.string();
    v.hint = to_text(where);
  }
  return v;
}

// The result of a straightness, angular, roll or rotary run (kinds/kind.hpp).
void print_profile(const LinearRunOutcome& out, const Verdict& verdict, bool json, bool tty) {
  auto j = *out.profile;
  j["run_id"] = out.run_id;
  j["status"] = cal::storage::to_string(out.status);
  j["values"] = rows_json(result_rows(j));
  j["verdict"] = to_json(verdict);
  if (json) return fmt::print("{}\n", j.dump(2));
  fmt::print("{}\nrun {} stored ({}): {} readings\n\n", tty ? "\r\033[K" : "", out.run_id,
             cal::storage::to_string(out.status), out.readings);
  if (j.value("schema", "") == "caldaq.rotary.v1") {  // its table in deg and arcsec
    print_kind_result(j, out.component);
    return print_verdict(verdict);
  }
  const std::string unit = j.value("unit", "");
  fmt::print("{} {} (mean of the stops at each target, {})\n", j.value("kind", ""), out.component,
             unit);
  for (const auto& t : j["targets"])
    fmt::print("  {:10.3f} mm  {:+10.3f}  (spread {:.3f}, {} stops)\n",
               t["position_mm"].get<double>(), t["mean"].get<double>(), t["spread"].get<double>(),
               t["count"].get<int>());
  fmt::print("\n");
  print_result(j);  // the values as daq show and daq analyse print them
  print_verdict(verdict);
}

}  // namespace

void run_linear_test(const RunOptions& o, boost::asio::io_context& io, const RunDriver& drive) {
  const auto config = cal::daq::load_config(o.config);
  const auto specs = linear_specs(config);
  check_at_start(config, specs, o);
  SessionCapture capture(o.capture, config, specs);
  LinearRunSetup setup;
  setup.config = config;
  setup.database = database_path(o.db);
  setup.capture_path = capture.absolute_path(o.capture);
  add_linear_instruments(io, config, specs, o, capture.recorder.get(), setup);
  auto progress = std::make_shared<ProgressOut>(o.json);
  setup.on_event = [progress](const std::string& e) { progress->event(e); };
  setup.on_live = [progress](const LiveState& s) {
    if (progress->json) return progress->live(live_key(s), to_json_text(s));
    if (!s.progress.next_position_mm) return;
    progress->live(live_key(s), live_line(s));
  };
  LinearRun run(io, std::move(setup));
  run.start();
  progress->event(fmt::format(
      "Waiting for the machine: run the program from `daq gcode linear --config {}`; Enter "
      "captures the current stop by hand; Ctrl-C stops.",
      o.config));
  watch_keyboard(io, [&] { run.manual_capture(); });
  const auto& out = run_to_end(io, run, capture, drive);
  const auto run_record = cal::storage::Store(database_path(o.db)).run(out.run_id);
  const auto stored =
      run_record ? cal::daq::parse_stored_json(run_record->settings_json) : nlohmann::json();
  // Judged by the limits stored with the run; with none, the verdict says where they are given.
  const auto verdict = [&](const nlohmann::json& result) {
    return run_record ? run_verdict(run_record->kind, run_record->axis, stored, result)
                      : verdict_of(stored, result);
  };
  if (out.profile) return print_profile(out, verdict(*out.profile), o.json, progress->tty);
  const auto v = verdict(to_json(*out.evaluation));
  if (o.json) {
    auto j = to_json(*out.evaluation);
    j["run_id"] = out.run_id;
    j["status"] = cal::storage::to_string(out.status);
    j["missed_stops"] = nlohmann::json::array();
    for (const auto& m : out.missed)
      j["missed_stops"].push_back({{"run", m.run_number},
                                   {"direction", m.direction == '+' ? "up" : "down"},
                                   {"target_index", m.target_index + 1},
                                   {"nominal_mm", m.nominal_mm}});
    j["verdict"] = to_json(v);
    return fmt::print("{}\n", j.dump(2));
  }
  fmt::print("{}\nrun {} stored ({}): {} readings\n", progress->tty ? "\r\033[K" : "", out.run_id,
             cal::storage::to_string(out.status), out.readings);
  if (!out.missed.empty()) {
    fmt::print("INCOMPLETE: {}; the evaluation uses the stops captured:\n", out.reason);
    for (const auto& m : out.missed)
      fmt::print("  missed run {} {} target {} ({:.3f} mm)\n", m.run_number,
                 m.direction == '+' ? "up" : "down", m.target_index + 1, m.nominal_mm);
  }
  fmt::print("\n");
  print(*out.evaluation);
  print_verdict(v);
}

// daq run circle: the ballbar streams; the run waits for the feed-in, then records both arcs.
void run_circle_test(const RunOptions& o, boost::asio::io_context& io, const RunDriver& drive) {
  const auto config = cal::daq::load_config(o.config);
  const auto tests = circle_tests(config);  // one test, or the set of [test.circle] planes
  const auto& dc = need(config, "ballbar");
  const std::vector<InstrumentSpec> specs{spec_of(dc, 0)};
  check_at_start(config, specs, o);
  SessionCapture capture(o.capture, config, specs);
  CircleRunSetup setup{
      .config = config,
      .program = tests.front().program,
      .analysis = tests.front().analysis,
      .database = database_path(o.db),
      .ballbar = make_instrument(io, specs[0], make_transport(io, dc),
                                 instrument_options(dc, specs[0], o, capture.recorder.get())),
      .capture_path = capture.absolute_path(o.capture),
      .origins = {{"ballbar", origin_of(specs[0].origin, "")}},
      .following = std::vector<CircleTest>(tests.begin() + 1, tests.end())};
  auto progress = std::make_shared<ProgressOut>(o.json);
  setup.on_event = [progress](const std::string& e) { progress->event(e); };
  setup.on_live = [progress](const CircleLive& s) {
    const std::string key = fmt::format("{} {}", s.phase, s.samples > 0);
    if (progress->json) return progress->live(key, to_json_text(s));
    if (s.samples == 0)  // no deviation before the bar has sent one
      return progress->live(key,
                            fmt::format("{:<24} waiting for the ballbar's first reading", s.phase));
    if (s.state == "waiting")  // nor before the feed-in: no deviation from the circle yet
      return progress->live(
          key, fmt::format("{:<24} the bar streams; waiting for the feed-in", s.phase));
    std::string line =
        fmt::format("{:<24} {:7.1f} deg  {:+9.2f} um  {:5.1f} %  {} elapsed", s.phase, s.angle_deg,
                    s.deviation_um, 100 * s.fraction, clock_text(s.time_s));
    if (const auto left = remaining_s(s.time_s, s.fraction, 1.0))
      line += fmt::format(", about {} left", clock_text(*left));
    progress->live(key, line);
  };
  CircleRun run(io, std::move(setup));
  run.start();
  progress->event(fmt::format(
      "Waiting for the feed-in{}: run the program from `daq gcode circle --config {}`; Ctrl-C "
      "stops.",
      tests.size() > 1 ? fmt::format(" of the first of {} tests", tests.size()) : "", o.config));
  const auto& last = run_to_end(io, run, capture, drive);
  std::vector<const CircleRunOutcome*> outs;
  for (const auto& c : run.completed()) outs.push_back(&c);
  outs.push_back(&last);
  auto all = nlohmann::json::array();
  for (const auto* out : outs) {
    auto j = circle_document(*out->result, out->program, out->analysis);
    const auto v = verdict_circle(config, out->analysis.plane, j);
    j["run_id"] = out->run_id;
    j["status"] = "complete";
    j["verdict"] = to_json(v);
    if (!o.json) {
      fmt::print("\nrun {}: {} readings\n", out->run_id, out->readings);
      print_circle_result(*out->result, out->program, out->analysis);
      print_verdict(v);
    }
    all.push_back(std::move(j));
  }
  if (o.json) {
    if (outs.size() == 1) return fmt::print("{}\n", all.front().dump(2));
    return fmt::print("{}\n", nlohmann::json{{"schema", "caldaq.circle-set.v1"},
                                             {"campaign", config.campaign},
                                             {"runs", all}}
                                  .dump(2));
  }
  if (outs.size() > 1)
    fmt::print(
        "\n{} tests stored as runs {}..{} of campaign '{}': `daq ballbar volumetric "
        "--runs ...` or `daq report --campaign` for the three-plane table\n",
        outs.size(), outs.front()->run_id, outs.back()->run_id, config.campaign);
}

namespace {

void run_linear(const RunOptions& o) {
  boost::asio::io_context io;
  run_linear_test(o, io, {});
}

void run_circle(const RunOptions& o) {
  boost::asio::io_context io;
  run_circle_test(o, io, {});
}

struct GcodeOptions {
  std::string config, dialect = "fanuc", output;
  bool set = false;  // circle: the standard set (XY, ZX, YZ) even for a single-test configuration
  bool by_radius = false;
};

void gcode(const GcodeOptions& o, bool circle) {
  const auto text = part_program(cal::daq::load_config(o.config), circle ? "circle" : "linear",
                                 o.dialect, {.standard_set = o.set, .by_radius = o.by_radius});
  if (o.output.empty()) return fmt::print("{}", text);
  std::ofstream out(o.output);
  if (!(out << text)) throw cal::InputError(fmt::format("{}: cannot write", o.output));
}

// What the help of `daq run linear` and `daq run circle` says differently about the options
// both take.
struct AcquisitionHelp {
  std::string config;
  std::string give_up_after;
  std::string check_s;
  std::string json;
};

// The options of an acquisition: the set-up, the run store, the capture, the reconnection and
// start-up checks, and the result as JSON. Both kinds parse into the same RunOptions.
void add_acquisition_options(CLI::App& cmd, RunOptions& o, const AcquisitionHelp& help) {
  cmd.add_option("-c,--config", o.config, help.config)->required();
  add_db_option(cmd, o.db);
  cmd.add_option("--capture", o.capture, "Record the wire-level capture to this file");
  cmd.add_option("--give-up-after", o.give_up_after, help.give_up_after)->capture_default_str();
  cmd.add_option("--check-s", o.check_s, help.check_s)
      ->capture_default_str()
      ->check(finite_non_negative());
  cmd.add_flag("--json", o.json, help.json);
}

}  // namespace

void add_run_commands(CLI::App& app) {
  auto o = std::make_shared<RunOptions>();
  auto* run = add_group(app, "run", "Acquire a test with the configured instruments");
  auto* lin = run->add_subcommand(
      "linear",
      "Linear test: ISO 230-2 positioning (laser, air, material), or by [test.linear] measure a "
      "straightness (indicator), pitch or yaw (two laser axes) or roll (level) run");
  add_acquisition_options(
      *lin, *o,
      {.config = "Machine/campaign TOML (docs/config.md)",
       .give_up_after = "Reconnection attempts before a device is given up",
       .check_s = "Before the run, every device must open and speak within this time (0: no "
                  "check)",
       .json = "Print the result as caldaq.iso230-2.v1 JSON with run_id, status, missed_stops "
               "and verdict (progress goes to stderr)"});
  lin->callback([o] { run_linear(*o); });
  auto* circ = run->add_subcommand("circle", "ISO 230-4 circular test with a ballbar");
  add_acquisition_options(
      *circ, *o,
      {.config = "Machine/campaign TOML with [test.circle]",
       .give_up_after = "Reconnection attempts before the ballbar is given up",
       .check_s = "Before the run, the ballbar must open within this time (0: no check)",
       .json = "Print the result as caldaq.circle.v2 JSON with run_id and verdict (progress "
               "goes to stderr)"});
  circ->callback([o] { run_circle(*o); });

  auto g = std::make_shared<GcodeOptions>();
  auto* gc = add_group(app, "gcode", "Part program for a configured test");
  for (const char* kind : {"linear", "circle"}) {
    auto* sub = gc->add_subcommand(kind, std::string("Program for [test.") + kind + "]");
    sub->add_option("-c,--config", g->config, "Machine/campaign TOML")->required();
    sub->add_option("-d,--dialect", g->dialect, "fanuc, heidenhain or siemens")
        ->capture_default_str();
    sub->add_option("-o,--output", g->output, "Write to a file instead of stdout");
    const bool circle = std::string(kind) == "circle";
    if (circle) {
      sub->add_flag("--set", g->set,
                    "The standard set: XY 360 deg, ZX and YZ partial arcs, at each configured "
                    "feed and radius (docs/circle.md)");
      sub->add_flag("--by-radius", g->by_radius,
                    "Arcs by radius (R / CR=) in pieces of at most 90 deg instead of by centre");
    }
    sub->callback([g, circle] { gcode(*g, circle); });
  }
}

}  // namespace daq
