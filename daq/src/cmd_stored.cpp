// Analysis of stored runs: daq analyse RUN --standard ..., daq recompensate RUN ...
#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "cal/analysis/error.hpp"
#include "cal/analysis/iso230_2.hpp"
#include "cal/daq/env_stage.hpp"
#include "cal/drivers/instrument.hpp"
#include "cal/storage/store.hpp"
#include "circle_output.hpp"
#include "circle_run.hpp"
#include "commands.hpp"
#include "database.hpp"
#include "iso230_2_output.hpp"

namespace daq {
namespace {

namespace st = cal::storage;
using nlohmann::json;

st::RunRecord linear_run(const st::Store& store, std::int64_t id) {
  const auto r = store.run(id);
  if (!r)
    throw cal::InputError(fmt::format("{}: no run {} (see daq runs)", store.path().string(), id));
  if (r->kind != "linear")
    throw cal::InputError(
        fmt::format("run {} is a {} test; this needs a linear (ISO 230-2) run", id, r->kind));
  return *r;
}

struct AnalyseRunOptions {
  std::string db;
  std::int64_t run = 0;
  std::string standard = "iso230-2:2014";
  bool store = false;
  bool json = false;
  // Circle runs: what may be corrected after the fact.
  std::optional<double> calibrated_radius_mm, cyclic_period_mm;
  bool uncalibrated = false;
};

// A stored ballbar run again from its raw bar readings, with the analysis settings it was
// run with unless corrected here (the calibrated length of the bar, the cyclic period).
void analyse_circle_run(st::Store& store, const st::RunRecord& run, const AnalyseRunOptions& o) {
  const json settings = json::parse(run.settings_json, nullptr, false);
  if (settings.is_discarded() || !settings.contains("radius_mm"))
    throw cal::InputError(fmt::format("run {}: its circle settings are missing", o.run));
  auto [program, analysis] = circle_settings_from_json(settings);
  if (o.calibrated_radius_mm) analysis.calibrated_radius_mm = o.calibrated_radius_mm;
  if (o.cyclic_period_mm) analysis.cyclic_period_mm = o.cyclic_period_mm;
  if (o.uncalibrated) analysis.uncalibrated = true;
  std::vector<double> bar_mm;
  for (const auto& r : store.readings(o.run))
    if (r.quantity == static_cast<std::uint8_t>(cal::drivers::Quantity::length_m))
      bar_mm.push_back(r.value * 1e3);
  cal::circle::Result result;
  try {
    result = analyse_ballbar(program, analysis, bar_mm);
  } catch (const cal::InputError& e) {
    throw cal::InputError(
        fmt::format("run {} ({} bar readings stored): {}", o.run, bar_mm.size(), e.what()));
  }
  const auto j = circle_json(result, program.radius_mm, analysis.plane, program.feed_mm_per_min);
  if (o.store) store.add_result({.run_id = o.run, .standard = "ISO 230-4:2005", .json = j.dump()});
  if (o.json) return fmt::print("{}\n", j.dump(2));
  print_circle(result, program.radius_mm, analysis.plane, program.feed_mm_per_min);
}

void analyse_run(const AnalyseRunOptions& o) {
  // Only --store writes; without it the database is opened read-only.
  auto store = o.store ? st::Store(database_path(o.db)) : open_database_read_only(o.db);
  const auto run = store.run(o.run);
  if (run && run->kind == "circle") return analyse_circle_run(store, *run, o);
  linear_run(store, o.run);
  const auto targets = store.targets(o.run);
  if (targets.empty()) throw cal::InputError(fmt::format("run {} has no captured targets", o.run));
  const auto e = cal::iso230_2::evaluate(measurements(targets),
                                         cal::iso230_2::standard_from_string(o.standard));
  if (o.store)
    store.add_result(
        {.run_id = o.run, .standard = std::string(e.standard.title), .json = to_json(e).dump()});
  if (o.json) return fmt::print("{}\n", to_json(e).dump(2));
  print(e);
}

struct RecompensateOptions {
  std::string db;
  std::int64_t run = 0;
  std::optional<double> alpha_ppm_per_k;
  double material_offset_k = 0.0, air_temperature_offset_k = 0.0;
  double pressure_offset_pa = 0.0, humidity_offset_pct = 0.0;
  std::optional<std::string> equation;
  bool json = false;
};

// Re-runs the environmental compensation of every captured stop from the stored raw laser
// value and the stored (uncompensated) environment readings, with the corrections applied,
// then re-evaluates and stores the new targets and result. The raw data are not changed.
void recompensate(const RecompensateOptions& o) {
  st::Store store(database_path(o.db));
  const auto run = linear_run(store, o.run);
  json settings = json::parse(run.settings_json, nullptr, false);
  if (settings.is_discarded() || !settings.contains("environment"))
    throw cal::InputError(fmt::format("run {}: its stored settings lack the environment", o.run));
  const auto& env = settings["environment"];
  cal::daq::EnvironmentConfig cfg;
  cfg.equation = o.equation.value_or(env.value("equation", "ciddor"));
  cfg.expansion_ppm_per_k = o.alpha_ppm_per_k.value_or(env.value("expansion_ppm_per_k", 11.5));
  cfg.co2_umol_per_mol = env.value("co2_umol_per_mol", 450.0);
  cfg.wavelength_nm = env.value("wavelength_nm", 632.991);
  cfg.stale_after_s = 1e9;  // every stored sample counts; staleness was judged during the run
  const double datum_mm = settings.value("datum_mm", 0.0);

  // The environment as recorded, with the sensor corrections.
  const auto readings = store.readings(o.run);
  int material_sensors = 0;
  for (const auto& r : readings)
    if (static_cast<cal::drivers::Quantity>(r.quantity) ==
        cal::drivers::Quantity::material_temperature_degc)
      material_sensors = std::max(material_sensors, r.device - 1);
  cal::daq::EnvStage stage(cfg, std::max(material_sensors, 1));
  for (const auto& r : readings) {
    using Q = cal::drivers::Quantity;
    switch (static_cast<Q>(r.quantity)) {
      case Q::air_temperature_degc:
        stage.add_air(r.time_ns, cal::daq::AirQuantity::temperature_degc,
                      r.value + o.air_temperature_offset_k);
        break;
      case Q::air_pressure_pa:
        stage.add_air(r.time_ns, cal::daq::AirQuantity::pressure_pa,
                      r.value + o.pressure_offset_pa);
        break;
      case Q::air_humidity_pct:
        stage.add_air(r.time_ns, cal::daq::AirQuantity::humidity_pct,
                      r.value + o.humidity_offset_pct);
        break;
      case Q::material_temperature_degc:
        if (r.device >= 2)
          stage.add_material(r.time_ns, r.device - 2, r.value + o.material_offset_k);
        break;
      default:
        break;
    }
  }
  auto targets = store.targets(o.run);
  double max_change_um = 0.0;
  for (auto& t : targets) {
    const auto c = stage.compensate(t.time_ns, t.raw_m);
    const double deviation_um = (datum_mm + c.length_m * 1e3 - t.nominal_mm) * 1e3;
    max_change_um = std::max(max_change_um, std::abs(deviation_um - t.deviation_um));
    t.deviation_um = deviation_um;
    t.refractive_index = c.n;
    t.material_temperature_degc = c.material_degc;
  }
  store.replace_targets(o.run, targets);
  const auto standard =
      cal::iso230_2::standard_from_string(settings.value("standard", "iso230-2:2014"));
  const auto e = cal::iso230_2::evaluate(measurements(targets), standard);
  json doc = to_json(e);
  doc["recompensation"] = {{"equation", cfg.equation},
                           {"expansion_ppm_per_k", cfg.expansion_ppm_per_k},
                           {"material_offset_k", o.material_offset_k},
                           {"air_temperature_offset_k", o.air_temperature_offset_k},
                           {"pressure_offset_pa", o.pressure_offset_pa},
                           {"humidity_offset_pct", o.humidity_offset_pct},
                           {"max_change_um", max_change_um}};
  store.add_result({.run_id = o.run,
                    .standard = std::string(e.standard.title) + " (recompensated)",
                    .json = doc.dump()});
  if (o.json) return fmt::print("{}\n", doc.dump(2));
  fmt::print("run {}: {} stops recompensated (largest change {:.3f} um), result stored\n\n", o.run,
             targets.size(), max_change_um);
  print(e);
}

}  // namespace

void add_stored_run_commands(CLI::App& app, CLI::App& analyse) {
  auto a = std::make_shared<AnalyseRunOptions>();
  analyse.require_subcommand(0, 1);
  analyse.add_option("RUN", a->run, "A stored run to evaluate again (see daq runs)");
  add_db_option(analyse, a->db);
  analyse.add_option("-s,--standard", a->standard, "Standard for a stored run")
      ->capture_default_str();
  analyse.add_flag("--store", a->store, "Store the result with the run");
  analyse
      .add_option("--calibrated-radius-mm", a->calibrated_radius_mm,
                  "Circle runs: the bar's corrected calibrated length")
      ->check(CLI::PositiveNumber);
  analyse
      .add_option("--cyclic-period-mm", a->cyclic_period_mm,
                  "Circle runs: the cyclic-error period (default: as run, else searched)")
      ->check(CLI::PositiveNumber);
  analyse.add_flag("--uncalibrated", a->uncalibrated, "Circle runs: no radius error");
  analyse.add_flag("--json", a->json, "Print JSON (caldaq.iso230-2.v1 or caldaq.circle.v1)");
  analyse.callback([a, &analyse] {
    if (!analyse.get_subcommands().empty()) return;
    if (a->run <= 0)
      throw cal::InputError(
          "analyse: give a stored RUN number, or a subcommand (see daq analyse --help)");
    analyse_run(*a);
  });

  auto r = std::make_shared<RecompensateOptions>();
  auto* cmd = app.add_subcommand(
      "recompensate",
      "Recompute a stored linear run's compensation from its raw readings with corrected "
      "coefficients or sensor offsets, re-evaluate it and store the result");
  cmd->add_option("RUN", r->run, "Run number")->required();
  add_db_option(*cmd, r->db);
  cmd->add_option("--alpha-ppm", r->alpha_ppm_per_k, "Corrected expansion coefficient, ppm/K");
  cmd->add_option("--material-offset", r->material_offset_k,
                  "Add to every material temperature, K");
  cmd->add_option("--air-temperature-offset", r->air_temperature_offset_k,
                  "Add to the air temperature, K");
  cmd->add_option("--pressure-offset", r->pressure_offset_pa, "Add to the pressure, Pa");
  cmd->add_option("--humidity-offset", r->humidity_offset_pct, "Add to the humidity, %RH");
  cmd->add_option("--equation", r->equation, "ciddor, edlen or shop-floor");
  cmd->add_flag("--json", r->json, "Print the result JSON");
  cmd->callback([r] { recompensate(*r); });
}

}  // namespace daq
