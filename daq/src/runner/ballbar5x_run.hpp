#pragma once
// A five-axis ballbar run (issue 36): the ballbar's gauge streams while a rotary table axis
// turns and the linear axes follow the ball (cal::kinematics::RotaryBallbarTest, one test per
// set-up of the bar), every reading is stored raw, the RotaryBallbarSegmenter finds each test's
// feed-in and the program's stops by its timing (a ballbar has no angle sensor, as in a circle
// run), the bar's mean reading at each stop is fitted into the axis's four location errors with
// their uncertainty (cal::kinematics::fit_rotary_ballbar) and the result is stored with the run
// (kind "ballbar5x", schema caldaq.ballbar5x.v1). The maths: docs/kinematics.md, "The ballbar on
// a rotary axis"; the procedure: docs/five-axis-walkthrough.md, section 7.
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <vector>

#include "cal/analysis/ballbar5x.hpp"
#include "cal/daq/config.hpp"
#include "cal/drivers/instrument.hpp"
#include "origin.hpp"

namespace boost::asio {
class io_context;
}

namespace daq {

// The program's timing, which both the simulated machine runs and the segmenter reads by: each
// test starts with the spindle ball `feed_in_mm` out along the bar (the bar set up, `out_s`),
// moves in over `feed_in_s`, then at each angle of the test dwells `dwell_s` and turns to the
// next at `rate_deg_per_s` (the linear axes following), and moves out again after the last.
struct RotaryBallbarTiming {
  double sample_rate_hz = 100.0;  // the gauge's streaming rate
  double feed_in_mm = 1.5;
  double feed_in_s = 0.5;
  double out_s = 2.0;
  double dwell_s = 2.0;
  double settle_s = 0.5;  // a stop is averaged from settle_s after its start to settle_s / 2
                          // before its end (the axes settle; the feed-in's end is found late
                          // by up to a few samples)
  double rate_deg_per_s = 10.0;
  // Seconds from a test's feed-in end to the start of its stop k.
  std::vector<double> stop_starts_s(const std::vector<double>& angles_deg) const;
};
nlohmann::json timing_json(const RotaryBallbarTiming& t);

// One stop's reading: the mean of the bar's samples in its window (um) and how many.
struct RotaryBallbarStop {
  double angle_deg = 0.0;
  double reading_um = 0.0;
  double spread_um = 0.0;  // standard deviation of its samples
  std::size_t samples = 0;
};

// The stream of bar readings (mm, at the gauge's fixed rate) cut into the tests' stops.
class RotaryBallbarSegmenter {
 public:
  RotaryBallbarSegmenter(std::vector<cal::kinematics::RotaryBallbarTest> tests,
                         RotaryBallbarTiming timing);
  void add(double reading_mm);
  bool complete() const { return test_ == tests_.size(); }
  std::size_t current_test() const { return test_; }
  bool measuring() const { return feed_in_end_.has_value(); }
  // Each test's stops; throws cal::InputError when not complete (naming the test waited for).
  std::vector<std::vector<RotaryBallbarStop>> stops() const;

 private:
  std::vector<cal::kinematics::RotaryBallbarTest> tests_;
  RotaryBallbarTiming t_;
  std::vector<double> starts_;  // of the current test's stops
  std::vector<std::vector<RotaryBallbarStop>> stops_;
  std::vector<double> sum_sq_;  // of the current test's stops, for the spread
  std::size_t test_ = 0, index_ = 0, settle_count_ = 0;
  bool saw_out_ = false;
  std::optional<std::size_t> feed_in_end_;
};

// The fit of each axis's tests and the result document (caldaq.ballbar5x.v1): per axis the four
// location errors with their uncertainty, what is left against the control's own (`left`: the
// fitted less the control's; with a nominal control the same), the bar offsets, residuals and
// the stops. Throws cal::InputError when the tests cannot separate the errors.
nlohmann::json ballbar5x_result(const cal::kinematics::FiveAxisMachine& control,
                                const std::vector<cal::kinematics::RotaryBallbarTest>& tests,
                                const std::vector<std::vector<RotaryBallbarStop>>& stops);
// The fitted location errors of a result, by name (E_X0C ...): value and uncertainty.
struct FittedLocation {
  std::string name;
  double value = 0.0, uncertainty = 0.0, left = 0.0;
};
std::vector<FittedLocation> fitted_locations(const nlohmann::json& result);

struct RotaryBallbarRunSetup {
  cal::daq::Config config;                   // machine and campaign names
  cal::kinematics::FiveAxisMachine control;  // the kinematics the program was computed with
  std::vector<cal::kinematics::RotaryBallbarTest> tests;
  RotaryBallbarTiming timing;
  std::string extra_settings_json;  // an object merged into the run's settings (its files)
  // The file config's tolerances were read from (daq model ballbar5x-run --tolerances; "": the
  // configuration's), named in the limits stored with the run: the verdict's basis says it.
  std::string tolerances_file;
  std::filesystem::path database;
  std::unique_ptr<cal::drivers::Instrument> ballbar;
  // Where the bar's readings come from, stored with the run (docs/storage.md "Origin"); every
  // run is the simulated one of daq model ballbar5x-run so far, which says which twin.
  InstrumentOrigin ballbar_origin{.kind = "simulated", .detail = ""};
  std::string software_version = "daq 0.1.0";
  std::function<void(const std::string&)> on_event;
};

struct RotaryBallbarRunOutcome {
  std::int64_t run_id = 0;
  bool complete = false;
  std::string reason;
  std::size_t readings = 0;
  std::string result_json;  // the stored document (empty until complete)
};

class RotaryBallbarRun {
 public:
  RotaryBallbarRun(boost::asio::io_context& io, RotaryBallbarRunSetup setup);
  ~RotaryBallbarRun();
  void start();
  void stop(const std::string& reason);
  bool finished() const;
  const RotaryBallbarRunOutcome& outcome() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace daq
