// Analysis of stored runs: daq analyse RUN --standard ..., daq recompensate RUN ...
#include <fmt/format.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>

#include "cal/analysis/error.hpp"
#include "cal/analysis/iso230_2.hpp"
#include "cal/daq/env_stage.hpp"
#include "cal/drivers/instrument.hpp"
#include "cal/storage/store.hpp"
#include "circle_output.hpp"
#include "circle_run.hpp"
#include "cli_checks.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "database.hpp"
#include "iso230_2_output.hpp"
#include "json_input.hpp"
#include "provenance.hpp"
#include "result_rows.hpp"
#include "roles.hpp"
#include "run_quality.hpp"
#include "run_version.hpp"
#include "stored_profile.hpp"
#include "terminal.hpp"
#include "verdict.hpp"

namespace daq {
namespace {

namespace st = cal::storage;
using nlohmann::json;

st::RunRecord linear_run(const st::RunReader& store, std::int64_t id) {
  const auto r = store.run(id);
  if (!r) throw cal::InputError(fmt::format("{}: no run {} (see daq runs)", store.name(), id));
  if (r->kind != "linear")
    throw cal::InputError(
        fmt::format("run {} is a {} test; this needs a linear (ISO 230-2) run", id, r->kind));
  return *r;
}

struct AnalyseRunOptions {
  std::string db;
  std::int64_t run = 0;
  std::string standard;  // empty: ISO 230-2:2014 (linear), the run's own (circle)
  bool store = false;
  bool json = false;
  // Circle runs: what may be corrected after the fact.
  std::optional<double> calibrated_radius_mm, cyclic_period_mm;
  bool uncalibrated = false;
  int version = 0;  // --version: of the run's stops (0: the current one)
};

// A stored ballbar run again from its raw bar readings, with the analysis settings it was
// run with unless corrected here (the calibrated length of the bar, the cyclic period).
// `writer`: the local store, for --store (null without it).
void analyse_circle_run(const st::RunReader& store, st::Store* writer, const st::RunRecord& run,
                        const AnalyseRunOptions& o) {
  json settings = cal::daq::parse_stored_json(run.settings_json);
  if (settings.is_discarded() || !settings.contains("radius_mm"))
    throw cal::InputError(fmt::format("run {}: its circle settings are missing", o.run));
  auto [program, analysis] = circle_settings_from_json(settings);
  if (o.calibrated_radius_mm) {
    analysis.calibrated_radius_mm = o.calibrated_radius_mm;
    analysis.uncalibrated = false;
    analysis.calibration_source = "option";
    analysis.calibration.reset();
    analysis.uncalibrated_reason.clear();
  }
  if (o.cyclic_period_mm) analysis.cyclic_period_mm = o.cyclic_period_mm;
  if (o.uncalibrated) {
    analysis.uncalibrated = true;
    analysis.uncalibrated_reason = "daq analyse --uncalibrated";
  }
  if (!o.standard.empty()) {
    cal::circle::circular_standard_from_key(o.standard);  // refused here if unknown
    analysis.standard = o.standard;
  }
  // Only the bar's series is read, streamed into the segmenter, whose samples are paged: the
  // analysis reads them in place, in bounded memory however long the run (issue 32).
  const auto segmenter = segment_stored_run(store, o.run, program);
  cal::circle::Result result;
  try {
    result = analyse_traces(program, analysis, segmenter.sources());
  } catch (const cal::InputError& e) {
    throw cal::InputError(
        fmt::format("run {} ({} bar readings stored): {}", o.run, segmenter.samples(), e.what()));
  }
  auto j = circle_document(result, program, analysis);
  if (o.store) {
    json prov = provenance("reanalysed", software_version);
    prov["analysis"] = circle_settings_json(program, analysis);
    const auto id = writer->add_result({.run_id = o.run,
                                        .standard = standard_label(analysis),
                                        .json = j.dump(),
                                        .provenance_json = prov.dump()});
    j["result_id"] = id;
  }
  const auto v = run_verdict(run.kind, run.axis, settings, j);
  j["verdict"] = to_json(v);
  if (o.json) return fmt::print("{}\n", cal::daq::dump_output(j, 2));
  print_circle_result(result, program, analysis);
  print_verdict(v);
}

// A straightness, angular or roll run again from its stored stops (ISO 230-1): printed as
// daq show prints its stored result, with its verdict.
void analyse_profile_run(const st::RunReader& store, const st::RunRecord& run,
                         const AnalyseRunOptions& o) {
  if (!o.standard.empty() || o.store)
    throw cal::InputError(fmt::format(
        "run {} is a {} test, evaluated by ISO 230-1 only: --standard and --store apply to "
        "positioning and circular runs",
        run.id, run.kind));
  json j = stored_profile(store, run);
  j["values"] = rows_json(result_rows(j));
  const auto v = run_verdict(run.kind, run.axis, cal::daq::parse_stored_json(run.settings_json), j);
  j["verdict"] = to_json(v);
  if (o.json) return fmt::print("{}\n", cal::daq::dump_output(j, 2));
  print_result(j);
  print_verdict(v);
}

// A rotary axis's angular positioning run again from its stored stops (each one's deviation in
// arcsec): ISO 230-2 by the run's standard or --standard, printed as the run printed it.
void analyse_rotary_run(const st::RunReader& store, st::Store* writer, const st::RunRecord& run,
                        const AnalyseRunOptions& o) {
  if (o.calibrated_radius_mm || o.cyclic_period_mm || o.uncalibrated)
    throw cal::InputError(fmt::format(
        "run {} is a rotary test: --calibrated-radius-mm, --cyclic-period-mm and --uncalibrated "
        "apply to circle runs",
        run.id));
  if (!o.standard.empty()) cal::iso230_2::standard_from_string(o.standard);  // refused if unknown
  json j = stored_rotary(store, run, o.standard);
  j["values"] = rows_json(result_rows(j));
  if (o.store) {
    json prov = provenance("reanalysed", software_version);
    prov["standard"] = j.value("standard", "");
    prov["measure"] = "rotary";
    j["result_id"] =
        writer->add_result({.run_id = run.id,
                            .standard = fmt::format("{} rotary {} ({})", j.value("title", ""),
                                                    run.axis, j.value("component", "")),
                            .json = j.dump(),
                            .provenance_json = prov.dump()});
  }
  const auto v = run_verdict(run.kind, run.axis, cal::daq::parse_stored_json(run.settings_json), j);
  j["verdict"] = to_json(v);
  if (o.json) return fmt::print("{}\n", cal::daq::dump_output(j, 2));
  print_kind_result(j, j.value("component", ""));
  print_verdict(v);
}

void analyse_run(const AnalyseRunOptions& o) {
  // Only --store writes (the local file); without it the store is opened read-only, either.
  std::optional<st::Store> writer;
  if (o.store) writer.emplace(database_path(o.db));
  const auto reader = writer ? nullptr : open_run_reader(o.db);
  // A version other than the current one is read, not stored: --store (a local store) refuses it.
  choose_version(writer ? *writer : *reader, o.db, o.run, o.version);
  const st::RunReader& store = writer ? *writer : *reader;
  const auto run = store.run(o.run);
  if (run && run->kind == "circle")
    return analyse_circle_run(store, writer ? &*writer : nullptr, *run, o);
  if (run && is_profile_kind(run->kind)) return analyse_profile_run(store, *run, o);
  if (run && run->kind == "rotary")
    return analyse_rotary_run(store, writer ? &*writer : nullptr, *run, o);
  const std::string standard = o.standard.empty() ? "iso230-2:2014" : o.standard;
  linear_run(store, o.run);
  const auto targets = store.targets(o.run);
  if (targets.empty()) throw cal::InputError(fmt::format("run {} has no captured targets", o.run));
  const auto e =
      cal::iso230_2::evaluate(measurements(targets), cal::iso230_2::standard_from_string(standard));
  json j = to_json(e);
  if (o.store) {
    // The stops' deviations are as compensated for the current result: the same coefficients.
    const json settings = cal::daq::parse_stored_json(run->settings_json);
    const auto used = compensation_used(settings, store.results(o.run));
    json prov = provenance("reanalysed", software_version);
    prov["standard"] = standard;
    prov["coefficients"] = used.coefficients;
    prov["sensor_offsets"] = to_json(used.offsets);
    if (used.result_id) prov["of_result"] = *used.result_id;
    j["result_id"] = writer->add_result({.run_id = o.run,
                                         .standard = std::string(e.standard.title),
                                         .json = j.dump(),
                                         .provenance_json = prov.dump()});
  }
  const auto v =
      run_verdict(run->kind, run->axis, cal::daq::parse_stored_json(run->settings_json), j);
  j["verdict"] = to_json(v);
  if (o.json) return fmt::print("{}\n", cal::daq::dump_output(j, 2));
  print(e);
  print_verdict(v);
}

struct RecompensateOptions {
  std::string db;
  std::int64_t run = 0;
  std::optional<double> alpha_ppm_per_k;
  // Unset: as the current result used them (0 for a run never re-compensated).
  std::optional<double> material_offset_k, air_temperature_offset_k;
  std::optional<double> pressure_offset_pa, humidity_offset_pct;
  std::optional<std::string> equation;
  bool json = false;
};

// Re-runs the environmental compensation of every captured stop from the stored raw laser
// value and the stored (uncompensated) environment readings, then re-evaluates and stores the
// new deviations with the new result, which supersedes the earlier ones (they stay stored).
// It starts from what the current result used (coefficients and sensor offsets, from its
// provenance): the options given replace those values, the others are kept, and the result's
// provenance says which result it re-compensates and what changed. The raw data do not change.
void recompensate(const RecompensateOptions& o) {
  // A correction must be a finite number (the option parser takes "nan" and "inf").
  for (const auto& [name, value] :
       {std::pair{"--alpha-ppm", o.alpha_ppm_per_k},
        std::pair{"--material-offset", o.material_offset_k},
        std::pair{"--air-temperature-offset", o.air_temperature_offset_k},
        std::pair{"--pressure-offset", o.pressure_offset_pa},
        std::pair{"--humidity-offset", o.humidity_offset_pct}})
    if (value && !std::isfinite(*value))
      throw cal::InputError(fmt::format("recompensate: {} {}: not a finite number", name, *value));
  st::Store store(database_path(o.db));
  const auto run = linear_run(store, o.run);
  json settings = cal::daq::parse_stored_json(run.settings_json);
  if (settings.is_discarded() || !settings.contains("environment"))
    throw cal::InputError(fmt::format("run {}: its stored settings lack the environment", o.run));
  const auto used = compensation_used(settings, store.results(o.run));
  cal::daq::EnvironmentConfig cfg;
  cfg.equation = o.equation.value_or(used.coefficients.value("equation", "ciddor"));
  cfg.expansion_ppm_per_k =
      o.alpha_ppm_per_k.value_or(used.coefficients.value("expansion_ppm_per_k", 11.5));
  cfg.co2_umol_per_mol = used.coefficients.value("co2_umol_per_mol", 450.0);
  cfg.wavelength_nm = used.coefficients.value("wavelength_nm", 632.991);
  cfg.stale_after_s = 1e9;  // every stored sample counts; staleness was judged during the run
  const SensorOffsets off{
      .material_k = o.material_offset_k.value_or(used.offsets.material_k),
      .air_temperature_k = o.air_temperature_offset_k.value_or(used.offsets.air_temperature_k),
      .pressure_pa = o.pressure_offset_pa.value_or(used.offsets.pressure_pa),
      .humidity_pct = o.humidity_offset_pct.value_or(used.offsets.humidity_pct)};
  const double datum_mm = settings.value("datum_mm", 0.0);

  // The environment as recorded, with the sensor corrections: only its series are read (the
  // laser's millions of readings are not needed here).
  using Q = cal::drivers::Quantity;
  static constexpr std::uint8_t environment[] = {
      static_cast<std::uint8_t>(Q::air_temperature_degc),
      static_cast<std::uint8_t>(Q::air_pressure_pa), static_cast<std::uint8_t>(Q::air_humidity_pct),
      static_cast<std::uint8_t>(Q::material_temperature_degc)};
  const auto readings = store.readings(o.run, environment);
  // The run's material thermometers, by their stored role (roles.hpp).
  const auto instruments = store.instruments(o.run);
  const RunDevices devices(static_cast<std::size_t>(
      std::count_if(instruments.begin(), instruments.end(),
                    [](const auto& i) { return i.driver == name(Role::material); })));
  int material_sensors = 0;
  for (const auto& r : readings)
    if (static_cast<cal::drivers::Quantity>(r.quantity) ==
        cal::drivers::Quantity::material_temperature_degc)
      if (const auto k = devices.index(Role::material, r.device))
        material_sensors = std::max(material_sensors, static_cast<int>(*k) + 1);
  // Every sample is kept: the stops are compensated after all samples were given, each with
  // the environment at its own time (the stage otherwise keeps the last 2 minutes, and a long
  // run's early stops would get the air of its end).
  cal::daq::EnvStage stage(
      cfg, cal::daq::EnvSensors{.material_enabled = std::vector<bool>(
                                    static_cast<std::size_t>(std::max(material_sensors, 1)), true),
                                .keep_all_samples = true});
  for (const auto& r : readings) {
    // A sample the device flagged is no environment value, as in the live run.
    if (r.status != static_cast<std::uint8_t>(cal::drivers::ReadingStatus::ok)) continue;
    switch (static_cast<Q>(r.quantity)) {
      case Q::air_temperature_degc:
        stage.add_air(r.time_ns, cal::daq::AirQuantity::temperature_degc,
                      r.value + off.air_temperature_k);
        break;
      case Q::air_pressure_pa:
        stage.add_air(r.time_ns, cal::daq::AirQuantity::pressure_pa, r.value + off.pressure_pa);
        break;
      case Q::air_humidity_pct:
        stage.add_air(r.time_ns, cal::daq::AirQuantity::humidity_pct, r.value + off.humidity_pct);
        break;
      case Q::material_temperature_degc:
        if (const auto k = devices.index(Role::material, r.device))
          stage.add_material(r.time_ns, static_cast<int>(*k), r.value + off.material_k);
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
  const std::string standard_key = settings.value("standard", "iso230-2:2014");
  const auto e = cal::iso230_2::evaluate(measurements(targets),
                                         cal::iso230_2::standard_from_string(standard_key));
  // What changed, value by value, against what the current result used.
  json changed = json::array();
  const auto change = [&](const char* name, const json& from, const json& to) {
    if (from != to) changed.push_back({{"name", name}, {"from", from}, {"to", to}});
  };
  change("equation", used.coefficients.value("equation", "ciddor"), cfg.equation);
  change("expansion_ppm_per_k", used.coefficients.value("expansion_ppm_per_k", 11.5),
         cfg.expansion_ppm_per_k);
  change("material_offset_k", used.offsets.material_k, off.material_k);
  change("air_temperature_offset_k", used.offsets.air_temperature_k, off.air_temperature_k);
  change("pressure_offset_pa", used.offsets.pressure_pa, off.pressure_pa);
  change("humidity_offset_pct", used.offsets.humidity_pct, off.humidity_pct);
  json doc = to_json(e);
  doc["recompensation"] = {{"equation", cfg.equation},
                           {"expansion_ppm_per_k", cfg.expansion_ppm_per_k},
                           {"material_offset_k", off.material_k},
                           {"air_temperature_offset_k", off.air_temperature_k},
                           {"pressure_offset_pa", off.pressure_pa},
                           {"humidity_offset_pct", off.humidity_pct},
                           {"max_change_um", max_change_um}};
  json prov = provenance("recompensated", software_version);
  prov["standard"] = standard_key;
  prov["coefficients"] = compensation_json(cfg);
  prov["sensor_offsets"] = to_json(off);
  prov["of_result"] = used.result_id ? json(*used.result_id) : json(nullptr);
  prov["changed"] = changed;
  prov["max_change_um"] = max_change_um;
  const auto id = store.replace_targets(o.run, targets,
                                        {.run_id = o.run,
                                         .standard = std::string(e.standard.title),
                                         .json = doc.dump(),
                                         .provenance_json = prov.dump()});
  doc["result_id"] = id;
  doc["provenance"] = prov;
  // The stops changed: their quality against the run's repeatability is assessed again and
  // stored (a recompensation can make a stop suspect, or clear one).
  const auto quality = assess_stops(store.targets(o.run), "um");
  store.set_quality(o.run, quality);
  doc["quality"] = quality_json(quality);
  const auto v = run_verdict(run.kind, run.axis, settings, doc);
  doc["verdict"] = to_json(v);
  if (o.json) return fmt::print("{}\n", cal::daq::dump_output(doc, 2));
  fmt::print("run {}: {} stops recompensated (largest change {:.3f} um), stored as result {}",
             o.run, targets.size(), max_change_um, id);
  if (used.result_id) fmt::print(", superseding result {}", *used.result_id);
  print_line("");
  if (changed.empty()) print_line("  nothing changed: the same coefficients and offsets again");
  print_line("  stop quality: {}", quality_text(quality));
  for (const auto& s : quality.suspects) print_line("    SUSPECT {}", s.reason);
  for (const auto& c : changed)
    fmt::print("  {}: {} -> {}\n", c["name"].get<std::string>(), c["from"].dump(), c["to"].dump());
  print_line("");
  print(e);
  print_verdict(v);
}

}  // namespace

void add_stored_run_commands(CLI::App& app, CLI::App& analyse) {
  auto a = std::make_shared<AnalyseRunOptions>();
  analyse.require_subcommand(0, 1);
  analyse.add_option("RUN", a->run, "A stored run to evaluate again (see daq runs)");
  add_read_db_option(analyse, a->db);
  analyse.add_option("-s,--standard", a->standard,
                     "Standard for a stored run: a linear or rotary run iso230-2:2014 (default: "
                     "a rotary run's own), ...; a circle run iso230-4:2005, gb/t17421.4-2016 or "
                     "iso230-4:1996 (default: as "
                     "run)");
  analyse.add_flag("--store", a->store, "Store the result with the run");
  analyse
      .add_option("--calibrated-radius-mm", a->calibrated_radius_mm,
                  "Circle runs: the bar's corrected calibrated length")
      ->check(finite_positive());
  analyse
      .add_option("--cyclic-period-mm", a->cyclic_period_mm,
                  "Circle runs: the cyclic-error period (default: as run, else searched)")
      ->check(finite_positive());
  analyse.add_flag("--uncalibrated", a->uncalibrated, "Circle runs: no radius error");
  add_version_option(analyse, a->version);
  analyse.add_flag(
      "--json", a->json,
      "Print JSON (caldaq.iso230-2.v1, caldaq.circle.v2, caldaq.profile.v1 or caldaq.rotary.v1)");
  analyse.callback([a, &analyse] {
    if (!analyse.get_subcommands().empty()) return;
    if (a->run <= 0)
      throw cal::InputError(
          "analyse: give a stored RUN number, or a subcommand (see daq analyse --help)");
    analyse_run(*a);
  });

  const auto [cmd, r] = add_command<RecompensateOptions>(
      app, "recompensate", recompensate,
      "Recompute a stored linear run's compensation from its raw readings with corrected "
      "coefficients or sensor offsets, re-evaluate it and store the result");
  cmd->add_option("RUN", r->run, "Run number")->required();
  add_db_option(*cmd, r->db);
  cmd->add_option("--alpha-ppm", r->alpha_ppm_per_k,
                  "Corrected expansion coefficient, ppm/K (default: as the current result)");
  cmd->add_option("--material-offset", r->material_offset_k,
                  "Add to every stored material temperature, K (replaces the current offset)");
  cmd->add_option("--air-temperature-offset", r->air_temperature_offset_k,
                  "Add to the stored air temperature, K (replaces the current offset)");
  cmd->add_option("--pressure-offset", r->pressure_offset_pa,
                  "Add to the stored pressure, Pa (replaces the current offset)");
  cmd->add_option("--humidity-offset", r->humidity_offset_pct,
                  "Add to the stored humidity, %RH (replaces the current offset)");
  cmd->add_option("--equation", r->equation, "ciddor, edlen or shop-floor (default: as current)")
      ->check(CLI::IsMember({"ciddor", "edlen", "shop-floor"}));
  cmd->add_flag("--json", r->json, "Print the result JSON");
}

}  // namespace daq
