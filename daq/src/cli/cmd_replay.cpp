// daq replay CAPTURE: the recorded bytes through the same instruments and pipeline again,
// into a new stored run. The same capture always gives the same readings and results.
#include <fmt/format.h>

#include <algorithm>
#include <boost/asio/io_context.hpp>
#include <chrono>
#include <filesystem>

#include "cal/analysis/error.hpp"
#include "cal/analysis/text.hpp"
#include "cal/replay/session.hpp"
#include "cal/storage/store.hpp"
#include "circle_output.hpp"
#include "circle_run.hpp"
#include "cli_checks.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "database.hpp"
#include "iso230_2_output.hpp"
#include "json_input.hpp"
#include "kinds/kind.hpp"
#include "linear_run.hpp"
#include "run_setup.hpp"
#include "session_spec.hpp"
#include "terminal.hpp"
#include "verdict.hpp"

namespace daq {
namespace {

using nlohmann::json;
using namespace std::chrono_literals;

struct ReplayOptions {
  std::string capture;
  std::string db;
  double speed = 0.0;
  bool json = false;
};

struct ReplaySession {
  boost::asio::io_context io;
  cal::replay::ReplayBus bus;
  json header;
  cal::daq::Config config;
  std::vector<InstrumentSpec> specs;

  ReplaySession(const ReplayOptions& o) : bus(io, o.capture, o.speed) {
    try {
      read_header();
    } catch (const cal::InputError& e) {  // "capture header: key ...": which file
      throw cal::InputError(fmt::format("{}: {}", o.capture, e.what()));
    }
  }
  void read_header() {
    header = cal::daq::parse_json_input(bus.header_json(), "capture header");
    if (!header.is_object() || !header.contains("format") || !header["format"].is_string() ||
        header["format"] != "caldaq.capture-header.v1")
      throw cal::InputError(
          "the capture header is not a caldaq session header (no format "
          "\"caldaq.capture-header.v1\")");
    if (!header.contains("config")) throw cal::InputError("capture header: no key 'config'");
    config = config_from_json(header["config"]);
    const auto instruments = header.find("instruments");
    if (instruments == header.end() || !instruments->is_array())
      throw cal::InputError("capture header: key 'instruments': expected an array");
    for (const auto& j : *instruments) specs.push_back(instrument_spec_from_json(j));
    if (header.contains("software") && !header["software"].is_string())
      throw cal::InputError("capture header: key 'software': expected a string");
  }
  // The run this capture was first stored as (the earliest run recording it), whose context
  // (customer, instruments, tolerances) the replay keeps, as the capture header lacks it.
  std::optional<std::int64_t> original_run;
  std::string original_context;
  json original_settings;
  void find_original(const ReplayOptions& o) {
    const auto capture = std::filesystem::absolute(o.capture).string();
    cal::storage::Store store(database_path(o.db));
    for (const auto& r : store.runs()) {
      if (r.capture_path != capture) continue;
      original_run = r.id;
      const json settings = cal::daq::parse_stored_json(r.settings_json);
      original_settings = settings;
      if (settings.is_object() && settings.contains("context"))
        original_context = settings["context"].dump();
      return;
    }
  }
  std::string software() const {
    return "daq 0.1.0 (replay of " + header.value("software", "?") + ")";
  }
  std::unique_ptr<cal::drivers::Instrument> instrument(const InstrumentSpec& spec) {
    return make_instrument(io, spec, bus.transport(spec.device, spec.transport),
                           {.name = spec.role, .clock = bus.clock(), .replay = true});
  }
  // Starts the run and runs the bus until the run finishes or the capture ends (an incomplete
  // run is stopped with the reason), then reads the rest of the capture: how it ends, damaged
  // or not. A run left incomplete is an error naming the capture, the stored run and why.
  template <class Run>
  cal::replay::ReplayEnd play(Run& run, const std::string& capture, const char* incomplete) {
    run.start();
    std::optional<cal::replay::ReplayEnd> end;
    bus.start([&](const cal::replay::ReplayEnd& e) { end = e; });
    while (!run.finished() && !end) io.run_for(50ms);
    // Readings the instruments still hold are delivered before the run is judged incomplete.
    if (!run.finished()) io.run_for(10ms);
    if (!run.finished()) {
      std::string why = incomplete;
      if (end && end->damage) why = "the capture is " + damage_text(*end->damage);
      run.stop(why);
    }
    if (!end) end = bus.read_to_end();
    const auto& out = run.outcome();
    if (!out.complete)
      throw cal::InputError(fmt::format("{}: replay stored as run {} but incomplete: {}", capture,
                                        out.run_id, out.reason));
    return *end;
  }
  static std::string damage_text(const cal::replay::Damage& d) {
    return fmt::format("damaged at byte {} (block {}): {}", d.offset, d.block, d.what);
  }
};

// The replayed run's verdict, by the limits stored with it (its original run's), as daq run
// prints one. With none it says which keys would judge it, under which table, and why a replay
// has none: the report's verdict line named them, the terminal said only "[tolerances] in the
// configuration". `kind`: the stored run's (verdict.hpp, tolerance_keys); `table`: its axis or
// plane.
void print_replay_verdict(const ReplaySession& s, const ReplayOptions& o, const json& result,
                          std::string_view kind, std::string_view table) {
  const auto v = verdict_of(s.original_settings, result);
  if (v.configured || !v.notes.empty()) return print_verdict(v);
  const json standard = result.value("standard", json::object());
  const std::string title = standard.is_object() ? standard.value("title", "") : "";
  const auto keys = tolerance_keys(kind, title);
  const std::string which = fmt::format("{} under [tolerances.{}]", either_of(keys), table);
  const bool one = keys.size() == 1;
  if (!s.original_run) {
    fmt::print(
        "verdict: no tolerance configured: {} would judge it (docs/config.md), but a replay "
        "takes the limits of its original run in the same database; this capture's original "
        "run is not in {}, and a capture does not carry the limits\n",
        which, cal::text::terminal_safe(database_path(o.db).string()));
    return;
  }
  const json context = s.original_settings.value("context", json::object());
  const std::string config = context.is_object() ? context.value("configuration", "") : "";
  fmt::print(
      "verdict: no tolerance configured: no limit was stored with run {}, this capture's "
      "original run: {} in {} judge{} the runs made with it (docs/config.md)\n",
      *s.original_run, which,
      config.empty()
          ? std::string("the configuration it was made with")
          : "the configuration it was made with (" + cal::text::terminal_safe(config) + ")",
      one ? "s" : "");
}

// A complete run from a capture damaged further on: the results stand (printed), and the
// damage is an error (status 2) so that no script takes the file for a sound one.
void report_damage(const cal::replay::ReplayEnd& end, const ReplayOptions& o, std::int64_t run_id) {
  if (!end.damage) return;
  throw cal::InputError(
      fmt::format("{}: the capture is {}; run {} was replayed from the {} records before it",
                  o.capture, ReplaySession::damage_text(*end.damage), run_id, end.records));
}

json damage_json(const cal::replay::ReplayEnd& end) {
  if (!end.damage) return nullptr;
  return {{"offset", end.damage->offset},
          {"block", end.damage->block},
          {"what", end.damage->what},
          {"records_replayed", end.records}};
}

void replay_circle(ReplaySession& s, const ReplayOptions& o) {
  const auto it = std::find_if(s.specs.begin(), s.specs.end(),
                               [](const auto& x) { return x.role == "ballbar"; });
  if (it == s.specs.end())
    throw cal::InputError(fmt::format("{}: the session has no ballbar instrument", o.capture));
  const auto tests = circle_tests(s.config);  // a set's tests follow the first
  auto program = tests.front().program;
  auto analysis = tests.front().analysis;
  // The bar calibration the original run used, not whatever is newest now.
  if (s.original_settings.is_object() && s.original_settings.contains("radius_mm")) {
    const auto original = circle_settings_from_json(s.original_settings).second;
    analysis.calibrated_radius_mm = original.calibrated_radius_mm;
    analysis.uncalibrated = original.uncalibrated;
    analysis.calibration_source = original.calibration_source;
    analysis.calibration = original.calibration;
    analysis.uncalibrated_reason = original.uncalibrated_reason;
    if (analysis.calibration_source.empty() && !analysis.uncalibrated &&
        analysis.calibrated_radius_mm)  // stored before issue 18
      analysis.calibration_source = "configuration";
  } else {
    // No original run in this store: the capture header holds no wall-clock start, so the
    // bar's calibration is the newest one now (docs/circle.md, "Bar calibration"). Resolved
    // here so that the printed result says what the stored run used.
    cal::storage::Store store(database_path(o.db));
    const auto now = std::chrono::system_clock::now().time_since_epoch();
    resolve_calibration(analysis, s.config, program.radius_mm, store,
                        std::chrono::duration_cast<std::chrono::milliseconds>(now).count());
  }
  CircleRunSetup setup{
      .config = s.config,
      .program = program,
      .analysis = analysis,
      .database = database_path(o.db),
      .ballbar = s.instrument(*it),
      .capture_path = std::filesystem::absolute(o.capture).string(),
      .software_version = s.software(),
      .context_json = s.original_context,
      .replay = true,
      .replay_of_run = s.original_run,
      .origins = {{"ballbar",
                   origin_of(it->origin, std::filesystem::absolute(o.capture).string())}},
      .following = std::vector<CircleTest>(tests.begin() + 1, tests.end())};
  CircleRun run(s.io, std::move(setup));
  const auto end = s.play(run, o.capture, "the capture ended before both arcs were recorded");
  const auto& out = run.outcome();
  std::vector<const CircleRunOutcome*> outs;
  for (const auto& c : run.completed()) outs.push_back(&c);
  outs.push_back(&out);
  json all = json::array();
  for (const auto* x : outs) {
    json j = circle_document(*x->result, x->program, x->analysis);
    j["run_id"] = x->run_id;
    if (!o.json) {
      fmt::print("replayed {} into run {} ({} readings)\n\n", o.capture, x->run_id, x->readings);
      print_circle_result(*x->result, x->program, x->analysis);
      print_replay_verdict(s, o, j, "circle", x->analysis.plane);
    }
    all.push_back(std::move(j));
  }
  if (o.json) {
    json j =
        outs.size() == 1 ? all.front() : json{{"schema", "caldaq.circle-set.v1"}, {"runs", all}};
    j["capture_damage"] = damage_json(end);
    fmt::print("{}\n", cal::daq::dump_output(j, 2));
  }
  report_damage(end, o, out.run_id);
}

void replay_linear(ReplaySession& s, const ReplayOptions& o) {
  LinearRunSetup setup;
  setup.config = s.config;
  setup.database = database_path(o.db);
  setup.capture_path = std::filesystem::absolute(o.capture).string();
  setup.software_version = s.software();
  setup.context_json = s.original_context;
  setup.replay = true;
  setup.replay_of_run = s.original_run;
  // The run's instruments as recorded, its kind's own instrument (indicator, level, angle) too.
  const auto& kind = kinds::kind(s.config.linear->measure.kind);
  for (const auto& spec : s.specs)
    if (spec.role == "laser" || spec.role == "air" || spec.role == "material" ||
        spec.role == "position" || (!kind.probe_role().empty() && spec.role == kind.probe_role()))
      place_linear_instrument(spec, s.instrument(spec), setup);
  if ((!setup.laser && !kind.stops_from_probe()) || !setup.air)
    throw cal::InputError(
        fmt::format("{}: the session has no laser or no air instrument", o.capture));
  LinearRun run(s.io, std::move(setup));
  const auto end = s.play(run, o.capture, "the capture ended before every stop was captured");
  const auto& out = run.outcome();
  if (o.json) {
    json j = out.profile ? *out.profile : to_json(*out.evaluation);
    j["run_id"] = out.run_id;
    j["status"] = cal::storage::to_string(out.status);
    j["capture_damage"] = damage_json(end);
    fmt::print("{}\n", cal::daq::dump_output(j, 2));
  } else {
    fmt::print("replayed {} into run {} ({} readings)\n\n", o.capture, out.run_id, out.readings);
    if (!out.missed.empty())
      fmt::print("INCOMPLETE: {} (daq show {} lists them)\n\n", out.reason, out.run_id);
    if (out.profile)
      print_kind_result(*out.profile, out.component);
    else
      print(*out.evaluation);
    const json result = out.profile ? *out.profile : to_json(*out.evaluation);
    const std::string run_kind = !out.profile ? "linear"
                                 : out.profile->value("schema", "") == "caldaq.rotary.v1"
                                     ? "rotary"
                                     : out.profile->value("kind", "");
    print_replay_verdict(s, o, result, run_kind, s.config.linear->axis);
  }
  report_damage(end, o, out.run_id);
}

// A session is replayed as the test it recorded: a ballbar session as a circle, else linear.
void run_replay(const ReplayOptions& o) {
  ReplaySession s(o);
  s.find_original(o);
  const bool ballbar = std::any_of(s.specs.begin(), s.specs.end(),
                                   [](const auto& x) { return x.role == "ballbar"; });
  if (ballbar && s.config.circle) return replay_circle(s, o);
  if (!s.config.linear)
    throw cal::InputError(fmt::format(
        "{}: neither a linear (ISO 230-2) nor a ballbar (ISO 230-4) session", o.capture));
  replay_linear(s, o);
}

}  // namespace

void add_replay_command(CLI::App& app) {
  const auto [cmd, o] = add_command<ReplayOptions>(
      app, "replay", run_replay,
      "Replay a wire-level capture through the same instruments and pipeline into a new run");
  cmd->add_option("CAPTURE", o->capture, "Capture file (.cdq)")->required();
  add_db_option(*cmd, o->db);
  cmd->add_option("--speed", o->speed, "0: as fast as possible; 1: real time; 2: twice ...")
      ->capture_default_str()
      ->check(finite_non_negative());
  cmd->add_flag("--json", o->json,
                "Print the result as JSON (caldaq.iso230-2.v1 or caldaq.circle.v2)");
}

}  // namespace daq
