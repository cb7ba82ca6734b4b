// daq analyse circle: ISO 230-4 circular test and ballbar diagnostics from a CSV file.
#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "cal/analysis/circle.hpp"
#include "cal/analysis/circle_standards.hpp"
#include "cal/analysis/error.hpp"
#include "circle_output.hpp"
#include "cli_checks.hpp"
#include "commands.hpp"
#include "csv_table.hpp"

namespace daq {
namespace {

using nlohmann::json;
namespace ci = cal::circle;

ci::Plane plane_from(const std::string& p) {
  if (p == "XY") return ci::Plane::xy;
  if (p == "YZ") return ci::Plane::yz;
  if (p == "ZX") return ci::Plane::zx;
  throw cal::InputError(fmt::format("plane '{}' (expected XY, YZ or ZX)", p));
}

struct CircleOptions {
  std::string input;
  double radius_mm = 0.0;
  double feed_mm_per_min = 1000.0;
  std::string plane = "XY";
  double start_deg = 0.0;
  double arc_deg = 360.0;
  double overshoot_deg = 0.0;
  double spike_decay_deg = 6.0;
  double stick_slip_window_deg = 10.0;
  std::optional<double> cyclic_period_mm;
  std::optional<double> calibrated_radius_mm;
  bool uncalibrated = false;
  std::string standard = "iso230-4:2005";
  bool json = false;
  CsvOptions csv;
  bool has_lengths = false;  // the CSV gives length_mm (set by read_traces)

