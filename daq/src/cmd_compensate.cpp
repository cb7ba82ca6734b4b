// daq compensate: compensation tables for the controller from a measured run.
#include <fmt/format.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "cal/analysis/comp_table.hpp"
#include "cal/analysis/error.hpp"
#include "cal/analysis/iso230_2.hpp"
#include "cal/storage/store.hpp"
#include "cli_checks.hpp"
#include "commands.hpp"
#include "csv_table.hpp"
#include "database.hpp"
#include "measurement_csv.hpp"

namespace daq {
namespace {

namespace ct = cal::comptable;

struct CompensateOptions {
  std::string input, straightness, db, output;
  std::int64_t run = 0;
  std::string axis = "X", format = "csv", sign = "correction", units = "mm", outside = "refuse";
  double start_mm = 0, interval_mm = 0, resolution = 0.0001;
  int points = 0, axis_number = 1;
  bool bidirectional = false, incremental = false, remove_slope = false, json = false;
  CsvOptions csv;
};

std::vector<cal::iso230_2::Measurement> measurements(const CompensateOptions& o) {
  if (!o.input.empty()) return read_measurements(o.input, o.csv);
  cal::storage::Store store(database_path(o.db));
  std::vector<cal::iso230_2::Measurement> out;
  for (const auto& t : store.targets(o.run))
    out.push_back(
        {t.nominal_mm, t.run_number,
         t.direction == '+' ? cal::iso230_2::Direction::up : cal::iso230_2::Direction::down,
         t.deviation_um});
  if (out.empty()) throw cal::InputError(fmt::format("run {} has no captured targets", o.run));
  return out;
}

void run(const CompensateOptions& o) {
  if (o.input.empty() && o.run == 0 && o.straightness.empty())
    throw cal::InputError(
        "compensate: give --input MEAS.csv, --run RUN or --straightness FILE.csv");
  const ct::Spec spec{.axis = o.axis,
                      .start_mm = o.start_mm,
                      .interval_mm = o.interval_mm,
                      .points = o.points,
                      .bidirectional = o.bidirectional,
                      .incremental = o.incremental,
                      .sign = o.sign == "error" ? ct::Sign::error : ct::Sign::correction,
                      .units = ct::units_from_string(o.units),
                      .resolution = o.resolution,
                      .outside = o.outside == "hold" ? ct::Outside::hold : ct::Outside::refuse};
  ct::Table table;
  if (!o.straightness.empty()) {
    const auto csv = CsvTable::read(o.straightness, o.csv);
    csv.require({"position_mm", "deviation_um"});
    table =
        ct::cross(spec, csv.numbers("position_mm"), csv.numbers("deviation_um"), o.remove_slope);
  } else {
    const auto m = measurements(o);
    table = ct::positioning(spec, cal::iso230_2::target_stats(m));
  }
  std::string text;
  if (o.json) {
    nlohmann::json j{{"schema", "caldaq.comp-table.v1"},
                     {"axis", o.axis},
                     {"units", o.units},
                     {"sign", o.sign},
                     {"incremental", o.incremental},
                     {"position_mm", table.position_mm},
                     {"forward", table.forward}};
    if (o.bidirectional)
      j["reverse"] = table.reverse;
    else
      j["backlash"] = table.backlash;
    text = j.dump(2) + "\n";
  } else if (o.format == "csv") {
    text = ct::write_csv(table);
  } else if (o.format == "linuxcnc") {
    text = ct::write_linuxcnc(table);
  } else if (o.format == "siemens") {
    text = ct::write_siemens(table, o.axis_number);
  } else if (o.format == "isg") {
    text = ct::write_isg(table);
  } else {
    throw cal::InputError(
        fmt::format("format '{}' (expected csv, linuxcnc, siemens or isg)", o.format));
  }
  if (o.output.empty()) return fmt::print("{}", text);
  std::ofstream out(o.output);
  if (!(out << text)) throw cal::InputError(fmt::format("{}: cannot write", o.output));
}

}  // namespace

void add_compensate_commands(CLI::App& app, CLI::App& /*analyse*/) {
  auto o = std::make_shared<CompensateOptions>();
  auto* cmd =
      app.add_subcommand("compensate", "Compensation table for the controller from a measured run");
  cmd->add_option("-i,--input", o->input, "ISO 230-2 measurement CSV (see docs/cli.md)");
  cmd->add_option("--run", o->run, "A stored linear run instead of --input");
  add_db_option(*cmd, o->db);
  cmd->add_option("--straightness", o->straightness, "Cross compensation from a straightness CSV");
  cmd->add_option("--axis", o->axis, "Axis name")->capture_default_str();
  cmd->add_option("--axis-number", o->axis_number, "Siemens: the AXn number")
      ->capture_default_str();
  cmd->add_option("--start-mm", o->start_mm, "First grid point")->required();
  cmd->add_option("--interval-mm", o->interval_mm, "Grid interval")->required();
  cmd->add_option("--points", o->points, "Number of grid points")->required();
  cmd->add_flag("--bidirectional", o->bidirectional,
                "Separate forward and reverse tables (else one + backlash)");
  cmd->add_flag("--incremental", o->incremental, "Each value relative to the previous point");
  cmd->add_option("--sign", o->sign, "correction or error")
      ->capture_default_str()
      ->check(CLI::IsMember({"correction", "error"}));
  cmd->add_option("--units", o->units, "mm, um or inch")->capture_default_str();
  cmd->add_option("--resolution", o->resolution, "Rounding, in the units")->capture_default_str();
  cmd->add_option("--outside", o->outside,
                  "refuse or hold (grid points beyond the measured targets)")
      ->capture_default_str()
      ->check(CLI::IsMember({"refuse", "hold"}));
  cmd->add_flag("--remove-slope", o->remove_slope,
                "Cross compensation: remove the squareness (slope)");
  cmd->add_option("-f,--format", o->format, "csv, linuxcnc, siemens or isg")->capture_default_str();
  cmd->add_option("-o,--output", o->output, "Write to a file instead of stdout");
  add_decimal_comma_flag(*cmd, o->csv);
  cmd->add_flag("--json", o->json, "Print caldaq.comp-table.v1 JSON");
  cmd->callback([o] { run(*o); });
}

}  // namespace daq
