#pragma once
// A machine's stored ballbar tests (circle runs and their current results): the three-plane
// table of a campaign (docs/circle.md, "The three-plane table") and the history of the same
// machine's tests per plane and feed with their verdicts. Used by `daq ballbar volumetric`,
// `daq ballbar history` and the campaign report.
#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cal/analysis/ballbar_planes.hpp"
#include "cal/storage/store.hpp"
#include "verdict.hpp"

namespace daq {

// One stored ballbar test: a circle run with its current result.
struct BallbarTest {
  std::int64_t run = 0;
  std::int64_t started_unix_ms = 0;
  std::string campaign;
  cal::circle::Plane plane = cal::circle::Plane::xy;
  std::string plane_name;  // "XY", "YZ", "ZX"
  double feed_mm_per_min = 0.0, radius_mm = 0.0, arc_deg = 360.0;
  std::string standard;  // the result's label
  double G_bi_um = 0.0;
  // The diagnostics the table and the history use (unset: not fitted, e.g. one direction).
  std::optional<double> squareness_um_per_m, scale_mismatch_um_per_m, servo_ms, radius_error_um;
  std::string servo_name, mismatch_name;  // "Servo mismatch (Y lags X)", "Scale mismatch X - Y"
  std::optional<std::array<double, 3>> centre_mm;  // where the table ball was (runs since #18)
  Verdict verdict;
};

// The runs given, in that order, each with its current circle result. cal::InputError naming
// the database and run for an unknown run, a run that is not a circle, or one without a result.
std::vector<BallbarTest> ballbar_tests(const cal::storage::RunReader& store,
                                       std::span<const std::int64_t> runs);
// The complete circle runs of a machine (optionally of one campaign), oldest first.
// cal::InputError for an unknown machine; empty when it has no such run.
std::vector<std::int64_t> ballbar_runs(const cal::storage::RunReader& store, std::string_view machine,
                                       std::string_view campaign = {});

// The three-plane table of a set of tests: per plane, the tests at its slowest feed (servo
// errors grow with the feed, geometric ones do not), their squareness and scale mismatch
// averaged, and the radius error of the calibrated ones as the mean scale.
struct VolumetricTable {
  cal::circle::ThreePlanes combined;
  struct PlaneUse {
    std::vector<std::int64_t> runs;  // the tests averaged
    double feed_mm_per_min = 0.0;
    std::optional<std::array<double, 3>> centre_mm;  // the first test's, when recorded
  };
  std::array<PlaneUse, 3> used;    // indexed by cal::circle::Plane
  std::vector<std::string> notes;  // tests left out and why, planes missing
};
VolumetricTable volumetric_table(std::span<const BallbarTest> tests);

nlohmann::json to_json(const BallbarTest& t);
// caldaq.ballbar-volumetric.v1: the table, the tests it used, and `model_squareness`, the
// block a caldaq.model.v1 file takes (docs/model-file.md).
nlohmann::json to_json(const VolumetricTable& v, std::span<const BallbarTest> tests);
nlohmann::json model_squareness(const VolumetricTable& v);

void print_volumetric(const VolumetricTable& v, std::span<const BallbarTest> tests);
// The history: per plane, feed and radius, each test oldest first with its values and verdict.
void print_history(std::span<const BallbarTest> tests);
nlohmann::json history_json(std::span<const BallbarTest> tests);

}  // namespace daq
