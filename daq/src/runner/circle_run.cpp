// Ballbar run (see circle_run.hpp).
#include "circle_run.hpp"

#include <fmt/format.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/post.hpp>
#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>

#include "cal/analysis/error.hpp"
#include "cal/daq/gcode.hpp"
#include "cal/drivers/loop_time.hpp"
#include "cal/storage/store.hpp"
#include "cal/storage/writer.hpp"
#include "circle_output.hpp"
#include "provenance.hpp"
#include "roles.hpp"
#include "runner.hpp"

namespace daq {

using nlohmann::json;

namespace {

cal::circle::Plane circle_plane(const std::string& p) {
  switch (cal::daq::plane_from_string(p)) {
    case cal::daq::Plane::xy:
      return cal::circle::Plane::xy;
    case cal::daq::Plane::yz:
      return cal::circle::Plane::yz;
    case cal::daq::Plane::zx:
      return cal::circle::Plane::zx;
  }
  return cal::circle::Plane::xy;
}

}  // namespace

cal::circle::Result analyse_ballbar(const cal::daq::BallbarProgram& program,
                                    const BallbarAnalysis& analysis,
                                    std::span<const double> deviation_mm) {
  cal::daq::BallbarSegmenter segmenter(program);
  for (double v : deviation_mm) segmenter.add(v);
  return analyse_traces(program, analysis, segmenter.sources());
}

cal::daq::BallbarSegmenter segment_stored_run(const cal::storage::RunReader& store,
                                              std::int64_t run_id,
                                              const cal::daq::BallbarProgram& program) {
  static constexpr std::uint8_t bar[] = {
      static_cast<std::uint8_t>(cal::drivers::Quantity::length_m)};
  cal::daq::BallbarSegmenter segmenter(program);
  auto stream = store.stream_readings(run_id, bar);
  std::vector<cal::storage::RawReading> batch;
  while (stream.next(batch))
    for (const auto& r : batch) segmenter.add(r.value * 1e3);
  return segmenter;
}

cal::circle::Result analyse_traces(const cal::daq::BallbarProgram& program,
                                   const BallbarAnalysis& analysis,
                                   std::span<const cal::circle::TraceSource> traces) {
  return cal::circle::analyse({.plane = circle_plane(analysis.plane),
                               .radius_mm = program.radius_mm,
                               .feed_mm_per_min = program.feed_mm_per_min,
                               .cyclic_period_mm = analysis.cyclic_period_mm,
                               .radius_calibrated = !analysis.uncalibrated,
                               .calibrated_radius_mm = analysis.calibrated_radius_mm,
                               .sample_rate_hz = program.sample_rate_hz,
                               .start_deg = program.start_deg,
                               .arc_deg = program.arc_deg,
                               .overshoot_deg = program.overshoot_deg},
                              traces);
}

namespace {

// The stored record also keeps the exact time, which calibration_from_json reads back.
json calibration_json(const cal::storage::BarCalibration& c) {
  json j = bar_calibration_json(c);
  j["calibrated_unix_ms"] = c.calibrated_unix_ms;
  return j;
}

cal::storage::BarCalibration calibration_from_json(const json& j) {
  cal::storage::BarCalibration c{
      .id = j.value("id", std::int64_t{0}),
      .bar = j.value("bar", std::string()),
      .nominal_mm = j.value("nominal_mm", 0.0),
      .extensions = j.value("extensions", std::string()),
      .calibrator = j.value("calibrator", std::string()),
      .calibrator_length_mm = j.value("calibrator_length_mm", 0.0),
      .reading_mm = j.value("reading_mm", 0.0),
      .zero_length_mm = j.value("zero_length_mm", 0.0),
      .calibrated_unix_ms = j.value("calibrated_unix_ms", std::int64_t{0}),
      .note = j.value("note", std::string())};
  if (j.contains("temperature_degc") && j["temperature_degc"].is_number())
    c.temperature_degc = j["temperature_degc"].get<double>();
  return c;
}

// What the result says about the absolute radius (the "calibration" block of caldaq.circle.v2).
json calibration_block(const BallbarAnalysis& a) {
  if (a.uncalibrated || !a.calibrated_radius_mm)
    return {{"evaluated", false},
            {"reason", a.uncalibrated_reason.empty() ? std::string("the bar was not calibrated")
                                                     : a.uncalibrated_reason}};
  json j{{"evaluated", true},
         {"source",
          a.calibration_source.empty() ? std::string("configuration") : a.calibration_source},
         {"zero_length_mm", *a.calibrated_radius_mm}};
  if (a.calibration) j["record"] = calibration_json(*a.calibration);
  return j;
}

}  // namespace

void resolve_calibration(BallbarAnalysis& a, const cal::daq::Config& c, double radius_mm,
                         const cal::storage::RunReader& store, std::int64_t at_unix_ms) {
  if (a.uncalibrated || !a.calibration_source.empty()) return;
  if (a.calibrated_radius_mm) {
    a.calibration_source = "configuration";
    return;
  }
  const std::string bar = c.circle ? c.circle->bar : std::string();
  if (bar.empty()) {
    a.uncalibrated = true;
    a.uncalibrated_reason =
        "no bar is named ([test.circle] bar) and no calibrated_radius_mm is given";
    return;
  }
  if (auto cal = store.bar_calibration(bar, radius_mm, at_unix_ms)) {
    a.calibrated_radius_mm = cal->zero_length_mm;
    a.calibration_source = "stored";
    a.calibration = std::move(cal);
    return;
  }
  a.uncalibrated = true;
  a.uncalibrated_reason = fmt::format(
      "no calibration of bar '{}' at {:g} mm is stored (daq ballbar calibrate)", bar, radius_mm);
}

json circle_document(const cal::circle::Result& r, const cal::daq::BallbarProgram& program,
                     const BallbarAnalysis& analysis) {
  json j = circle_json(r, program.radius_mm, analysis.plane, program.feed_mm_per_min,
                       cal::circle::circular_standard_from_key(analysis.standard));
  j["calibration"] = calibration_block(analysis);
  return j;
}

void print_circle_result(const cal::circle::Result& r, const cal::daq::BallbarProgram& program,
                         const BallbarAnalysis& analysis) {
  print_circle(r, program.radius_mm, analysis.plane, program.feed_mm_per_min,
               cal::circle::circular_standard_from_key(analysis.standard));
}

std::string standard_label(const BallbarAnalysis& analysis) {
  return cal::circle::info(cal::circle::circular_standard_from_key(analysis.standard)).label;
}

// The program's numbers in a circle run's settings, written and read by the one list: the key,
// the member, and the value of a run stored before the key was (none: always stored).
struct ProgramKey {
  const char* key;
  double cal::daq::BallbarProgram::*member;
  std::optional<double> before;
};
constexpr ProgramKey kProgramKeys[] = {
    {"radius_mm", &cal::daq::BallbarProgram::radius_mm, std::nullopt},
    {"feed_mm_per_min", &cal::daq::BallbarProgram::feed_mm_per_min, std::nullopt},
    {"sample_rate_hz", &cal::daq::BallbarProgram::sample_rate_hz, std::nullopt},
    {"feed_in_mm", &cal::daq::BallbarProgram::feed_in_mm, std::nullopt},
    {"dwell_s", &cal::daq::BallbarProgram::dwell_s, std::nullopt},
    {"overshoot_deg", &cal::daq::BallbarProgram::overshoot_deg, std::nullopt},
    {"start_deg", &cal::daq::BallbarProgram::start_deg, 0.0},
    {"arc_deg", &cal::daq::BallbarProgram::arc_deg, 360.0},
};

json circle_settings_json(const cal::daq::BallbarProgram& p, const BallbarAnalysis& a) {
  json j{{"plane", a.plane}, {"uncalibrated", a.uncalibrated}, {"standard", a.standard}};
  for (const auto& k : kProgramKeys) j[k.key] = p.*k.member;
  if (!a.calibration_source.empty()) j["calibration_source"] = a.calibration_source;
  if (a.calibration) j["calibration"] = calibration_json(*a.calibration);
  if (!a.uncalibrated_reason.empty()) j["uncalibrated_reason"] = a.uncalibrated_reason;
  if (a.calibrated_radius_mm) j["calibrated_radius_mm"] = *a.calibrated_radius_mm;
  if (a.cyclic_period_mm) j["cyclic_period_mm"] = *a.cyclic_period_mm;
  return j;
}

std::pair<cal::daq::BallbarProgram, BallbarAnalysis> circle_settings_from_json(const json& j) {
  cal::daq::BallbarProgram p;
  for (const auto& k : kProgramKeys)
    p.*k.member = k.before ? j.value(k.key, *k.before) : j.at(k.key).get<double>();
  // Runs stored before issue 18 have no standard: they were evaluated by ISO 230-4:2005.
  BallbarAnalysis a{.plane = j.value("plane", std::string("XY")),
                    .uncalibrated = j.value("uncalibrated", false),
                    .standard = j.value("standard", std::string("iso230-4:2005"))};
  if (j.contains("calibrated_radius_mm")) a.calibrated_radius_mm = j["calibrated_radius_mm"];
  a.calibration_source = j.value("calibration_source", std::string());
  if (j.contains("calibration") && j["calibration"].is_object())
    a.calibration = calibration_from_json(j["calibration"]);
  a.uncalibrated_reason = j.value("uncalibrated_reason", std::string());
  // Runs stored before bar calibrations were recorded (issue 18): a length given in the
  // configuration counts as such; none means the nominal was assumed, which is no calibration.
  if (a.calibration_source.empty() && !a.uncalibrated) {
    if (a.calibrated_radius_mm) {
      a.calibration_source = "configuration";
    } else {
      a.uncalibrated = true;
      a.uncalibrated_reason =
          "stored without a calibrated length (the nominal was assumed): not a calibration";
    }
  }
  if (j.contains("cyclic_period_mm")) a.cyclic_period_mm = j["cyclic_period_mm"];
  return {p, a};
}

std::vector<CircleTest> circle_tests(const cal::daq::Config& c, bool standard_set) {
  if (!c.circle) throw cal::InputError(fmt::format("{}: no [test.circle]", c.source.string()));
  const auto& t = *c.circle;
  cal::daq::BallbarSetConfig set{
      .feeds_mm_per_min =
          t.feeds_mm_per_min.empty() ? std::vector<double>{t.feed_mm_per_min} : t.feeds_mm_per_min,
      .radii_mm = t.radii_mm.empty() ? std::vector<double>{t.radius_mm} : t.radii_mm,
      .partial_arc_deg = t.partial_arc_deg,
      .overshoot_deg = t.overshoot_deg,
      .partial_overshoot_deg = t.partial_overshoot_deg,
      .sample_rate_hz = t.sample_rate_hz,
      .feed_in_mm = t.feed_in_mm,
      .dwell_s = t.dwell_s};
  set.planes.clear();
  if (!t.planes.empty())
    for (const auto& p : t.planes) set.planes.push_back(cal::daq::plane_from_string(p));
  else if (standard_set)
    set.planes = {cal::daq::Plane::xy, cal::daq::Plane::zx, cal::daq::Plane::yz};
  const bool single = set.planes.empty();
  if (single) {
    // One full circle in `plane`, as before sets existed (also in ZX and YZ: the operator's
    // choice, e.g. on a machine where the spindle allows it).
    set.planes = {cal::daq::plane_from_string(t.plane)};
    set.partial_arc_deg = 360.0;
  }
  std::vector<CircleTest> out;
  for (const auto& s : cal::daq::ballbar_set(set)) {
    BallbarAnalysis a{.plane = cal::daq::plane_name(s.plane), .standard = t.standard};
    if (t.calibrated_radius_mm > 0) a.calibrated_radius_mm = t.calibrated_radius_mm;
    out.push_back({s.plane, s.program, a});
  }
  return out;
}

cal::daq::CircleProgramSetup circle_program_setup(const cal::daq::Config& c) {
  if (!c.circle) throw cal::InputError(fmt::format("{}: no [test.circle]", c.source.string()));
  const auto& t = *c.circle;
  return {.centre_x_mm = t.centre_mm[0],
          .centre_y_mm = t.centre_mm[1],
          .centre_z_mm = t.centre_mm[2],
          .plane = cal::daq::plane_from_string(t.plane)};
}

std::pair<cal::daq::BallbarProgram, BallbarAnalysis> circle_test(const cal::daq::Config& c) {
  const auto tests = circle_tests(c);
  return {tests.front().program, tests.front().analysis};
}

std::string to_json_text(const CircleLive& s) {
  const auto trace = [](const std::vector<std::pair<double, double>>& points) {
    json a = json::array();
    for (const auto& [angle, dev] : points) a.push_back({angle, dev});
    return a;
  };
  // Before the bar's first sample there is no deviation: null, never a 0 that looks measured.
  // Nor before the feed-in: the bar's reading is then no deviation from the circle (a set's
  // bar moving onto its next plane, the bar being fed in).
  const bool deviation = s.samples > 0 && s.state != "waiting";
  return json{{"schema", "caldaq.live-circle.v1"},
              {"time_s", s.time_s},
              {"state", s.state},
              {"phase", s.phase},
              {"angle_deg", s.angle_deg},
              {"deviation_um", deviation ? json(s.deviation_um) : json(nullptr)},
              {"fraction", s.fraction},
              {"samples", s.samples},
              {"trace", {{"ccw", trace(s.ccw)}, {"cw", trace(s.cw)}}}}
      .dump();
}

struct CircleRun::Impl : Runner {
  CircleRunSetup setup;
  cal::daq::BallbarSegmenter segmenter;
  CircleRunOutcome outcome;
  CircleLive live;
  std::vector<CircleRunOutcome> completed;  // a set's tests before the current one
  std::size_t next_test = 0;                // into setup.following
  const std::uint16_t ballbar_device = RunDevices().device(Role::ballbar);

