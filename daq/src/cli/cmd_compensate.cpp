// daq compensate: compensation tables for the controller from a measured run.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>

#include "cal/analysis/comp_formats.hpp"
#include "cal/analysis/comp_meaning.hpp"
#include "cal/analysis/comp_read.hpp"
#include "cal/analysis/comp_table.hpp"
#include "cal/analysis/error.hpp"
#include "cal/analysis/fixed_text.hpp"
#include "cal/analysis/iso230_2.hpp"
#include "cal/storage/store.hpp"
#include "cli_checks.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "compensate_run.hpp"
#include "compensation/compensation_check.hpp"
#include "csv_columns.hpp"
#include "database.hpp"
#include "measurement_csv.hpp"
#include "provenance.hpp"
#include "run_quality.hpp"

namespace daq {
namespace {

namespace ct = cal::comptable;

struct CompensateOptions {
  std::string input, straightness, db, output, output_axis;
  std::int64_t run = 0;
  std::vector<std::int64_t> accept_suspect;  // suspect runs used knowingly (run_quality.hpp)
  std::vector<std::int64_t> accepted;        // ... of which --run is one: said in the output
  std::string origin_label, origin_text;     // --run not measured on real instruments: said
  std::string axis = "X", format = "csv", units = "mm", outside = "refuse";
  std::optional<std::string> sign;  // csv and --json only: the other formats' sign is the vendor's
  double start_mm = 0, interval_mm = 0;
  std::optional<double> resolution;  // unset: by unit (default_resolution)
  int points = 0, axis_number = 1, output_axis_number = 2;
  bool bidirectional = false, incremental = false, remove_slope = false, json = false;
  bool straightness_run = false;  // --run is a straightness run: a cross-axis table
  CsvOptions csv;
  ct::FanucOptions fanuc;
  std::optional<double> fanuc_reference_mm;  // default: --start-mm
};

std::vector<double> spec_positions(const ct::CrossAxisTable& t) {
  std::vector<double> p;
  for (std::size_t i = 0; i < t.correction_mm.size(); ++i) p.push_back(t.position_mm(i));
  return p;
}

// The stops of --run, refused when it is suspect and not accepted; its origin noted.
std::vector<cal::iso230_2::Measurement> run_measurements(CompensateOptions& o,
                                                         const cal::storage::RunReader& store) {
  const std::int64_t runs[] = {o.run};
  o.accepted = refuse_suspect_runs(store, runs, o.accept_suspect, "daq compensate");
  if (const auto run = store.run(o.run)) {
    const auto origin = run_origin(*run, store.instruments(o.run), "");
    o.origin_label = origin.label();
    o.origin_text = origin.text;
  }
  std::vector<cal::iso230_2::Measurement> out;
  for (const auto& t : store.targets(o.run))
    out.push_back(
        {t.nominal_mm, t.run_number,
         t.direction == '+' ? cal::iso230_2::Direction::up : cal::iso230_2::Direction::down,
         t.deviation_um});
  if (out.empty()) throw cal::InputError(fmt::format("run {} has no captured targets", o.run));
  return out;
}

std::vector<cal::iso230_2::Measurement> measurements(CompensateOptions& o) {
  if (!o.input.empty()) return read_measurements(o.input, o.csv);
  return run_measurements(o, open_database_read_only(o.db));
}

// A straightness run is the error of another axis (--output-axis) along --axis: its correction
// belongs in a cross-axis table of the output axis, never in --axis's own pitch table (which
// corrects --axis along itself: the wrong axis).
ct::CrossAxisTable straightness_table(const CompensateOptions& o, const ct::Spec& spec,
                                      std::span<const double> position_mm,
                                      std::span<const double> deviation_um) {
  if (o.output_axis.empty())
    throw cal::InputError(
        "--straightness: name the corrected axis with --output-axis (the straightness of --axis "
        "measured in that axis, e.g. --axis X --output-axis Y for E_YX)");
  if (o.units != "mm" || o.incremental || o.sign)
    throw cal::InputError(
        "--straightness writes absolute corrections in mm: no --units, --incremental or --sign");
  return ct::from_straightness(o.axis, o.output_axis, spec, position_mm, deviation_um,
                               o.remove_slope);
}

std::string straightness_text(const CompensateOptions& o, const ct::CrossAxisTable& t) {
  const std::vector<ct::CrossAxisTable> one{t};
  if (o.json)
    return nlohmann::json{{"schema", "caldaq.cross-table.v1"},
                          {"input_axis", t.input},
                          {"output_axis", t.output},
                          {"units", "mm"},
                          {"sign", "correction"},
                          {"position_mm", spec_positions(t)},
                          {"correction", t.correction_mm}}
               .dump(2) +
           "\n";
  if (o.format == "csv") return ct::write_cross_csv(one);
  if (o.format == "siemens-cec")
    return ct::write_sinumerik_cec(
        one, {{o.axis, o.axis_number}, {o.output_axis, o.output_axis_number}});
  if (o.format == "isg") return ct::write_isg_cross(t, o.output_axis_number, o.axis_number);
  if (o.format == "heidenhain") return ct::write_heidenhain_com(one);
  throw cal::InputError(
      fmt::format("format '{}' cannot hold a straightness: it corrects an axis along itself, and a "
                  "straightness "
                  "of {} corrects {} (use csv, siemens-cec, isg or heidenhain{})",
                  o.format, o.axis, o.output_axis,
                  o.format == "linuxcnc" ? "; LinuxCNC documents no cross-axis table" : ""));
}

std::string straightness_csv_text(const CompensateOptions& o, const ct::Spec& spec) {
  const auto csv = read_csv_columns(o.straightness, {"position_mm", "deviation_um"}, {}, o.csv);
  return straightness_text(o, straightness_table(o, spec, csv.numbers.at("position_mm"),
                                                 csv.numbers.at("deviation_um")));
}

// A stored straightness run (--run): the mean of each target's stops is the straightness the
// cross-axis table corrects (the run's axis and the direction it was read in unless given).
struct StraightnessRun {
  std::int64_t machine_id = 0;
  std::vector<double> position_mm, deviation_um;
};
StraightnessRun straightness_of_run(CompensateOptions& o, const cal::storage::Store& store,
                                    const cal::storage::RunRecord& run) {
  const auto settings = nlohmann::json::parse(run.settings_json, nullptr, false);
  const std::string direction =
      settings.is_object()
          ? settings.value("measure", nlohmann::json::object()).value("direction", "")
          : "";
  o.axis = run.axis;
  if (o.output_axis.empty()) o.output_axis = direction;
  if (o.output_axis != direction)
    throw cal::InputError(fmt::format("run {} is the straightness of {} read in {}, not in {}",
                                      run.id, run.axis, direction, o.output_axis));
  StraightnessRun s{.machine_id = run.machine_id};
  for (const auto& t : cal::iso230_2::target_stats(run_measurements(o, store), 1)) {
    s.position_mm.push_back(t.target_mm);
    s.deviation_um.push_back(t.runs_up && t.runs_down ? t.mean_bi_um
                             : t.runs_up              ? t.mean_up_um
                                                      : t.mean_down_um);
  }
  return s;
}

// The cross-axis table of a stored straightness run, stored with the run's machine so that the
// next straightness run of the axis is compared with it (daq verify RUN).
std::string straightness_run_text(CompensateOptions& o, const ct::Spec& spec,
                                  const cal::storage::RunRecord& run) {
  o.straightness_run = true;
  const auto store = open_database_read_only(o.db);
  const auto s = straightness_of_run(o, store, run);
  const auto t = straightness_table(o, spec, s.position_mm, s.deviation_um);
  const std::string text = straightness_text(o, t);
  if (o.json) return text;
  const std::string format = o.format == "isg" ? "isg-cross" : o.format;
  try {
    cal::storage::Store rw(database_path(o.db));
    CrossCompensation c{.format = format, .files = {{"", text}}, .file = o.output};
    if (format == "heidenhain") {
      // The *.COM's input axis is in the control's *.CMA: stored with the assignment it needs
      // (the table in the column of this axis), which the output names.
      const std::string name = o.output.empty()
                                   ? fmt::format("{}.COM", o.axis)
                                   : std::filesystem::path(o.output).filename().string();
      c.files = {{name, text}, {"config.cma", ct::write_heidenhain_cma({{o.axis, name}})}};
      fmt::print(stderr,
                 "HEIDENHAIN: enter {} in the column {} of the active row of the control's "
                 "*.CMA ({} = F({})); stored with that assignment\n",
                 name, o.axis, o.output_axis, o.axis);
    }
    c.axis_numbers = {{o.axis, o.axis_number}, {o.output_axis, o.output_axis_number}};
    const auto id = store_cross_compensation(rw, s.machine_id, o.run, fmt::format("run {}", o.run),
                                             c, {{"label", o.origin_label}});
    fmt::print(stderr,
               "stored as compensation {}: the next straightness run of {} in {} on this machine "
               "is compared with it (daq verify RUN)\n",
               id, o.axis, o.output_axis);
  } catch (const std::exception& e) {
    fmt::print(stderr,
               "note: the compensation was not stored with run {} ({}); daq verify will "
               "not find it\n",
               o.run, e.what());
  }
  return text;
}

TableWriter writer_of(const CompensateOptions& o) {
  TableWriter w{.format = o.format, .axis_number = o.axis_number, .fanuc = o.fanuc};
  w.fanuc.reference_mm = o.fanuc_reference_mm.value_or(o.start_mm);
  return w;
}

// A table from a suspect run used as told (--accept-suspect), or from a run not measured on
// real instruments, says so in its header.
std::string suspect_note(const CompensateOptions& o, std::string_view comment) {
  std::string out;
  for (const auto& line :
       table_origin_lines(o.origin_label,
                          fmt::format("from run {}, not a measurement of a real machine ({})",
                                      o.run, o.origin_text),
                          {}))
    out += fmt::format("{}{}\n", comment, line);
  for (const auto id : o.accepted)
    out += fmt::format(
        "{}SUSPECT run {}: a stop far outside its repeatability, used as told "
        "(--accept-suspect)\n",
        comment, id);
  return out;
}

std::string positioning_text(const CompensateOptions& o, const ct::Table& table) {
  if (o.json) {
    nlohmann::json j{{"schema", "caldaq.comp-table.v1"},
                     {"axis", o.axis},
                     {"units", o.units},
                     {"sign", table.spec.sign == ct::Sign::error ? "error" : "correction"},
                     {"incremental", o.incremental},
                     {"position_mm", table.position_mm},
                     {"forward", table.forward}};
    if (o.bidirectional)
      j["reverse"] = table.reverse;
    else
      j["backlash"] = table.backlash;
    if (!o.accepted.empty()) j["accepted_suspect_runs"] = o.accepted;
    if (!o.origin_label.empty()) j["origin"] = o.origin_label;
    return j.dump(2) + "\n";
  }
  // A table from a suspect run used as told says so in its header, where the format has comments
  // (LinuxCNC and HEIDENHAIN tables have none: the command's output says it).
  const std::string text = write_table(writer_of(o), table);
  if (o.format == "csv" || o.format == "isg") return suspect_note(o, "# ") + text;
  if (o.format == "siemens") return suspect_note(o, "; ") + text;
  if (o.format == "fanuc") return suspect_note(o, "") + text;
  return text;
}

// A resolution that suits each unit when none is given: 0.1 um in mm or um tables, 0.00001 in
// (0.254 um) in inch tables (a rounding of 0.0001 in would be 2.54 um).
double default_resolution(const std::string& units) {
  const auto u = ct::units_from_string(units);
  return u == ct::Units::inch ? 0.00001 : u == ct::Units::um ? 0.1 : 0.0001;
}

// The meaning of the chosen format's values (comp_meaning.hpp): -f isg with --straightness is
// ISG's cross compensation.
const ct::FormatMeaning& meaning_of(const CompensateOptions& o) {
  if (o.format == "isg" && (!o.straightness.empty() || o.straightness_run))
    return ct::format_meaning("isg-cross");
  return ct::format_meaning(o.format);
}

// The sign of the table: the vendor's for a controller format; the user's (default
// correction) only for caldaq's own CSV and JSON.
ct::Sign table_sign(const CompensateOptions& o) {
  if (o.format == "csv" || o.json)
    return o.sign.value_or("correction") == "error" ? ct::Sign::error : ct::Sign::correction;
  const auto& m = meaning_of(o);
  if (o.sign)
    throw cal::InputError(fmt::format(
        "--sign is for csv and --json only: the values of {} are {} by the vendor's own rule, "
        "which caldaq follows ({}; docs/compensation-tables.md)",
        m.name, m.written == ct::Sign::error ? "the measured errors" : "corrections", m.source));
  return m.written;
}

nlohmann::json predicted_json(const ct::PredictedResidual& p) {
  return {{"target_mm", p.target_mm},
          {"before_up_um", p.before_up_um},
          {"before_down_um", p.before_down_um},
          {"up_um", p.up_um},
          {"down_um", p.down_um},
          {"before_max_um", p.before_max_um},
          {"after_max_um", p.after_max_um}};
}

// Kept with the run (schema 5) so that the next measurement of the axis can be compared with
// what this table was predicted to leave (daq verify): the stored compensation's id. Throws
// what the store throws (a read-only medium, no such run).
std::int64_t store_compensation_record(const CompensateOptions& o, const ct::Table& t,
                                       const ct::Applied& a, const ct::PredictedResidual& p,
                                       const std::string& text) {
  cal::storage::Store store(database_path(o.db));
  {
    const auto run = store.run(o.run);
    if (!run) throw cal::InputError(fmt::format("no run {}", o.run));
    const auto origin = run_origin(*run, store.instruments(o.run), "");  // said by suspect_note
    const auto& m = meaning_of(o);
    const nlohmann::json doc{{"schema", "caldaq.compensation.v1"},
                             {"format", o.format},
                             // The file written (empty: stdout), named by daq report --verify.
                             {"file", o.output},
                             {"writer", to_json(writer_of(o))},
                             {"meaning",
                              {{"values", m.written == ct::Sign::error ? "error" : "correction"},
                               {"evidence", ct::to_string(m.evidence)},
                               {"source", m.source}}},
                             {"table",
                              {{"units", ct::units_name(t.spec.units)},
                               {"position_mm", t.position_mm},
                               {"forward", t.forward},
                               {"reverse", t.reverse},
                               {"backlash", t.backlash}}},
                             {"applied",
                              {{"position_mm", a.position_mm},
                               {"forward_um", a.forward_um},
                               {"reverse_um", a.reverse_um}}},
                             {"predicted", predicted_json(p)},
                             {"origin", to_json(origin)},
                             {"accepted_suspect_runs", o.accepted},
                             {"text", text}};
    return store.add_compensation({.machine_id = run->machine_id,
                                   .source_run_id = o.run,
                                   .source = fmt::format("run {}", o.run),
                                   .axis = o.axis,
                                   .format = o.format,
                                   .json = doc.dump()});
  }
}

// The command's: a store that cannot be written (a read-only medium) is said, not fatal: the
// table is still written.
void store_compensation(const CompensateOptions& o, const ct::Table& t, const ct::Applied& a,
                        const ct::PredictedResidual& p, const std::string& text) {
  try {
    const auto id = store_compensation_record(o, t, a, p, text);
    fmt::print(stderr,
               "stored as compensation {}: the next run of axis {} on this machine is compared "
               "with its prediction (daq verify RUN)\n",
               id, o.axis);
  } catch (const std::exception& e) {
    fmt::print(stderr,
               "note: the compensation was not stored with run {} ({}); daq verify will "
               "not find it\n",
               o.run, e.what());
  }
}

ct::Spec spec_of(const CompensateOptions& o) {
  return {.axis = o.axis,
          .start_mm = o.start_mm,
          .interval_mm = o.interval_mm,
          .points = o.points,
          .bidirectional = o.bidirectional,
          .incremental = o.incremental,
          .sign = table_sign(o),
          .units = ct::units_from_string(o.units),
          .resolution = o.resolution.value_or(default_resolution(o.units)),
          .outside = o.outside == "hold" ? ct::Outside::hold : ct::Outside::refuse};
}

void run(CompensateOptions& o) {
  if (o.input.empty() && o.run == 0 && o.straightness.empty())
    throw cal::InputError(
        "compensate: give --input MEAS.csv, --run RUN or --straightness FILE.csv");
  const ct::Spec spec = spec_of(o);
  std::string text;
  std::optional<ct::PredictedResidual> predicted;
  const auto stored = o.run != 0 && o.input.empty() ? open_database_read_only(o.db).run(o.run)
                                                    : std::optional<cal::storage::RunRecord>{};
  if (!o.straightness.empty()) {
    text = straightness_csv_text(o, spec);
  } else if (stored && stored->kind == "straightness") {
    text = straightness_run_text(o, spec, *stored);
  } else {
    const auto m = measurements(o);
    const auto stats = cal::iso230_2::target_stats(m);
    const auto table = ct::positioning(spec, stats);
    text = positioning_text(o, table);
    const auto a = applied_of(writer_of(o), table);
    predicted = ct::predict(a, stats);
    if (o.run != 0 && !o.json) store_compensation(o, table, a, *predicted, text);
  }
  // Said here too unless the table with its header goes to the terminal.
  if ((!o.accepted.empty() || !o.origin_label.empty()) &&
      (o.format != "csv" || !o.output.empty()) && !o.json)
    fmt::print(stderr, "{}", suspect_note(o, "note: "));
  if (o.output.empty())
    fmt::print("{}", text);
  else if (std::ofstream out(o.output); !(out << text))
    throw cal::InputError(fmt::format("{}: cannot write", o.output));
  if (o.json) return;
  if (!o.output.empty()) fmt::print(stderr, "written {}\n", o.output);
  fmt::print(stderr, "{}\n", ct::meaning_text(meaning_of(o)));
  if (predicted)
    fmt::print(stderr,
               "predicted: largest |mean deviation| {} um before, {} um left by this table as "
               "written (its rounding, sign and reference applied to the measured means)\n",
               cal::fixed_text(predicted->before_max_um, 3),
               cal::fixed_text(predicted->after_max_um, 3));
}

}  // namespace

nlohmann::json run_compensation(const cal::storage::Store& store, std::int64_t run,
                                const std::string& format, const std::string* store_in) {
  CompensateOptions o;
  o.run = run;
  o.format = format;
  if (store_in) o.db = *store_in;
  const auto record = store.run(run);
  if (!record) throw cal::InputError(fmt::format("no run {}", run));
  if (record->kind != "linear")
    throw cal::InputError(fmt::format(
        "run {} is a {} test: a compensation table is made from a linear one", run, record->kind));
  o.axis = record->axis;
  meaning_of(o);  // an unknown format is refused before anything is read
  const auto m = run_measurements(o, store);
  // The run's own grid: its first target, its spacing, its number of targets.
  std::vector<double> nominal;
  for (const auto& x : m) nominal.push_back(x.target_mm);
  std::sort(nominal.begin(), nominal.end());
  nominal.erase(std::unique(nominal.begin(), nominal.end()), nominal.end());
  if (nominal.size() < 2)
    throw cal::InputError(fmt::format("run {} has fewer than 2 targets: no table", run));
  o.start_mm = nominal.front();
  o.points = static_cast<int>(nominal.size());
  o.interval_mm = (nominal.back() - nominal.front()) / (o.points - 1);
  const auto stats = cal::iso230_2::target_stats(m);
  const auto table = ct::positioning(spec_of(o), stats);
  const auto text = positioning_text(o, table);
  const auto applied = applied_of(writer_of(o), table);
  const auto predicted = ct::predict(applied, stats);
  const auto& meaning = meaning_of(o);
  // Stored as `daq compensate --run` stores it (the same record), for daq verify.
  nlohmann::json stored = nullptr;
  if (store_in) stored = {{"id", store_compensation_record(o, table, applied, predicted, text)}};
  return {{"schema", "caldaq.run-compensation.v1"},
          {"stored", stored},
          {"run", run},
          {"axis", o.axis},
          {"format", o.format},
          {"command", fmt::format("daq compensate --run {} --axis {} --start-mm {} --interval-mm "
                                  "{} --points {} -f {}",
                                  run, o.axis, o.start_mm, o.interval_mm, o.points, o.format)},
          {"meaning", ct::meaning_text(meaning)},
          {"values", table.spec.sign == ct::Sign::error ? "error" : "correction"},
          {"units", ct::units_name(table.spec.units)},
          {"position_mm", table.position_mm},
          {"forward", table.forward},
          {"backlash", table.backlash},
          {"predicted", predicted_json(predicted)},
          {"origin", o.origin_label},
          {"text", text}};
}

void add_compensate_commands(CLI::App& app, CLI::App& /*analyse*/) {
  const auto [cmd, o] = add_command<CompensateOptions>(
      app, "compensate", run, "Compensation table for the controller from a measured run");
  cmd->add_option("-i,--input", o->input, "ISO 230-2 measurement CSV (see docs/cli.md)");
  cmd->add_option("--run", o->run, "A stored linear run instead of --input");
  cmd->add_option("--accept-suspect", o->accept_suspect,
                  "Use --run although it is suspect (a stop far outside its repeatability; "
                  "refused otherwise); said in the table's header")
      ->take_all();
  add_db_option(*cmd, o->db);
  cmd->add_option("--straightness", o->straightness,
                  "Cross compensation from a straightness CSV (position_mm, deviation_um)");
  cmd->add_option("--output-axis", o->output_axis,
                  "--straightness: the axis the straightness is measured in, which is corrected");
  cmd->add_option("--output-axis-number", o->output_axis_number,
                  "siemens-cec, isg: the number of --output-axis")
      ->capture_default_str();
  cmd->add_option("--axis", o->axis, "Axis name")->capture_default_str();
  cmd->add_option("--axis-number", o->axis_number, "Siemens: the AXn number")
      ->capture_default_str();
  cmd->add_option("--start-mm", o->start_mm, "First grid point")->required();
  cmd->add_option("--interval-mm", o->interval_mm, "Grid interval")->required();
  cmd->add_option("--points", o->points, "Number of grid points")->required();
  cmd->add_flag("--bidirectional", o->bidirectional,
                "Separate forward and reverse tables (else one + backlash)");
  cmd->add_flag("--incremental", o->incremental, "Each value relative to the previous point");
  cmd->add_option("--sign", o->sign,
                  "csv and --json only: correction (default) or error; every controller format "
                  "has its vendor's sign (docs/compensation-tables.md)")
      ->check(CLI::IsMember({"correction", "error"}));
  cmd->add_option("--units", o->units, "mm, um or inch")->capture_default_str();
  cmd->add_option("--resolution", o->resolution,
                  "Rounding, in the units (default 0.0001 mm, 0.1 um, 0.00001 inch)");
  cmd->add_option("--outside", o->outside,
                  "refuse or hold (grid points beyond the measured targets)")
      ->capture_default_str()
      ->check(CLI::IsMember({"refuse", "hold"}));
  cmd->add_flag("--remove-slope", o->remove_slope,
                "Cross compensation: remove the squareness (slope)");
  cmd->add_option("-f,--format", o->format,
                  "csv, linuxcnc, siemens, isg, heidenhain, fanuc; with --straightness: csv, "
                  "siemens-cec, isg, heidenhain")
      ->capture_default_str();
  cmd->add_option("--fanuc-reference-mm", o->fanuc_reference_mm,
                  "fanuc: the reference position, a grid point (default --start-mm)");
  cmd->add_option("--fanuc-first-point", o->fanuc.first_point, "fanuc: number of the first point")
      ->capture_default_str();
  cmd->add_option("--fanuc-unit-um", o->fanuc.detection_unit_um, "fanuc: the detection unit")
      ->capture_default_str();
  cmd->add_option("--fanuc-magnification", o->fanuc.magnification, "fanuc: parameter 3623")
      ->capture_default_str();
  cmd->add_option("-o,--output", o->output, "Write to a file instead of stdout");
  add_decimal_comma_flag(*cmd, o->csv);
  cmd->add_flag("--json", o->json,
                "Print caldaq.comp-table.v1 JSON (caldaq.cross-table.v1 with --straightness)");
}

}  // namespace daq
