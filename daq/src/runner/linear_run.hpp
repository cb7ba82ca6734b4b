#pragma once
// One linear run of any test kind (kinds/kind.hpp: positioning, straightness, angular, roll),
// acquired. For positioning, an ISO 230-2 run: the laser, air and material instruments
// feed the pipeline stages on one io_context (environment compensation -> stability trigger
// -> sequencer), every raw reading goes to the run store through the batch writer, captured
// targets are stored as they come, and at the end the run is evaluated by its standard and
// the result stored. The other kinds read their instrument at the same stops (recognised by
// the laser's or the position feed's stability) and store their profile. A stale sensor under
// the stop policy, or an instrument that gives up, aborts the run with the reason recorded;
// what was stored stays.
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "cal/analysis/iso230_2.hpp"
#include "cal/analysis/iso230_2_targets.hpp"
#include "cal/daq/config.hpp"
#include "cal/daq/sequencer.hpp"
#include "cal/drivers/instrument.hpp"
#include "cal/storage/store.hpp"
#include "origin.hpp"

namespace boost::asio {
class io_context;
}

namespace daq {

struct LiveState {
  double time_s = 0.0;
  std::string state;    // "waiting", "measuring", "complete", "aborted"
  std::string message;  // the last event
  double position_mm = 0.0;
  double deviation_um = 0.0;  // from the next expected target
  cal::daq::Progress progress;
  double air_temperature_degc = 0.0, pressure_pa = 0.0, humidity_pct = 0.0, n = 1.0;
  double material_degc = 20.0, factor_ppm = 0.0;
  bool fallback = false;
  // What the operator's page shows (cal/daq/motion.hpp): the axis moving, settling, stable or
  // captured; while the position is within the capture window of a target, the deviation from
  // that target (not from the next expected one, which is meaningless while the axis moves).
  // The *_mm and *_um values in these units (deg and arcsec on a rotary axis), and the
  // instrument whose readings give the position (the laser, or a rotary axis's reference).
  cal::daq::AxisUnits units;
  std::string reference = "laser";
  bool has_reading = false;  // a reference reading arrived (until then: no number at all)
  bool valid = true;         // the newest laser reading was valid (not signal lost)
  std::string motion = "moving";
  double stable_fraction = 0.0;
  std::optional<double> at_target_mm;
  double at_target_deviation_um = 0.0;
  // The last captured stop: how long it settled, and was stable before the capture.
  std::optional<double> last_settling_s, last_stable_s;
  // Stop k of N: the next expected stop in plan order (k = N + 1 when complete).
  std::size_t stop_number = 0, stop_count = 0;
  struct Stop {
    std::size_t number = 0;  // 1-based, in plan order
    int run = 0, target = 0;
    bool up = true;
    double nominal_mm = 0.0, deviation_um = 0.0;
    bool missed = false;
    bool skipped = false;       // given up by the operator
    bool manual = false;        // captured by hand
    bool while_moving = false;  // captured by hand, forced while the axis moved
    bool pending = false;       // captured, its value still waiting for the kind's instrument
  };
  // What a captured stop's value is, and its unit: the deviation from the target (positioning,
  // rotary), or the kind's own value (straightness um, angular and roll urad), never the
  // laser's positioning deviation under the kind's name.
  std::string stop_value = "deviation";
  std::string stop_unit = "um";
  bool paused = false;      // no automatic capture until resumed (the operator's pause)
  std::vector<Stop> stops;  // captured or missed so far, in plan order
};
std::string to_json_text(const LiveState& s);

// The plan of a configuration's [test.linear]: what the run expects and the part program does.
cal::iso230_2::Plan linear_plan(
    const cal::daq::LinearTestConfig& l);  // schema caldaq.live.v1 (docs/cli.md)

struct LinearRunSetup {
  cal::daq::Config config;  // needs config.linear
  std::filesystem::path database;
  std::unique_ptr<cal::drivers::Instrument> laser;
  std::unique_ptr<cal::drivers::Instrument> air;
  std::vector<std::unique_ptr<cal::drivers::Instrument>> material;  // material thermometers
  // The channels of each material instrument that are material sensors (each its own series:
  // a TEMPer2's stick and probe are two sensors, never one). Missing or empty for an
  // instrument: one sensor, whatever its channel.
  std::vector<std::vector<std::uint8_t>> material_channels;
  // A machine position feed (optional): with one, stops are recognised from the control's
  // position (PositionTrigger) instead of the laser's stability; its channel is the test axis.
  std::unique_ptr<cal::drivers::Instrument> position;
  int position_channel = 0;
  // The feed sends a position only when it changes (MTConnect SHDR): its last sample holds.
  bool position_on_change = false;
  int laser_channel = 0;
  // The instrument of a test kind that reads besides the laser (kinds/kind.hpp): the
  // straightness indicator, the electronic level; null for positioning and angular runs.
  std::unique_ptr<cal::drivers::Instrument> probe;
  double datum_mm = 0.0;  // axis position where the laser reads 0
  std::string software_version = "daq 0.1.0";
  std::string capture_path;
  // The run's context (customer, machine, instruments, tolerances; provenance.hpp) as JSON;
  // empty: made from `config`. A replay passes the original run's.
  std::string context_json;
  // A replay of a capture: the results record it, and the original run when it is known.
  bool replay = false;
  std::optional<std::int64_t> replay_of_run;
  Origins origins;                           // by role: stored with each instrument (origin.hpp)
  cal::storage::StoreOptions store_options;  // the run's and the writer's (tests: max_pages)
  std::function<void(const LiveState&)> on_live;     // about 10 Hz
  std::function<void(const std::string&)> on_event;  // captures, missed stops, stale sensors
  std::function<void(const cal::drivers::Reading&)> on_reading;  // every reading (capture, web)
};

// The material sensors of a run: one per used channel of each material instrument (a TEMPer2's
// stick and probe are two sensors, two series); an instrument with no channels listed is one
// sensor, whatever its channel.
class MaterialSensors {
 public:
  MaterialSensors(std::size_t instruments, const std::vector<std::vector<std::uint8_t>>& channels);
  int count() const { return count_; }
  // The sensor of a reading of material instrument `k` on `channel`; -1: not a used channel.
  int sensor(std::size_t k, std::uint8_t channel) const;