  Impl(boost::asio::io_context& i, CircleRunSetup s)
      : Runner(i, s.database, s.store_options), setup(std::move(s)), segmenter(setup.program) {}

  void event(const std::string& e) {
    if (setup.on_event) setup.on_event(e);
  }

  void start() {
    open_store();
    begin_test();
    running = true;
    setup.ballbar->start(
        {.reading = [this](const cal::drivers::Reading& r) { on_reading(r); },
         .state =
             [this](cal::drivers::InstrumentState s, std::string_view why) {
               if (s == cal::drivers::InstrumentState::closed && running)
                 abort(fmt::format("ballbar closed: {}", why));
             },
         .codec_error = codec_errors_as_events(setup.ballbar->describe(),
                                               [this](const std::string& e) { event(e); })});
    tick();
  }

  // The stored run of the current test (setup.program, setup.analysis) and its writer.
  void begin_test() {
    resolve_calibration(setup.analysis, setup.config, setup.program.radius_mm, *store,
                        setup.calibration_at_unix_ms
                            ? setup.calibration_at_unix_ms
                            : std::chrono::duration_cast<std::chrono::milliseconds>(
                                  std::chrono::system_clock::now().time_since_epoch())
                                  .count());
    const auto& c = setup.config;
    const auto& p = setup.program;
    json settings = circle_settings_json(p, setup.analysis);
    settings["context"] = setup.context_json.empty()
                              ? json(nullptr)
                              : json::parse(setup.context_json, nullptr, false);
    if (!settings["context"].is_object()) {
      const std::string opened[] = {"ballbar"};  // the one instrument a circle reads
      settings["context"] = run_context(c, "circle", setup.analysis.plane, opened);
    }
    // Where the table ball was: a circle's squareness is local to it (the three-plane table).
    if (c.circle && c.circle->centre_mm.size() == 3) settings["centre_mm"] = c.circle->centre_mm;
    outcome.run_id = store->begin_run({.machine_id = machine_id(c),
                                       .campaign = c.campaign,
                                       .kind = "circle",
                                       .axis = setup.analysis.plane,
                                       .settings_json = settings.dump(),
                                       .capture_path = setup.capture_path,
                                       .software_version = setup.software_version});
    const auto origin = setup.origins.find("ballbar");
    store->add_instrument(
        {.run_id = outcome.run_id,
         .device = ballbar_device,
         .driver = std::string(name(Role::ballbar)),
         .transport = setup.ballbar->describe(),
         .origin = origin == setup.origins.end() ? "" : origin->second.kind,
         .origin_detail = origin == setup.origins.end() ? "" : origin->second.detail});
    open_writer(outcome.run_id);
    outcome.program = setup.program;
    outcome.analysis = setup.analysis;
    const std::size_t tests = completed.size() + 1 + (setup.following.size() - next_test);
    event(fmt::format("run {}: {}ballbar {} R {} mm at {} mm/min, waiting for the feed-in",
                      outcome.run_id,
                      tests > 1 ? fmt::format("test {} of {}: ", completed.size() + 1, tests) : "",
                      setup.analysis.plane, p.radius_mm, p.feed_mm_per_min));
    // The live readout says the run waits even before the bar sends anything.
    if (setup.on_live) {
      live.state = "waiting";
      live.phase = std::string(cal::daq::to_string(segmenter.progress().phase));
      setup.on_live(live);
    }
  }

