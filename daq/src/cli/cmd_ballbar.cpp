// daq ballbar calibrate|calibrations: the bar's calibration against a calibrator, stored with
// its date, used for the absolute radius of later tests (docs/circle.md, "Bar calibration").
// daq ballbar volumetric|history: the three-plane table of a campaign's tests and a machine's
// tests over time (docs/circle.md, "The three-plane table", "History").
#include <fmt/format.h>

#include <cmath>
#include <ctime>
#include <nlohmann/json.hpp>
#include <optional>

#include "ballbar_campaign.hpp"
#include "bar_calibration_input.hpp"
#include "cal/analysis/error.hpp"
#include "cal/storage/store.hpp"
#include "cli_checks.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "database.hpp"
#include "json_input.hpp"
#include "model/model_file.hpp"
#include "provenance.hpp"
#include "terminal.hpp"

namespace daq {
namespace {

using nlohmann::json;
namespace st = cal::storage;

struct CalibrateOptions {
  std::string db, bar, calibrator, extensions, note;
  BarCalibrationInput values;
  bool json = false;
};

void calibrate(const CalibrateOptions& o) {
  const auto& v = o.values;
  const std::int64_t calibrated_unix_ms =
      check_bar_calibration(v, static_cast<std::int64_t>(std::time(nullptr)));
  st::BarCalibration c{.bar = o.bar,
                       .nominal_mm = v.nominal_mm,
                       .extensions = o.extensions,
                       .calibrator = o.calibrator,
                       .calibrator_length_mm = v.calibrator_mm,
                       .reading_mm = v.reading_mm,
                       .zero_length_mm = v.calibrator_mm - v.reading_mm,
                       .temperature_degc = v.temperature_degc,
                       .calibrated_unix_ms = calibrated_unix_ms,
                       .note = o.note};
  st::Store store(database_path(o.db));
  c.id = store.add_bar_calibration(c);
  const auto stored = store.bar_calibrations(c.bar);
  for (const auto& x : stored)
    if (x.id == c.id) c = x;
  if (o.json) {
    json j{{"schema", "caldaq.bar-calibration.v1"}};
    j.update(bar_calibration_json(c));
    return fmt::print("{}\n", cal::daq::dump_output(j, 2));
  }
  print_line(
      "calibration {} of bar '{}' at {:g} mm stored ({}): reads 0 at {:.4f} mm (calibrator {:.4f} "
      "mm, reading {:+.4f} mm)",
      c.id, c.bar, c.nominal_mm, utc_iso(c.calibrated_unix_ms), c.zero_length_mm,
      c.calibrator_length_mm, c.reading_mm);
}

void list(const std::string& db, const std::string& bar, bool as_json) {
  const auto reader = open_run_reader(db);  // either store (--db postgresql://...)
  const auto& store = *reader;
  const auto all = store.bar_calibrations(bar);
  if (as_json) {
    json j{{"schema", "caldaq.bar-calibrations.v1"}, {"calibrations", json::array()}};
    for (const auto& c : all) j["calibrations"].push_back(bar_calibration_json(c));
    return fmt::print("{}\n", cal::daq::dump_output(j, 2));
  }
  if (all.empty())
    return print_line("no ballbar calibration stored{}",
                      bar.empty() ? std::string() : fmt::format(" for bar '{}'", bar));
  print_line("{:>4}  {:<16} {:>9} {:<10} {:<24} {:>12} {:>10} {:>12}  {}", "id", "bar", "nominal",
             "extensions", "calibrator", "calibrator", "reading", "zero at", "date (UTC)");
  for (const auto& c : all)
    print_line("{:>4}  {:<16} {:>9.3f} {:<10} {:<24} {:>12.4f} {:>+10.4f} {:>12.4f}  {}", c.id,
               c.bar, c.nominal_mm, c.extensions.empty() ? "-" : c.extensions,
               c.calibrator.empty() ? "-" : c.calibrator, c.calibrator_length_mm, c.reading_mm,
               c.zero_length_mm, utc_iso(c.calibrated_unix_ms).substr(0, 16));
}

struct SetOptions {
  std::string db, machine, campaign, model_in, model_out;
  std::vector<std::int64_t> runs;
  bool json = false;
};

std::vector<BallbarTest> tests_of(const st::RunReader& store, const SetOptions& o) {
  if (!o.runs.empty() && !o.machine.empty())
    throw cal::InputError("give --runs or --machine, not both");
  if (o.runs.empty() && o.machine.empty())
    throw cal::InputError("give the tests: --machine NAME [--campaign C] or --runs N,N,...");
  const auto runs = o.runs.empty() ? ballbar_runs(store, o.machine, o.campaign) : o.runs;
  if (runs.empty())
    throw cal::InputError(
        fmt::format("{}: machine '{}' has no complete ballbar test{}", store.name(),
                    o.machine, o.campaign.empty() ? "" : " in campaign '" + o.campaign + "'"));
  return ballbar_tests(store, runs);
}

// The model file with the table's squareness in place of its own (the rest as it was).
void write_model(const VolumetricTable& v, const SetOptions& o) {
  namespace md = cal::daq::model;
  auto m = md::read(o.model_in);
  const json block = model_squareness(v);
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& pv = v.combined.planes[i];
    if (!pv) continue;
    const auto p = cal::circle::model_plane(pv->plane);
    const json& e = block[std::string(cal::kinematics::location_error_name(p))];
    auto& entry = m.squareness[static_cast<std::size_t>(p)];
    m.machine.squareness.of(p) = cal::circle::location_error_urad(*pv);
    entry.given = true;
    entry.stated_as = "iso230_1_urad";
    entry.method = e["method"].get<std::string>();
    entry.placement = e.value("placement", std::string());
    entry.position_mm.reset();
    if (e.contains("position_mm"))
      entry.position_mm = cal::kinematics::Vec3{e["position_mm"][0].get<double>(),
                                                e["position_mm"][1].get<double>(),
                                                e["position_mm"][2].get<double>()};
    entry.source.json = e["source"].dump();
  }
  md::write(m, o.model_out);
}

void volumetric(const SetOptions& o) {
  if (o.model_in.empty() != o.model_out.empty())
    throw cal::InputError("--model and --write-model go together (read one, write the other)");
  const auto reader = open_run_reader(o.db);  // either store (--db postgresql://...)
  const auto& store = *reader;
  const auto tests = tests_of(store, o);
  const auto v = volumetric_table(tests);
  if (!o.model_in.empty()) write_model(v, o);
  if (o.json) return fmt::print("{}\n", cal::daq::dump_output(to_json(v, tests), 2));
  print_volumetric(v, tests);
  if (!o.model_in.empty())
    fmt::print("\nwrote {} (the squareness of {} with the table's)\n", o.model_out, o.model_in);
}

void history(const SetOptions& o) {
  const auto reader = open_run_reader(o.db);  // either store (--db postgresql://...)
  const auto& store = *reader;
  const auto tests = tests_of(store, o);
  if (o.json) return fmt::print("{}\n", cal::daq::dump_output(history_json(tests), 2));
  print_history(tests);
}

void add_set_options(CLI::App& cmd, SetOptions& o) {
  add_read_db_option(cmd, o.db);
  cmd.add_option("--machine", o.machine, "The machine's ballbar tests (its complete circle runs)");
  cmd.add_option("--campaign", o.campaign, "Only this campaign's");
  cmd.add_option("--runs", o.runs, "These circle runs instead")->delimiter(',');
}

}  // namespace

