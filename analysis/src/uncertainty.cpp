#include "cal/analysis/uncertainty.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "cal/analysis/error.hpp"

namespace cal::unc {
namespace {

const double kSqrt3 = std::sqrt(3.0);

// Sensitivity of n to one input by a central difference on the chosen equation, the two
// points kept inside [lo, hi] (a relative humidity of 100 % can only step down). The step
// is small against the input but large against rounding (n - 1 carries ~1e-16 noise).
template <typename Get>
double dn(const air::Conditions& at, air::Equation eq, double step, double lo, double hi, Get get) {
  air::Conditions a = at, b = at;
  double& va = get(a);
  double& vb = get(b);
  va = std::max(lo, va - step / 2);
  vb = std::min(hi, vb + step / 2);
  return (air::refractive_index(b, eq).n - air::refractive_index(a, eq).n) / (vb - va);
}

void require_non_negative(double v, const char* name) {
  if (!(v >= 0)) throw InputError(fmt::format("uncertainty setup: {} = {} must be >= 0", name, v));
}

}  // namespace

Budget positioning_budget(const PositioningSetup& s) {
  if (!(s.length_m > 0)) {
    throw InputError(fmt::format("uncertainty setup: length = {} m must be > 0", s.length_m));
  }
  for (auto [v, name] : {std::pair{s.laser_cert_expanded_ppm, "laser certificate (ppm)"},
                         {s.laser_cert_expanded_um, "laser certificate (um)"},
                         {s.u_air_temperature_k, "u(air temperature)"},
                         {s.u_pressure_pa, "u(pressure)"},
                         {s.u_humidity_pct, "u(humidity)"},
                         {s.u_material_temperature_k, "u(material temperature)"},
                         {s.u_alpha_per_k, "u(expansion coefficient)"},
                         {s.environmental_variation_um, "environmental variation E_VE"},
                         {s.misalignment_offset_mm, "misalignment offset"},
                         {s.dead_path_m, "dead path"},
                         {s.index_change_during_test, "index change"}}) {
    require_non_negative(v, name);
  }
  if (!(s.laser_cert_k > 0)) throw InputError("uncertainty setup: certificate k must be > 0");

  Budget b;
  const double L_um = s.length_m * 1e6;
  b.warnings = air::refractive_index(s.air, s.equation).warnings;

  // Index of air: sensitivities dn/dt, dn/dp, dn/dRH of the equation in use.
  constexpr double inf = std::numeric_limits<double>::infinity();
  const double c_t = dn(s.air, s.equation, 0.02, -inf, inf,
                        [](air::Conditions& c) -> double& { return c.temperature_degc; });
  const double c_p = dn(s.air, s.equation, 2.0, -inf, inf,
                        [](air::Conditions& c) -> double& { return c.pressure_pa; });
  air::Conditions rh_air = s.air;
  if (rh_air.humidity.kind != air::Humidity::Kind::relative_pct) {
    // Express the humidity as RH so that u(RH) applies.
    rh_air.humidity =
        air::Humidity::relative_pct(100.0 * air::water_vapour_pressure_pa(s.air) /
                                    air::saturation_vapour_pressure_pa(s.air.temperature_degc));
  }
  const double c_h = dn(rh_air, s.equation, 0.1, 0.0, 100.0,
                        [](air::Conditions& c) -> double& { return c.humidity.value; });
  const double u_eq = air::equation_standard_uncertainty(s.equation);
  b.u_index =
      std::sqrt(std::pow(c_t * s.u_air_temperature_k, 2) + std::pow(c_p * s.u_pressure_pa, 2) +
                std::pow(c_h * s.u_humidity_pct, 2) + u_eq * u_eq);

  auto add = [&](std::string name, std::string model, double u_um) {
    b.contributors.push_back({std::move(name), std::move(model), u_um});
  };
  add("laser (certificate)", "sqrt(U_ppm² L² + U_um²) / k",
      std::hypot(s.laser_cert_expanded_ppm * 1e-6 * L_um, s.laser_cert_expanded_um) /
          s.laser_cert_k);
  add("air temperature sensor", fmt::format("L |dn/dt| u(t), dn/dt = {:.4g} /K", c_t),
      L_um * std::abs(c_t) * s.u_air_temperature_k);
  add("air pressure sensor", fmt::format("L |dn/dp| u(p), dn/dp = {:.4g} /Pa", c_p),
      L_um * std::abs(c_p) * s.u_pressure_pa);
  add("humidity sensor", fmt::format("L |dn/dRH| u(RH), dn/dRH = {:.4g} /%", c_h),
      L_um * std::abs(c_h) * s.u_humidity_pct);
  add(fmt::format("{} equation", air::to_string(s.equation)), "L u(equation)", L_um * u_eq);
  add("material temperature", "L alpha u(T)", L_um * s.alpha_per_k * s.u_material_temperature_k);
  add("expansion coefficient", "L |T - 20 degC| u(alpha)",
      L_um * std::abs(s.material_degc - 20.0) * s.u_alpha_per_k);
  add("environmental variation (drift test)", "E_VE / (2 sqrt 3)",
      s.environmental_variation_um / (2 * kSqrt3));
  const double cosine_um = std::pow(s.misalignment_offset_mm * 1e3, 2) / (2 * L_um);
  add("misalignment (cosine error)", "offset² / (2 L) / (2 sqrt 3)", cosine_um / (2 * kSqrt3));
  if (s.dead_path_corrected) {
    add("dead path (corrected)", "d u(n)", s.dead_path_m * 1e6 * b.u_index);
  } else {
    add("dead path (not corrected)", "d |Δn| / sqrt 3",
        s.dead_path_m * 1e6 * s.index_change_during_test / kSqrt3);
  }
  double sum = 0;
  for (const auto& c : b.contributors) sum += c.u_um * c.u_um;
  b.u_combined_um = std::sqrt(sum);
  b.expanded_um = b.k * b.u_combined_um;
  return b;
}

}  // namespace cal::unc