  void on_reading(const cal::drivers::Reading& r) {
    if (setup.on_reading) setup.on_reading(r);
    if (!running || r.quantity != cal::drivers::Quantity::length_m) return;
    if (outcome.readings == 0) set_time_origin(outcome.run_id, r.time_ns);
    ++outcome.readings;
    if (!store_reading({.time_ns = r.time_ns,
                        .device = ballbar_device,
                        .quantity = static_cast<std::uint8_t>(r.quantity),
                        .status = static_cast<std::uint8_t>(r.status),
                        .value = r.value}))
      return;
    const bool had = segmenter.feed_in_end().has_value();
    segmenter.add(r.value * 1e3);
    trace(r.value * 1e6);
    if (!had && segmenter.feed_in_end()) event("feed-in found: the circle starts after the dwell");
    publish_live(r);
    if (!segmenter.complete()) return;
    // A set's next test must see every reading after this one (a replay delivers them in
    // bursts, the next feed-in may be among them): the switch is made now. The last test
    // finishes from the loop, outside the instrument's handler.
    if (next_test < setup.following.size())
      finish();
    else
      boost::asio::post(io, [this] { finish(); });
  }

  // The live polar trace: a point per degree of each arc (the page draws it; the analysis
  // uses every sample).
  void trace(double deviation_um) {
    if (!setup.on_live) return;
    const auto pr = segmenter.progress();
    auto* arc = pr.phase == cal::daq::BallbarPhase::ccw_arc  ? &live.ccw
                : pr.phase == cal::daq::BallbarPhase::cw_arc ? &live.cw
                                                             : nullptr;
    if (arc && (arc->empty() || std::abs(pr.angle_deg - arc->back().first) >= 1.0))
      arc->emplace_back(pr.angle_deg, deviation_um);
  }