  ci::Setup setup() const {
    return {.plane = plane_from(plane),
            .radius_mm = radius_mm,
            .feed_mm_per_min = feed_mm_per_min,
            .cyclic_period_mm = cyclic_period_mm,
            .spike_decay_deg = spike_decay_deg,
            .stick_slip_window_deg = stick_slip_window_deg,
            .radius_calibrated = !uncalibrated,
            .calibrated_radius_mm = calibrated_radius_mm,
            .start_deg = start_deg,
            .arc_deg = arc_deg,
            .overshoot_deg = overshoot_deg};
  }
};

// Columns (docs/circle.md): direction (cw|ccw), angle_deg or time_s, deviation_um or length_mm.
std::vector<ci::Trace> read_traces(CircleOptions& o) {
  const auto csv = CsvTable::read(o.input, o.csv);
  const bool angles = csv.has("angle_deg"), deviations = csv.has("deviation_um");
  o.has_lengths = !deviations && csv.has("length_mm");
  if (!csv.has("direction") || (!angles && !csv.has("time_s")) || (!deviations && !o.has_lengths))
    throw cal::InputError(
        fmt::format("{}:{}: the header needs direction, angle_deg or time_s, and "
                    "deviation_um or length_mm",
                    o.input, csv.header_line()));
  std::map<ci::Direction, ci::Trace> traces;
  std::map<ci::Direction, std::vector<double>> times;
  for (std::size_t row = 0; row < csv.rows(); ++row) {
    const auto d = csv.text(row, "direction");
    if (d != "cw" && d != "ccw")
      csv.fail(row, fmt::format("column direction: '{}' (expected cw or ccw)", d.substr(0, 40)));
    const auto dir = d == "cw" ? ci::Direction::cw : ci::Direction::ccw;
    auto& t = traces[dir];
    t.direction = dir;
    if (angles)
      t.angle_deg.push_back(csv.number(row, "angle_deg"));
    else
      times[dir].push_back(csv.number(row, "time_s"));
    // length_mm: the absolute bar length, so the deviation is from the nominal radius (and
    // --calibrated-radius-mm must not shift it again: read_traces' caller clears it).
    t.deviation_um.push_back(deviations ? csv.number(row, "deviation_um")
                                        : (csv.number(row, "length_mm") - o.radius_mm) * 1e3);
  }
  if (traces.empty()) throw cal::InputError(fmt::format("{}: no data rows", o.input));
  std::vector<ci::Trace> out;
  for (auto& [dir, t] : traces) {
    if (t.angle_deg.empty())  // time_s: angles from the program, the overshoot arcs trimmed
      t = ci::trace_from_time(o.setup(), dir, times[dir], t.deviation_um);
    out.push_back(std::move(t));
  }
  return out;
}

json to_json(const ci::Result& r, const CircleOptions& o) {
  return circle_json(r, o.radius_mm, o.plane, o.feed_mm_per_min,
                     ci::circular_standard_from_key(o.standard));
}

void print(const ci::Result& r, const CircleOptions& o) {
  print_circle(r, o.radius_mm, o.plane, o.feed_mm_per_min,
               ci::circular_standard_from_key(o.standard));
}

}  // namespace

void add_circle_commands(CLI::App& /*app*/, CLI::App& analyse) {
  auto o = std::make_shared<CircleOptions>();
  auto* cmd =
      analyse.add_subcommand("circle", "Circular test: ISO 230-4 values and ballbar diagnostics");
  cmd->add_option("-i,--input", o->input,
                  "CSV: direction, angle_deg or time_s, deviation_um or length_mm")
      ->required();
  cmd->add_option("-R,--radius-mm", o->radius_mm, "Nominal radius")
      ->required()
      ->check(finite_positive());
  cmd->add_option("--feed-mm-min", o->feed_mm_per_min,
                  "Feed (for time-based angles and the servo lag)")
      ->capture_default_str()
      ->check(finite_positive());
  cmd->add_option("--plane", o->plane, "XY, YZ or ZX")->capture_default_str();
  cmd->add_option("--start-deg", o->start_deg,
                  "With time_s: angle where the ccw arc move starts (time 0 of each move)")
      ->capture_default_str();
  cmd->add_option("--arc-deg", o->arc_deg, "With time_s: the measured arc, 180..360")
      ->capture_default_str();
  cmd->add_option("--overshoot-deg", o->overshoot_deg,
                  "With time_s: overshoot arc before and after the measured arc (trimmed)")
      ->capture_default_str();
  cmd->add_option("--spike-decay-deg", o->spike_decay_deg, "Decay angle of a reversal spike")
      ->capture_default_str();
  cmd->add_option("--stick-slip-window-deg", o->stick_slip_window_deg,
                  "Stick-slip: window about each reversal of an axis (1 < W <= 45)")
      ->capture_default_str();
  cmd->add_option("--cyclic-period-mm", o->cyclic_period_mm,
                  "Cyclic-error period (default: searched)");
  cmd->add_option("--calibrated-radius-mm,--calibrated-length-mm", o->calibrated_radius_mm,
                  "Bar length at which deviation_um reads 0 (default: the nominal radius)")
      ->check(finite_positive());
  cmd->add_flag("--uncalibrated", o->uncalibrated, "The bar was not calibrated: no radius error");
  cmd->add_option("-s,--standard", o->standard,
                  "iso230-4:2005, gb/t17421.4-2016 (identical) or iso230-4:1996 (docs/circle.md, "
                  "\"Standards\")")
      ->capture_default_str();
  add_decimal_comma_flag(*cmd, o->csv);
  cmd->add_flag("--json", o->json, "Print caldaq.circle.v2 JSON");
  cmd->callback([o] {
    ci::circular_standard_from_key(o->standard);  // an unknown standard before reading the file
    const auto traces = read_traces(*o);
    auto setup = o->setup();
    if (o->has_lengths) setup.calibrated_radius_mm.reset();  // lengths are absolute
    // The radius error needs the bar's absolute length: absolute lengths in the file, or the
    // calibrated length given; otherwise only changes of length are known.
    setup.radius_calibrated = !o->uncalibrated && (o->has_lengths || o->calibrated_radius_mm);
    const auto r = ci::analyse(setup, traces);
    if (o->json) return fmt::print("{}\n", to_json(r, *o).dump(2));
    print(r, *o);
  });
}

}  // namespace daq
