#include "cal/analysis/compensation.hpp"

#include <fmt/format.h>

#include <cmath>

#include "cal/analysis/error.hpp"

namespace cal::comp {

double vacuum_displacement_m(std::int64_t counts, const CountScale& s) {
  if (!(s.wavelength_vacuum_nm > 0) || s.optical_passes < 1 || !(s.counts_per_fringe > 0)) {
    throw InputError(fmt::format(
        "count scale: wavelength {} nm, passes {}, counts per fringe {} must all be positive",
        s.wavelength_vacuum_nm, s.optical_passes, s.counts_per_fringe));
  }
  const double fringe_m = s.wavelength_vacuum_nm * 1e-9 / (2.0 * s.optical_passes);
  return static_cast<double>(counts) * fringe_m / s.counts_per_fringe;
}

double dead_path_corrected_m(double compensated_length_m, double dead_path_m, double n_datum,
                             double n_now) {
  if (!(dead_path_m >= 0)) {
    throw InputError(fmt::format("dead path = {} m must be >= 0", dead_path_m));
  }
  return compensated_length_m - dead_path_m * (n_now - n_datum) / n_now;
}

double material_temperature_degc(std::span<const MaterialSensor> sensors) {
  double sum = 0.0;
  int used = 0;
  for (const auto& s : sensors) {
    if (!s.enabled) continue;
    if (!std::isfinite(s.temperature_degc) || s.temperature_degc < -50 ||
        s.temperature_degc > 150) {
      throw InputError(fmt::format("material sensor '{}' reads {} degC, outside -50 .. 150 degC",
                                   s.name, s.temperature_degc));
    }
    sum += s.temperature_degc;
    ++used;
  }
  if (used == 0) throw InputError("no material temperature sensor is enabled");
  return sum / used;
}

Factor combined_factor(double n_air, double alpha_per_k, double material_degc) {
  if (!(n_air >= 1.0 && n_air < 1.01)) {
    throw InputError(fmt::format("refractive index n = {} is not that of air", n_air));
  }
  if (!std::isfinite(alpha_per_k) || std::abs(alpha_per_k) > 1e-3) {
    throw InputError(fmt::format(
        "expansion coefficient = {} 1/K is implausible (expected e.g. 11.5e-6 for steel)",
        alpha_per_k));
  }
  Factor f;
  f.n_air = n_air;
  f.material_degc = material_degc;
  f.alpha_per_k = alpha_per_k;
  const double thermal = 1.0 + alpha_per_k * (material_degc - kReferenceTemperatureDegc);
  f.factor = 1.0 / (n_air * thermal);
  f.air_ppm = (1.0 / n_air - 1.0) * 1e6;
  f.material_ppm = (1.0 / thermal - 1.0) * 1e6;
  f.total_ppm = (f.factor - 1.0) * 1e6;
  return f;
}

}  // namespace cal::comp