  // At most every 0.1 s of the bar's own clock, so a replay at full speed is not slowed down.
  void publish_live(const cal::drivers::Reading& r) {
    if (!setup.on_live) return;
    const double t_s = static_cast<double>(r.time_ns) * 1e-9;
    if (live.samples > 0 && t_s - live.time_s < 0.1 && !segmenter.complete()) return;
    const auto pr = segmenter.progress();
    live.time_s = t_s;
    live.state = segmenter.feed_in_end() ? "measuring" : "waiting";
    live.phase = std::string(cal::daq::to_string(pr.phase));
    live.angle_deg = pr.angle_deg;
    live.deviation_um = r.value * 1e6;
    live.fraction = pr.fraction;
    live.samples = segmenter.samples();
    setup.on_live(live);
  }

  void publish_end(const char* state) {
    if (!setup.on_live) return;
    live.state = state;
    setup.on_live(live);
  }

  void finish() {
    // Posted once per reading after the arcs: the first one finishes (a set's next test is
    // not complete when the others arrive).
    if (done || !segmenter.complete()) return;
    running = false;
    try {
      writer->flush();
    } catch (const std::exception& e) {
      return abort(fmt::format("storage failed: {}", e.what()));
    }
    try {
      // The traces read in place from the run's own segmenter's (paged) samples, which the
      // sources keep after the segmenter is renewed: nothing a sample is held in memory
      // (issue 32, docs/benchmarks.md).
      const auto traces = segmenter.sources();
      segmenter = cal::daq::BallbarSegmenter(setup.program);
      outcome.result = analyse_traces(setup.program, setup.analysis, traces);
    } catch (const std::exception& e) {
      return abort(e.what());
    }
    json prov = provenance(setup.replay ? "replayed" : "acquired", setup.software_version);
    prov["analysis"] = circle_settings_json(setup.program, setup.analysis);
    if (setup.replay) {
      prov["capture"] = setup.capture_path;
      prov["replay_of_run"] = setup.replay_of_run ? json(*setup.replay_of_run) : json(nullptr);
    }
    try {
      store->add_result(
          {.run_id = outcome.run_id,
           .standard = standard_label(setup.analysis),
           .json = circle_document(*outcome.result, setup.program, setup.analysis).dump(),
           .provenance_json = prov.dump()});
      store->finish_run(outcome.run_id, cal::storage::RunStatus::complete);
    } catch (const std::exception& e) {
      outcome.result.reset();
      return abort(fmt::format("storage failed: {}", e.what()));
    }
    outcome.complete = true;
    if (next_test < setup.following.size()) return next();
    publish_end("complete");
    end();
  }

