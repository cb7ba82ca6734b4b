#pragma once
// Length compensation of interferometer readings: vacuum length -> length in air,
// dead-path correction, and thermal normalisation of the machine (material) to the ISO 1
// reference temperature of 20 degC.
#include <cstdint>
#include <span>
#include <string>

namespace cal::comp {

inline constexpr double kReferenceTemperatureDegc = 20.0;  // ISO 1

// Displacement in vacuum from an interferometer's count. One fringe is lambda / (2 passes):
// a linear (retroreflector) interferometer has 1 pass, a plane-mirror interferometer 2.
// `counts_per_fringe` is the electronic interpolation of the fringe.
struct CountScale {
  double wavelength_vacuum_nm = 632.991;
  int optical_passes = 1;
  double counts_per_fringe = 1.0;
};
double vacuum_displacement_m(std::int64_t counts, const CountScale& scale);

// A displacement measured along the same beam in vacuum equals n times the one measured in air.
inline double air_length_m(double vacuum_length_m, double n_air) { return vacuum_length_m / n_air; }

// Dead path: the beam length d between interferometer and reflector at the datum (zero).
// When the datum was set with index n_datum and the reading is now compensated with n, the
// reading carries the error d (n - n_datum) / n; this returns the corrected displacement.
// Derivation: the fringe count measures n (d + L) - n_datum d; dividing by n gives
// L + d (n - n_datum) / n.
double dead_path_corrected_m(double compensated_length_m, double dead_path_m, double n_datum,
                             double n_now);

// A material (machine) temperature sensor; disabled sensors are ignored (a broken or
// badly placed probe) but stay in the record.
struct MaterialSensor {
  std::string name;
  double temperature_degc = 20.0;
  bool enabled = true;
};
// Mean of the enabled sensors; throws InputError when none is enabled or one is not finite.
double material_temperature_degc(std::span<const MaterialSensor> sensors);

// Length at 20 degC of a length measured with the material at `material_degc`:
// L20 = L / (1 + alpha (T - 20)). `alpha_per_k` is the linear expansion coefficient (1/K).
// Inline: it is applied to every reading of a 10 kHz stream.
inline double normalise_to_20c_m(double length_m, double alpha_per_k, double material_degc) {
  return length_m / (1.0 + alpha_per_k * (material_degc - kReferenceTemperatureDegc));
}

// The whole factor that turns a vacuum length into a length at 20 degC:
// k = 1 / (n (1 + alpha (T - 20))). Reported in ppm as (k - 1) 1e6.
struct Factor {
  double n_air = 1.0;
  double material_degc = 20.0;
  double alpha_per_k = 0.0;
  double factor = 1.0;
  double air_ppm = 0.0;       // (1/n - 1) 1e6
  double material_ppm = 0.0;  // (1/(1 + alpha dT) - 1) 1e6
  double total_ppm = 0.0;     // (factor - 1) 1e6
};
Factor combined_factor(double n_air, double alpha_per_k, double material_degc);

}  // namespace cal::comp