void add_ballbar_commands(CLI::App& app) {
  auto* bb = add_group(app, "ballbar", "Ballbar calibrations (docs/circle.md)");
  const auto [cal, o] = add_command<CalibrateOptions>(
      *bb, "calibrate", calibrate,
      "Store a calibration of the bar against a calibrator: the bar reads 0 at the calibrator's "
      "length minus the reading");
  add_db_option(*cal, o->db);
  cal->add_option("--bar", o->bar, "The bar's identity (serial number), as [test.circle] bar")
      ->required();
  cal->add_option("--nominal-mm", o->values.nominal_mm,
                  "Nominal length of the bar with its extensions (the test radius)")
      ->required()
      ->check(finite_positive());
  cal->add_option("--calibrator-mm", o->values.calibrator_mm,
                  "The calibrator's certified length (Zerodur jig, known ring)")
      ->required()
      ->check(finite_positive());
  cal->add_option("--reading-mm", o->values.reading_mm, "The bar's reading in the calibrator, mm")
      ->required();
  cal->add_option("--calibrator", o->calibrator, "The calibrator's identity");
  cal->add_option("--extensions", o->extensions, "The extensions fitted, e.g. \"50 mm\"");
  cal->add_option("--temperature-degc", o->values.temperature_degc,
                  "Temperature at the calibration (recorded, not corrected for)");
  cal->add_option("--date", o->values.date, "When, YYYY-MM-DD[THH:MM[:SS]] UTC (default: now)");
  cal->add_option("--note", o->note, "Free text");
  cal->add_flag("--json", o->json, "Print caldaq.bar-calibration.v1");

  auto l = std::make_shared<std::pair<std::string, std::string>>();
  auto as_json = std::make_shared<bool>(false);
  auto* ls = bb->add_subcommand("calibrations", "The stored calibrations, oldest first");
  add_read_db_option(*ls, l->first);
  ls->add_option("--bar", l->second, "Only this bar's");
  ls->add_flag("--json", *as_json, "Print caldaq.bar-calibrations.v1");
  ls->callback([l, as_json] { list(l->first, l->second, *as_json); });

  const auto [vol, vo] = add_command<SetOptions>(
      *bb, "volumetric", volumetric,
      "The three-plane table: squareness XY, ZX, YZ as the model's E_C0Y, E_B0Z, E_A0Z and the "
      "axis scales, from a campaign's ballbar tests");
  add_set_options(*vol, *vo);
  vol->add_option("--model", vo->model_in, "A caldaq.model.v1 file to take the squareness");
  vol->add_option("--write-model", vo->model_out, "Where to write it with the table's squareness");
  vol->add_flag("--json", vo->json, "Print caldaq.ballbar-volumetric.v1");

  const auto [his, ho] = add_command<SetOptions>(
      *bb, "history", history,
      "A machine's ballbar tests over time, per plane, feed and radius, with verdicts");
  add_set_options(*his, *ho);
  his->add_flag("--json", ho->json, "Print caldaq.ballbar-history.v1");
}

}  // namespace daq
