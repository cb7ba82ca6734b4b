// daq analyse iso230-2, daq targets, daq uncertainty.
#include <fmt/format.h>

#include <memory>
#include <optional>
#include <string>

#include "cal/analysis/iso230_2.hpp"
#include "cal/analysis/iso230_2_targets.hpp"
#include "cal/analysis/uncertainty.hpp"
#include "cli_checks.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "iso230_2_output.hpp"
#include "measurement_csv.hpp"

namespace daq {
namespace {

struct AnalyseOptions {
  std::string input;
  std::string standard = "iso230-2:2014";
  CsvOptions csv;
  bool json = false;
};

void run_analyse(const AnalyseOptions& o) {
  const auto standard = cal::iso230_2::standard_from_string(o.standard);
  const auto data = read_measurements(o.input, o.csv);
  const auto e = cal::iso230_2::evaluate(data, standard);
  if (o.json) {
    auto j = to_json(e);
    j["input"] = o.input;
    fmt::print("{}\n", j.dump(2));
  } else {
    fmt::print("{}: {} measurements\n", o.input, data.size());
    print(e);
  }
}

std::string standards_help() {
  std::string s = "Standard and edition: iso230-2 (= iso230-2:2014)";
  for (const auto& i : cal::iso230_2::standards()) s += ", " + std::string(i.key);
  return s;
}

struct PlanOptions {
  cal::iso230_2::TargetSpec targets;
  cal::iso230_2::CycleSpec cycle;
  std::optional<double> interval_mm;
  std::optional<int> count;
  std::string cycle_name = "linear";
  bool unidirectional = false;
  bool json = false;
};

void run_plan(PlanOptions o) {
  o.targets.interval_mm = o.interval_mm;
  o.targets.count = o.count;
  o.cycle.cycle = cal::iso230_2::cycle_from_string(o.cycle_name);
  o.cycle.bidirectional = !o.unidirectional;
  const auto plan = cal::iso230_2::make_plan(o.targets, o.cycle);
  if (o.json) {
    fmt::print("{}\n", to_json(plan).dump(2));
    return;
  }
  fmt::print("{} targets (mm):", plan.targets_mm.size());
  for (double t : plan.targets_mm) fmt::print(" {:.3f}", t);
  fmt::print("\n{} moves, {} cycle, {} runs per direction\n\n", plan.moves.size(),
             cal::iso230_2::to_string(o.cycle.cycle), o.cycle.runs);
  fmt::print("{:>5} {:<10} {:>4} {:<5} {:>6} {:>12}\n", "#", "kind", "run", "dir", "target",
             "position/mm");
  int k = 0;
  for (const auto& m : plan.moves) {
    const char* kind = m.kind == cal::iso230_2::MoveKind::measure   ? "measure"
                       : m.kind == cal::iso230_2::MoveKind::overrun ? "overrun"
                                                                    : "reposition";
    fmt::print("{:>5} {:<10} {:>4} {:<5} {:>6} {:>12.3f}\n", ++k, kind, m.run,
               cal::iso230_2::to_string(m.direction),
               m.target_index ? std::to_string(m.target_index) : "-", m.position_mm);
  }
  for (const auto& w : plan.warnings) fmt::print("warning: {}\n", w);
  for (const auto& n : plan.notes) fmt::print("note: {}\n", n);
}

struct UncOptions {
  cal::unc::PositioningSetup s;
  double pressure_hpa = 1013.25;
  double rh_pct = 50.0;
  double alpha_ppm = 11.5, u_alpha_ppm = 1.0;
  std::string equation = "ciddor";
  bool not_corrected = false;
  bool json = false;
};

void run_uncertainty(UncOptions o) {
  o.s.air.pressure_pa = o.pressure_hpa * 100.0;
  o.s.air.humidity = cal::air::Humidity::relative_pct(o.rh_pct);
  o.s.alpha_per_k = o.alpha_ppm * 1e-6;
  o.s.u_alpha_per_k = o.u_alpha_ppm * 1e-6;
  o.s.equation = cal::air::equation_from_string(o.equation);
  o.s.dead_path_corrected = !o.not_corrected;
  const auto b = cal::unc::positioning_budget(o.s);
  if (o.json) {
    auto j = to_json(b);
    j["schema"] = "caldaq.uncertainty.v1";
    j["length_m"] = o.s.length_m;
    fmt::print("{}\n", j.dump(2));
  } else {
    print(b, o.s.length_m);
  }
}

void add_analyse(CLI::App& analyse) {
  const auto [cmd, o] = add_command<AnalyseOptions>(
      analyse, "iso230-2", run_analyse,
      "Positioning test: ISO 230-2 (all editions), VDI/DGQ 3441, JIS, GB/T");
  cmd->add_option("-i,--input", o->input,
                  "CSV with columns target_mm,run,direction,deviation_um (docs/cli.md)")
      ->required();
  cmd->add_option("-s,--standard", o->standard, standards_help())->capture_default_str();
  add_decimal_comma_flag(*cmd, o->csv);
  cmd->add_flag("--json", o->json, "Print JSON (schema caldaq.iso230-2.v1)");
}

void add_targets(CLI::App& app) {
  const auto [cmd, o] = add_command<PlanOptions>(app, "targets", run_plan,
                                                 "ISO 230-2 targets and the ordered test moves");
  cmd->add_option("--first", o->targets.first_mm, "First target, mm")->required();
  cmd->add_option("--last", o->targets.last_mm, "Last target, mm")->required();
  auto* iv = cmd->add_option("--interval", o->interval_mm, "Nominal target interval, mm");
  cmd->add_option("--count", o->count, "Number of targets (instead of --interval)")->excludes(iv);
  cmd->add_option("--random-fraction", o->targets.random_fraction,
                  "Random offset of inner targets, fraction of the interval (0 .. <0.5)")
      ->capture_default_str();
  cmd->add_option("--seed", o->targets.seed, "Seed of the random offsets")->capture_default_str();
  cmd->add_option("--round", o->targets.round_to_mm, "Round targets to this step, mm")
      ->capture_default_str();
  cmd->add_option("--cycle", o->cycle_name, "linear | pendulum | pilgrim-step")
      ->capture_default_str();
  cmd->add_option("--runs", o->cycle.runs, "Runs per direction")->capture_default_str();
  cmd->add_option("--overrun", o->cycle.overrun_mm, "Over-run beyond the targets, mm")
      ->capture_default_str();
  cmd->add_flag("--unidirectional", o->unidirectional, "Approach every target from below only");
  cmd->add_flag("--json", o->json, "Print JSON (schema caldaq.plan.v1)");
}

void add_uncertainty(CLI::App& app) {
  const auto [cmd, o] =
      add_command<UncOptions>(app, "uncertainty", run_uncertainty,
                              "Uncertainty budget of a laser positioning test (U, k = 2)");
  auto& s = o->s;
  cmd->add_option("-L,--length-m", s.length_m, "Measured travel, m")->capture_default_str();
  cmd->add_option("--laser-ppm", s.laser_cert_expanded_ppm, "Laser certificate U, ppm")
      ->capture_default_str();
  cmd->add_option("--laser-um", s.laser_cert_expanded_um, "Laser certificate U, constant part, um")
      ->capture_default_str();
  cmd->add_option("--laser-k", s.laser_cert_k, "Coverage factor of the certificate")
      ->capture_default_str();
  cmd->add_option("-t,--temperature", s.air.temperature_degc, "Air temperature, degC")
      ->capture_default_str();
  cmd->add_option("-p,--pressure-hpa", o->pressure_hpa, "Air pressure, hPa")->capture_default_str();
  cmd->add_option("-r,--rh", o->rh_pct, "Relative humidity, %")->capture_default_str();
  cmd->add_option("-e,--equation", o->equation, "edlen | ciddor | shop-floor")
      ->capture_default_str();
  cmd->add_option("--u-air-temp", s.u_air_temperature_k, "u(air temperature), K")
      ->capture_default_str();
  cmd->add_option("--u-pressure-pa", s.u_pressure_pa, "u(pressure), Pa")->capture_default_str();
  cmd->add_option("--u-rh", s.u_humidity_pct, "u(relative humidity), %")->capture_default_str();
  cmd->add_option("-m,--material-temp", s.material_degc, "Material temperature, degC")
      ->capture_default_str();
  cmd->add_option("--u-material-temp", s.u_material_temperature_k, "u(material temperature), K")
      ->capture_default_str();
  cmd->add_option("-a,--alpha-ppm", o->alpha_ppm, "Expansion coefficient, ppm/K")
      ->capture_default_str();
  cmd->add_option("--u-alpha-ppm", o->u_alpha_ppm, "u(expansion coefficient), ppm/K")
      ->capture_default_str();
  cmd->add_option("--drift-um", s.environmental_variation_um,
                  "Environmental variation error E_VE from a drift test, um")
      ->capture_default_str();
  cmd->add_option("--misalignment-mm", s.misalignment_offset_mm,
                  "Lateral beam offset between the ends of the travel, mm")
      ->capture_default_str();
  cmd->add_option("--dead-path-m", s.dead_path_m, "Dead path, m")->capture_default_str();
  cmd->add_flag("--dead-path-not-corrected", o->not_corrected,
                "The readings were not dead-path corrected");
  cmd->add_option("--index-change", s.index_change_during_test,
                  "|Δn| during the test (for an uncorrected dead path)")
      ->capture_default_str();
  cmd->add_flag("--json", o->json, "Print JSON (schema caldaq.uncertainty.v1)");
}

}  // namespace

void add_iso230_2_commands(CLI::App& app, CLI::App& analyse) {
  add_analyse(analyse);
  add_targets(app);
  add_uncertainty(app);
}

}  // namespace daq
