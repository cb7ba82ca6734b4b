// daq env: refractive index of air and the length compensation factor.
#include <fmt/format.h>

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "cal/analysis/air.hpp"
#include "cal/analysis/compensation.hpp"
#include "cal/analysis/error.hpp"
#include "command.hpp"
#include "commands.hpp"

namespace daq {
namespace {

struct EnvOptions {
  double temperature_degc = 20.0;
  std::optional<double> pressure_hpa, pressure_pa;
  std::optional<double> rh_pct, dew_point_degc, vapour_pressure_pa;
  double co2 = 450.0;
  double wavelength_nm = 632.991;
  std::string equation = "all";
  std::vector<double> material_degc;
  std::vector<int> disabled_sensors;  // 1-based
  double alpha_ppm_per_k = 0.0;
  bool json = false;
};

cal::air::Conditions conditions(const EnvOptions& o) {
  cal::air::Conditions c;
  c.temperature_degc = o.temperature_degc;
  c.pressure_pa =
      o.pressure_pa ? *o.pressure_pa : (o.pressure_hpa ? *o.pressure_hpa : 1013.25) * 100.0;
  if (o.dew_point_degc) {
    c.humidity = cal::air::Humidity::dew_point_degc(*o.dew_point_degc);
  } else if (o.vapour_pressure_pa) {
    c.humidity = cal::air::Humidity::vapour_pressure_pa(*o.vapour_pressure_pa);
  } else {
    c.humidity = cal::air::Humidity::relative_pct(o.rh_pct.value_or(50.0));
  }
  c.co2_umol_per_mol = o.co2;
  c.wavelength_vacuum_nm = o.wavelength_nm;
  return c;
}

std::vector<cal::comp::MaterialSensor> sensors(const EnvOptions& o) {
  std::vector<cal::comp::MaterialSensor> s;
  for (std::size_t i = 0; i < o.material_degc.size(); ++i) {
    s.push_back({fmt::format("material {}", i + 1), o.material_degc[i], true});
  }
  for (int d : o.disabled_sensors) {
    if (d < 1 || d > static_cast<int>(s.size())) {
      throw cal::InputError(
          fmt::format("--disable-sensor {}: there are {} material sensors", d, s.size()));
    }
    s[static_cast<std::size_t>(d - 1)].enabled = false;
  }
  return s;
}

void run_env(const EnvOptions& o) {
  const auto c = conditions(o);
  std::vector<cal::air::Equation> eqs;
  if (o.equation == "all") {
    eqs = {cal::air::Equation::edlen, cal::air::Equation::ciddor};
    if (std::abs(o.wavelength_nm - 633.0) < 0.5) eqs.push_back(cal::air::Equation::shop_floor);
  } else {
    eqs = {cal::air::equation_from_string(o.equation)};
  }
  const auto mat = sensors(o);
  const double material = mat.empty() ? 20.0 : cal::comp::material_temperature_degc(mat);
  const double alpha = o.alpha_ppm_per_k * 1e-6;

  nlohmann::json j;
  j["schema"] = "caldaq.env.v1";
  j["inputs"] = {{"air_temperature_degc", c.temperature_degc},
                 {"pressure_pa", c.pressure_pa},
                 {"co2_umol_per_mol", c.co2_umol_per_mol},
                 {"wavelength_vacuum_nm", c.wavelength_vacuum_nm},
                 {"material_temperature_degc", material},
                 {"expansion_coefficient_per_k", alpha}};
  j["material_sensors"] = nlohmann::json::array();
  for (const auto& s : mat) {
    j["material_sensors"].push_back(
        {{"name", s.name}, {"temperature_degc", s.temperature_degc}, {"enabled", s.enabled}});
  }
  j["results"] = nlohmann::json::array();
  for (auto eq : eqs) {
    const auto r = cal::air::refractive_index(c, eq);
    const auto f = cal::comp::combined_factor(r.n, alpha, material);
    j["results"].push_back({{"equation", cal::air::to_string(eq)},
                            {"n", r.n},
                            {"water_vapour_pressure_pa", r.water_vapour_pressure_pa},
                            {"air_ppm", f.air_ppm},
                            {"material_ppm", f.material_ppm},
                            {"total_ppm", f.total_ppm},
                            {"factor", f.factor},
                            {"warnings", r.warnings}});
  }
  if (o.json) {
    fmt::print("{}\n", j.dump(2));
    return;
  }
  fmt::print("Air {:.3f} degC, {:.2f} hPa, CO2 {:.0f} umol/mol, vacuum wavelength {:.4f} nm\n",
             c.temperature_degc, c.pressure_pa / 100.0, c.co2_umol_per_mol, c.wavelength_vacuum_nm);
  fmt::print("Material {:.3f} degC (mean of {} enabled sensor(s)), alpha {:.3f} ppm/K\n\n",
             material, std::count_if(mat.begin(), mat.end(), [](auto& s) { return s.enabled; }),
             o.alpha_ppm_per_k);
  fmt::print("{:<12} {:>16} {:>10} {:>12} {:>13} {:>11}\n", "equation", "n", "pv / Pa", "air / ppm",
             "material/ppm", "total/ppm");
  for (const auto& r : j["results"]) {
    fmt::print("{:<12} {:>16.10f} {:>10.2f} {:>12.4f} {:>13.4f} {:>11.4f}\n",
               r["equation"].get<std::string>(), r["n"].get<double>(),
               r["water_vapour_pressure_pa"].get<double>(), r["air_ppm"].get<double>(),
               r["material_ppm"].get<double>(), r["total_ppm"].get<double>());
    for (const auto& w : r["warnings"]) fmt::print("  warning: {}\n", w.get<std::string>());
  }
  fmt::print("\nA length read in vacuum units L_vac becomes L_20 = L_vac (1 + total_ppm 1e-6).\n");
}

}  // namespace

void add_env_command(CLI::App& app) {
  const auto [cmd, o] = add_command<EnvOptions>(
      app, "env", run_env, "Refractive index of air and the length compensation factor (ppm)");
  cmd->add_option("-t,--temperature", o->temperature_degc, "Air temperature, degC")
      ->capture_default_str();
  auto* hpa =
      cmd->add_option("-p,--pressure-hpa", o->pressure_hpa, "Air pressure, hPa (default 1013.25)");
  cmd->add_option("--pressure-pa", o->pressure_pa, "Air pressure, Pa")->excludes(hpa);
  auto* rh = cmd->add_option("-r,--rh", o->rh_pct, "Relative humidity, % (default 50)");
  auto* dp = cmd->add_option("--dew-point", o->dew_point_degc, "Dew point, degC")->excludes(rh);
  cmd->add_option("--vapour-pressure-pa", o->vapour_pressure_pa,
                  "Water vapour partial pressure, Pa")
      ->excludes(rh)
      ->excludes(dp);
  cmd->add_option("--co2", o->co2, "CO2 mole fraction, umol/mol")->capture_default_str();
  cmd->add_option("-w,--wavelength-nm", o->wavelength_nm, "Vacuum wavelength, nm")
      ->capture_default_str();
  cmd->add_option("-e,--equation", o->equation, "edlen | ciddor | shop-floor | all")
      ->capture_default_str();
  cmd->add_option("-m,--material-temp", o->material_degc,
                  "Material temperature sensor reading, degC (repeat for several sensors; "
                  "their enabled mean is used)");
  cmd->add_option("--disable-sensor", o->disabled_sensors,
                  "Ignore material sensor N (1-based, repeatable)");
  cmd->add_option("-a,--alpha-ppm", o->alpha_ppm_per_k,
                  "Expansion coefficient of the machine/scale, ppm/K (e.g. 11.5 for steel)")
      ->capture_default_str();
  cmd->add_flag("--json", o->json, "Print JSON (schema caldaq.env.v1)");
}

}  // namespace daq
