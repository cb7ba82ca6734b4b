// daq model testpiece: the ISO 10791-7 test piece predicted from the model, and CMM points
// evaluated with the same reference fits.
#include <fmt/format.h>

#include <cmath>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>

#include "cal/analysis/error.hpp"
#include "cal/analysis/testpiece.hpp"
#include "cli_checks.hpp"
#include "command.hpp"
#include "csv_columns.hpp"
#include "model_cli.hpp"

namespace daq {
namespace {

namespace tp = cal::testpiece;

struct Options {
  std::string file, cmm, db;
  std::vector<double> origin_mm;
  double tool_radius_mm = 0.0;
  tp::Layout layout;
  bool json = false;
};

// One row per result: name, quantity, predicted, measured (if any).
struct Row {
  std::string feature, quantity;
  double predicted = 0.0;
  std::optional<double> measured;
};

std::vector<Row> rows_of(const tp::Result& p, const std::optional<tp::Result>& m) {
  std::vector<Row> rows;
  const auto find_face = [&](const std::string& f) -> const tp::FaceResult* {
    if (!m) return nullptr;
    for (const auto& x : m->faces)
      if (x.feature == f) return &x;
    return nullptr;
  };
  const auto find_bore = [&](const std::string& f) -> const tp::BoreResult* {
    if (!m) return nullptr;
    for (const auto& x : m->bores)
      if (x.feature == f) return &x;
    return nullptr;
  };
  const auto opt = [](const auto* x, double v) {
    return x ? std::optional<double>(v) : std::nullopt;
  };
  for (const auto& f : p.faces) {
    const auto* mf = find_face(f.feature);
    rows.push_back(
        {f.feature, "straightness_um", f.straightness_um, opt(mf, mf ? mf->straightness_um : 0)});
  }
  const auto pairs = [&](const auto& pred, const auto* meas, const char* quantity) {
    for (const auto& [name, v] : pred) {
      std::optional<double> mv;
      if (meas)
        for (const auto& [n2, v2] : *meas)
          if (n2 == name) mv = v2;
      rows.push_back({name, quantity, v, mv});
    }
  };
  pairs(p.squareness_um_per_m, m ? &m->squareness_um_per_m : nullptr, "squareness_um_per_m");
  pairs(p.parallelism_um_per_m, m ? &m->parallelism_um_per_m : nullptr, "parallelism_um_per_m");
  for (const auto& b : p.bores) {
    const auto* mb = find_bore(b.feature);
    rows.push_back(
        {b.feature, "circularity_um", b.circularity_um, opt(mb, mb ? mb->circularity_um : 0)});
    if (b.feature != "bore0") {
      const bool positions = m && m->aligned;
      rows.push_back({b.feature, "position_x_um", b.position_x_um,
                      positions ? opt(mb, mb ? mb->position_x_um : 0) : std::nullopt});
      rows.push_back({b.feature, "position_y_um", b.position_y_um,
                      positions ? opt(mb, mb ? mb->position_y_um : 0) : std::nullopt});
    }
  }
  return rows;
}

void run(const Options& given) {
  const auto in = read_model_input(given.file, given.db);
  Options o = given;
  o.file = in.label;  // the file, or the stored model: what the output names
  const mdl::Model& model = in.model;
  mdl::require_no_rotary(model, o.file, "daq model testpiece");
  if (o.origin_mm.size() != 3)
    throw cal::InputError("--origin-mm needs X Y Z (Z: the cutting height)");
  tp::Cutting cut;
  cut.origin_mm = {o.origin_mm[0], o.origin_mm[1], o.origin_mm[2]};
  cut.tool_radius_mm = o.tool_radius_mm;
  const auto profiles = tp::predict_profiles(model.machine, o.layout, cut);
  for (const auto& p : profiles)  // before the fits, which refuse them without naming the model
    require_finite(p.deviation_um,
                   fmt::format("{}: the predicted profile of {}", o.file, p.feature));
  const tp::Result predicted = tp::evaluate(o.layout, profiles);
  std::optional<tp::Result> measured;
  if (!o.cmm.empty()) {
    const auto csv = read_csv_columns(o.cmm, {"x_mm", "y_mm"}, {"feature"});
    std::vector<tp::Point> pts;
    for (std::size_t r = 0; r < csv.rows(); ++r)
      pts.push_back(
          {csv.texts.at("feature")[r], csv.numbers.at("x_mm")[r], csv.numbers.at("y_mm")[r]});
    try {
      measured = tp::evaluate(o.layout, tp::measured_profiles(o.layout, pts));
    } catch (const cal::InputError& e) {
      throw cal::InputError(fmt::format("{}: {}", o.cmm, e.what()));
    }
  }
  const auto rows = rows_of(predicted, measured);
  for (const auto& r : rows)
    require_finite(std::array{r.predicted, r.measured.value_or(0.0)},
                   fmt::format("{} {}", r.feature, r.quantity));
  if (o.json) {
    json out = json::array();
    for (const auto& r : rows) {
      json j{{"feature", r.feature}, {"quantity", r.quantity}, {"predicted", r.predicted}};
      if (r.measured) j["measured"] = *r.measured, j["difference"] = *r.measured - r.predicted;
      out.push_back(j);
    }
    fmt::print("{}\n", json{{"schema", "caldaq.testpiece.v1"},
                            {"model", o.file},
                            {"origin_mm", o.origin_mm},
                            {"tool_radius_mm", o.tool_radius_mm},
                            {"cmm", o.cmm.empty() ? json(nullptr) : json(o.cmm)},
                            {"results", out}}
                           .dump(2));
    return;
  }
  fmt::print(
      "Test piece (after ISO 10791-7) predicted from {}, tool radius {:g} mm, part origin "
      "({:g}, {:g}, {:g}) mm{}\n",
      o.file, o.tool_radius_mm, o.origin_mm[0], o.origin_mm[1], o.origin_mm[2],
      o.cmm.empty() ? "" : ", against the CMM points of " + o.cmm);
  fmt::print("{:18} {:22} {:>10}{}\n", "feature", "quantity", "predicted",
             measured ? fmt::format(" {:>10} {:>10}", "measured", "difference") : "");
  for (const auto& r : rows) {
    std::string extra;
    if (measured)
      extra = r.measured ? fmt::format(" {:>10} {:>10}", fixed_text(*r.measured, 3),
                                       fixed_text(*r.measured - r.predicted, 3))
                         : fmt::format(" {:>10} {:>10}", "-", "-");
    fmt::print("{:18} {:22} {:>10}{}\n", r.feature, r.quantity, fixed_text(r.predicted, 3), extra);
  }
  if (measured && !measured->aligned)
    fmt::print("note: the CMM points lack face-Y or bore0, so bore positions are not compared\n");
}

}  // namespace

void add_model_testpiece_command(CLI::App& model) {
  const auto [cmd, o] = add_command<Options>(
      model, "testpiece", run,
      "Predict the test piece (faces' straightness, squareness, parallelism; bores' circularity "
      "and position) and compare CMM points");
  cmd->add_option("file", o->file, "Model file (caldaq.model.v1)")->required();
  add_model_db_option(*cmd, o->db);
  cmd->add_option("--origin-mm", o->origin_mm,
                  "Machine position of the part's centre X Y and the cutting height Z")
      ->expected(3)
      ->check(finite_in(-kMaxPositionMm, kMaxPositionMm))
      ->required();
  cmd->add_option("--tool-radius-mm", o->tool_radius_mm, "Radius of the end mill")
      ->required()
      ->check(finite_in(0, kMaxPositionMm));
  cmd->add_option("--side-mm", o->layout.side_mm, "Side of the square")
      ->check(finite_in(0, kMaxPositionMm))
      ->capture_default_str();
  cmd->add_option("--centre-bore-mm", o->layout.centre_bore_diameter_mm, "Diameter of bore0")
      ->check(finite_in(0, kMaxPositionMm))
      ->capture_default_str();
  cmd->add_option("--corner-bore-mm", o->layout.corner_bore_diameter_mm,
                  "Diameter of bore1 .. bore4")
      ->check(finite_in(0, kMaxPositionMm))
      ->capture_default_str();
  cmd->add_option("--corner-offset-mm", o->layout.corner_bore_offset_mm,
                  "Corner bores at (+-offset, +-offset)")
      ->check(finite_in(0, kMaxPositionMm))
      ->capture_default_str();
  cmd->add_option("--cmm", o->cmm, "CMM points, CSV feature,x_mm,y_mm in the part's frame");
  cmd->add_flag("--json", o->json, "Print caldaq.testpiece.v1 JSON");
}

}  // namespace daq
