#pragma once
// One ballbar circular test, acquired: the bar's gauge instrument streams readings, every
// reading is stored raw, the BallbarSegmenter finds the feed-in and cuts the two traces, and
// the ISO 230-4 / diagnostics result is stored with the run.
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <span>
#include <string>

#include "cal/analysis/circle.hpp"
#include "cal/daq/ballbar.hpp"
#include "cal/daq/config.hpp"
#include "origin.hpp"
#include "cal/daq/gcode.hpp"
#include "cal/drivers/instrument.hpp"
#include "cal/storage/store.hpp"

namespace boost::asio {
class io_context;
}

namespace daq {

// How the traces of a ballbar stream are analysed (besides the program's timing).
struct BallbarAnalysis {
  std::string plane = "XY";                    // XY | YZ | ZX: names the axes of the diagnostics
  std::optional<double> calibrated_radius_mm;  // the bar's calibrated length; unset: nominal
  std::optional<double> cyclic_period_mm;      // unset: searched
  bool uncalibrated = false;                   // no calibrator: no radius error
  std::string standard = "iso230-4:2005";      // cal::circle::circular_standard_from_key
  // Where calibrated_radius_mm came from (docs/circle.md, "Bar calibration"): "stored" (a
  // calibration of the bar in the run store, `calibration`), "configuration"
  // (calibrated_radius_mm in [test.circle]), "option" (daq analyse RUN --calibrated-radius-mm);
  // empty with `uncalibrated` and the reason.
  std::string calibration_source;
  std::optional<cal::storage::BarCalibration> calibration;
  std::string uncalibrated_reason;
};

// Where a test's absolute radius comes from, once, when its run starts: the configuration's
// calibrated_radius_mm; else the newest stored calibration of the configuration's bar at the
// test's radius made at or before `at_unix_ms`; else none, and the analysis is uncalibrated
// with the reason (the radius error is then not evaluated). An analysis already decided (a
// length or uncalibrated set) is left as it is.
void resolve_calibration(BallbarAnalysis& a, const cal::daq::Config& c, double radius_mm,
                         const cal::storage::RunReader& store, std::int64_t at_unix_ms);

// The ISO 230-4 result and diagnostics of a ballbar stream (one deviation per sample, in mm
// from the calibrated length, from before the feed-in): segmentation by the program's timing,
// then cal::circle::analyse. Used at the end of a run and again on the stored readings
// (daq analyse RUN). Throws cal::InputError when the stream is incomplete.
cal::circle::Result analyse_ballbar(const cal::daq::BallbarProgram& program,
                                    const BallbarAnalysis& analysis,
                                    std::span<const double> deviation_mm);
// A stored run's bar readings streamed into the program's segmenter, whose samples are paged:
// its sources() are read in place, in bounded memory however long the run (issue 32; daq
// analyse RUN, the report and the served trace plot).
cal::daq::BallbarSegmenter segment_stored_run(const cal::storage::RunReader& store,
                                              std::int64_t run_id,
                                              const cal::daq::BallbarProgram& program);
// The same for traces already cut (cal::daq::BallbarSegmenter::sources: read in place, in
// bounded memory).
cal::circle::Result analyse_traces(const cal::daq::BallbarProgram& program,
                                   const BallbarAnalysis& analysis,
                                   std::span<const cal::circle::TraceSource> traces);

// The result document (caldaq.circle.v2) of a ballbar test by the analysis' standard, and the
// same for a terminal.
nlohmann::json circle_document(const cal::circle::Result& r,
                               const cal::daq::BallbarProgram& program,
                               const BallbarAnalysis& analysis);
void print_circle_result(const cal::circle::Result& r, const cal::daq::BallbarProgram& program,
                         const BallbarAnalysis& analysis);
// The label a result is stored under ("ISO 230-4:2005", "GB/T 17421.4-2016", ...).
std::string standard_label(const BallbarAnalysis& analysis);

// The program and analysis settings stored with a circle run (runs.settings_json), and back.
nlohmann::json circle_settings_json(const cal::daq::BallbarProgram& p, const BallbarAnalysis& a);
std::pair<cal::daq::BallbarProgram, BallbarAnalysis> circle_settings_from_json(
    const nlohmann::json& j);

// One test of a configuration's [test.circle]: its plane, program and analysis.
struct CircleTest {
  cal::daq::Plane plane = cal::daq::Plane::xy;
  cal::daq::BallbarProgram program;
  BallbarAnalysis analysis;
};
// Every test of [test.circle] in the order of its program: one for a single test (`plane`), the
// set for `planes` (each plane at each feed, for each radius: cal::daq::ballbar_set); with
// `standard_set`, the set of XY, ZX, YZ even for a single-test configuration. The same programs
// `daq gcode circle` writes.
std::vector<CircleTest> circle_tests(const cal::daq::Config& c, bool standard_set = false);
// The centre (the table ball) and plane of the configuration, for the part program.
cal::daq::CircleProgramSetup circle_program_setup(const cal::daq::Config& c);

// The ballbar program and analysis of a configuration's single [test.circle] (its first test).
std::pair<cal::daq::BallbarProgram, BallbarAnalysis> circle_test(const cal::daq::Config& c);

// The live state of a circle run for the operator's display (about 10 Hz).
struct CircleLive {
  double time_s = 0.0;
  std::string state;          // "waiting", "measuring", "complete", "aborted"
  std::string phase;          // "waiting for the feed-in", "dwell", "ccw arc", "cw arc", "complete"
  double angle_deg = 0.0;     // programmed angle of the latest sample
  double deviation_um = 0.0;  // the bar's latest deviation
  double fraction = 0.0;      // of the test after the feed-in
  std::size_t samples = 0;    // 0: the bar has sent nothing (no deviation is shown)
  // The live polar trace: (programmed angle in deg, deviation in um) of each arc, a point
  // every degree or more (about 900 points for a whole test).
  std::vector<std::pair<double, double>> ccw, cw;
};
std::string to_json_text(const CircleLive& s);  // schema caldaq.live-circle.v1 (docs/cli.md)

struct CircleRunSetup {
  cal::daq::Config config;  // machine, campaign
  cal::daq::BallbarProgram program;
  BallbarAnalysis analysis;
  std::filesystem::path database;
  std::unique_ptr<cal::drivers::Instrument> ballbar;
  std::string capture_path;
  std::string software_version = "daq 0.1.0";
  // The run's context as JSON (provenance.hpp); empty: made from `config`. A replay passes the
  // original run's, and says which run it replays when that is known.
  std::string context_json;
  bool replay = false;
  std::optional<std::int64_t> replay_of_run;
  Origins origins;  // the ballbar's by its role (origin.hpp), stored with the run
  // The time the bar's calibration is looked up at (unix ms; 0: now). A replay decides the
  // calibration before (the original run's, or the newest), so that this lookup does nothing.
  std::int64_t calibration_at_unix_ms = 0;
  cal::storage::StoreOptions store_options;  // the run's and the writer's (tests: max_pages)
  // A ballbar set (docs/circle.md, "The standard set"): the tests after the first, in the
  // order of the program. Each is recognised in turn on the same bar stream (its feed-in after
  // the previous test's cw arc) and stored as its own run of the configuration's campaign.
  std::vector<CircleTest> following;
  std::function<void(const std::string&)> on_event;
  std::function<void(const CircleLive&)> on_live;                // about 10 Hz of the bar's time
  std::function<void(const cal::drivers::Reading&)> on_reading;  // every reading
};

struct CircleRunOutcome {
  cal::daq::BallbarProgram program;
  BallbarAnalysis analysis;  // as used: the bar calibration resolved
  std::int64_t run_id = 0;
  bool complete = false;
  std::string reason;
  std::optional<cal::circle::Result> result;
  std::size_t readings = 0;
};

class CircleRun {
 public:
  CircleRun(boost::asio::io_context& io, CircleRunSetup setup);
  ~CircleRun();
  void start();
  void stop(const std::string& reason);
  bool finished() const;
  const CircleRunOutcome& outcome() const;  // the current (last) test's
  // The tests of a set completed before the current one, in order.
  const std::vector<CircleRunOutcome>& completed() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace daq