  // A set's next test: a new run on the same bar stream, waiting for its feed-in.
  void next() {
    completed.push_back(std::move(outcome));
    outcome = {};
    auto& t = setup.following[next_test++];
    setup.program = t.program;
    setup.analysis = t.analysis;
    segmenter = cal::daq::BallbarSegmenter(setup.program);
    live = {};
    writer.reset();
    try {
      begin_test();
    } catch (const std::exception& e) {
      return abort(fmt::format("storage failed: {}", e.what()));
    }
    running = true;
  }

  // Runner's hooks: how a circle run records its abort and stops its bar.
  std::int64_t current_run() const override { return outcome.run_id; }
  void aborting(const std::string& reason) override { outcome.reason = reason; }
  void aborted(const std::string& reason) override {
    outcome.reason = reason;
    publish_end("aborted");
  }
  void stop_instruments() override { setup.ballbar->stop(); }
};

CircleRun::CircleRun(boost::asio::io_context& io, CircleRunSetup setup)
    : impl_(std::make_unique<Impl>(io, std::move(setup))) {}
CircleRun::~CircleRun() { impl_->stop_if_running(); }
void CircleRun::start() { impl_->start(); }
void CircleRun::stop(const std::string& reason) { impl_->abort(reason); }
bool CircleRun::finished() const { return impl_->done; }
const CircleRunOutcome& CircleRun::outcome() const { return impl_->outcome; }
const std::vector<CircleRunOutcome>& CircleRun::completed() const { return impl_->completed; }

}  // namespace daq
