// daq analyse straightness | squareness.
#include <fmt/format.h>

#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "cal/analysis/error.hpp"
#include "cal/analysis/kinematics.hpp"
#include "cal/analysis/squareness.hpp"
#include "cal/analysis/straightness.hpp"
#include "cli_checks.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "csv_columns.hpp"
#include "output_file.hpp"
#include "report/report.hpp"

namespace daq {
namespace {

using nlohmann::json;

// Named numeric columns of a CSV with a header line (csv_columns.hpp, the strict reader).
std::map<std::string, std::vector<double>> read_columns(const std::string& path,
                                                        std::initializer_list<const char*> names,
                                                        const CsvOptions& options) {
  return read_csv_columns(path, std::vector<std::string>(names.begin(), names.end()), {}, options)
      .numbers;
}

struct StraightnessOptions {
  std::string input;
  std::string reference = "lsq";
  std::string report;
  bool json = false;
  CsvOptions csv;
};

void run_straightness(const StraightnessOptions& o) {
  auto cols = read_columns(o.input, {"position_mm", "deviation_um"}, o.csv);
  const auto ref = cal::straightness::reference_from_string(o.reference);
  const auto r = cal::straightness::evaluate(cols["position_mm"], cols["deviation_um"], ref);
  if (!o.report.empty())
    write_report_page(o.report, cal::daq::report::straightness_report(
                                    {o.input, cols["position_mm"], cols["deviation_um"]},
                                    {.software = "daq 0.1.0"}));
  if (o.json) {
    json j{{"schema", "caldaq.straightness.v1"},
           {"standard", "ISO 230-1:2012"},
           {"reference", cal::straightness::to_string(ref)},
           {"straightness_um", r.straightness_um},
           {"slope_um_per_m", r.slope_um_per_m},
           {"intercept_um", r.intercept_um},
           {"position_mm", cols["position_mm"]},
           {"residual_um", r.residual_um}};
    return fmt::print("{}\n", j.dump(2));
  }
  fmt::print("Straightness (ISO 230-1), {} reference line, {} points\n",
             cal::straightness::to_string(ref), r.residual_um.size());
  fmt::print(
      "  straightness  {:8.3f} um\n  slope         {:8.3f} um/m\n  intercept     {:8.3f} um\n",
      r.straightness_um, r.slope_um_per_m, r.intercept_um);
}

struct SquarenessOptions {
  std::string method;
  std::string along_a, along_b;  // straightness
  double square_error = 0.0;
  double x_mm = 0, y_mm = 0, d1_um = 0, d2_um = 0;  // diagonal
  std::string circle;                               // circle CSV
  double radius_mm = 0;
  std::string report;
  std::string plane;  // XY, XZ or YZ: also give the model's location error
  bool json = false;
  CsvOptions csv;
};

void run_squareness(const SquarenessOptions& o) {
  cal::squareness::Result r;
  std::string how;
  if (o.method == "straightness") {
    if (o.along_a.empty() || o.along_b.empty())
      throw cal::InputError("squareness --method straightness needs --along-a and --along-b");
    auto a = read_columns(o.along_a, {"position_mm", "deviation_um"}, o.csv);
    auto b = read_columns(o.along_b, {"position_mm", "deviation_um"}, o.csv);
    r = cal::squareness::from_straightness({a["position_mm"], a["deviation_um"]},
                                           {b["position_mm"], b["deviation_um"]}, o.square_error);
    how = "two straightness runs (least-squares lines)";
    if (!o.report.empty())
      write_report_page(o.report, cal::daq::report::squareness_report(
                                      {o.along_a, a["position_mm"], a["deviation_um"]},
                                      {o.along_b, b["position_mm"], b["deviation_um"]},
                                      o.square_error, {.software = "daq 0.1.0"}));
  } else if (!o.report.empty()) {
    throw cal::InputError("squareness --report draws the two runs of --method straightness");
  } else if (o.method == "diagonal") {
    r = cal::squareness::from_diagonals(o.x_mm, o.y_mm, o.d1_um, o.d2_um);
    how = "ISO 230-6 diagonal displacement test";
  } else if (o.method == "circle") {
    if (o.circle.empty() || !(o.radius_mm > 0))
      throw cal::InputError("squareness --method circle needs --circle FILE and --radius-mm");
    auto c = read_columns(o.circle, {"angle_deg", "deviation_um"}, o.csv);
    const cal::squareness::CircleTrace t{c["angle_deg"], c["deviation_um"]};
    r = cal::squareness::from_circle(o.radius_mm, std::span(&t, 1));
    how = "circular test (sin 2t term)";
  } else {
    throw cal::InputError(fmt::format(
        "squareness method '{}' (expected straightness, diagonal or circle)", o.method));
  }
  std::optional<cal::kinematics::Plane> plane;
  if (!o.plane.empty()) plane = cal::kinematics::plane_from_string(o.plane);
  // 1 um/m = 1 urad: the model's location error in the ISO 230-1 sign (E_B0Z opposite).
  const double location_urad =
      plane ? cal::kinematics::location_error_from_angle_over_90(*plane, r.squareness_um_per_m) : 0;
  if (o.json) {
    json j{{"schema", "caldaq.squareness.v1"},
           {"method", o.method},
           {"squareness_um_per_m", r.squareness_um_per_m},
           {"squareness_arcsec", r.arcsec()},
           {"convention",
            "positive when the angle between the positive axis directions exceeds 90 deg"}};
    if (plane)
      j["location_error"] = {{"plane", cal::kinematics::to_string(*plane)},
                             {"name", cal::kinematics::location_error_name(*plane)},
                             {"iso230_1_urad", location_urad}};
    return fmt::print("{}\n", j.dump(2));
  }
  fmt::print(
      "Squareness by {}:\n  {:+.3f} um/m ({:+.3f} arcsec); positive: the angle between the "
      "positive "
      "axis directions exceeds 90 degrees\n",
      how, r.squareness_um_per_m, r.arcsec());
  if (plane)
    fmt::print(
        "  model ({} plane): {} = {:+.3f} urad (ISO 230-1 location error; "
        "caldaq.model.v1 \"iso230_1_urad\")\n",
        cal::kinematics::to_string(*plane), cal::kinematics::location_error_name(*plane),
        location_urad);
}

}  // namespace

void add_geometry_commands(CLI::App& /*app*/, CLI::App& analyse) {
  const auto [st, s] =
      add_command<StraightnessOptions>(analyse, "straightness", run_straightness,
                                       "Straightness of an axis (ISO 230-1 reference lines)");
  st->add_option("-i,--input", s->input, "CSV: position_mm, deviation_um")->required();
  st->add_option("-r,--reference", s->reference, "lsq, endpoint or minzone")->capture_default_str();
  st->add_option("--report", s->report,
                 "Also write an HTML report with the deviations and all three reference lines");
  add_decimal_comma_flag(*st, s->csv);
  st->add_flag("--json", s->json, "Print caldaq.straightness.v1 JSON");

  const auto [sq, q] = add_command<SquarenessOptions>(
      analyse, "squareness", run_squareness, "Squareness of two axes (ISO 230-1, ISO 230-6)");
  sq->add_option("-m,--method", q->method, "straightness, diagonal or circle")->required();
  sq->add_option("--along-a", q->along_a,
                 "straightness: run moving the reference axis (deviation in +B)");
  sq->add_option("--along-b", q->along_b,
                 "straightness: run moving the other axis (deviation in +A)");
  sq->add_option("--square-error", q->square_error, "straightness: the square's own error, um/m");
  sq->add_option("--x-mm", q->x_mm, "diagonal: side along A");
  sq->add_option("--y-mm", q->y_mm, "diagonal: side along B");
  sq->add_option("--d1-um", q->d1_um, "diagonal: length error of the (X,0)-(0,Y) diagonal");
  sq->add_option("--d2-um", q->d2_um, "diagonal: length error of the (0,0)-(X,Y) diagonal");
  sq->add_option("--circle", q->circle, "circle: CSV angle_deg, deviation_um");
  sq->add_option("--radius-mm", q->radius_mm, "circle: radius");
  sq->add_option("--report", q->report,
                 "straightness: also write an HTML report with both runs and their lines");
  sq->add_option("--plane", q->plane,
                 "XY, XZ or YZ: also print the model's location error (E_C0Y, E_B0Z, E_A0Z; "
                 "E_B0Z has the opposite sign)");
  add_decimal_comma_flag(*sq, q->csv);
  sq->add_flag("--json", q->json, "Print caldaq.squareness.v1 JSON");
}

}  // namespace daq