 private:
  std::vector<int> first_;  // the first sensor of each instrument
  std::vector<std::vector<std::uint8_t>> channels_;
  int count_ = 0;
};

struct LinearRunOutcome {
  std::int64_t run_id = 0;
  // The run reached the end of its plan and was evaluated (also when stops were missed:
  // `status` is then incomplete and `missed` lists them).
  bool complete = false;
  cal::storage::RunStatus status = cal::storage::RunStatus::running;
  std::vector<cal::storage::MissedStop> missed;
  std::string reason;  // why it stopped, when not complete; the missed stops when incomplete
  std::optional<cal::iso230_2::Evaluation> evaluation;  // positioning
  std::optional<nlohmann::json> profile;  // the other kinds: caldaq.profile.v1 (kinds/kind.hpp)
  std::string component;                  // the ISO 230-1 component measured, e.g. "E_YX"
  std::size_t readings = 0;
  // The stops against the run's own repeatability (run_quality.hpp), as stored with the run.
  cal::storage::RunQuality quality;
};

// The operator's control of a running linear run (issue 29; docs/web.md): capture the current
// stop by hand, skip the next target, measure the last stop again, pause and resume automatic
// capture. Each one applied is recorded in the run (cal::storage::OperatorAction) as it happens.
enum class Control { capture, skip, retry, pause, resume };
std::string_view to_string(Control c);
struct ControlOutcome {
  bool applied = false;  // false: not applicable now, `message` says why
  std::string message;   // what happened, in words (the stop, its value)
  // A capture refused because the axis moves: a second press within this many seconds forces
  // it (0: nothing to force).
  double force_within_s = 0.0;
};

// A store or capture that fails (a full disk) ends the run as aborted with the reason
// ("storage failed: FILE: ..."), keeping what was written; nothing is thrown out of the
// instruments' handlers or the destructor.
class LinearRun {
 public:
  LinearRun(boost::asio::io_context& io, LinearRunSetup setup);
  ~LinearRun();
  void start();
  void stop(const std::string& reason);  // aborts
  void manual_capture();                 // the operator's "capture now" (from the keyboard)
  // `source` says where it came from ("web page", "keyboard (daq run)"), stored with it.
  ControlOutcome control(Control c, std::string_view source);
  // Gives the run's live state to `on_live` now (it does so every 100 ms by itself): a page that
  // shows it beside the instruments' newest readings takes both at the same moment (the laser's
  // raw reading and the run's position from it, not one from up to 100 ms before).
  void publish_live();
  bool finished() const;
  const LinearRunOutcome& outcome() const;
  const cal::iso230_2::Plan& plan() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace daq
