#pragma once
// Measurement uncertainty of the positioning test with a laser interferometer, in the
// manner of ISO 230-2:2014 Annex A and ISO/TR 230-9: each contributor is turned into a
// standard uncertainty of the positional deviation at the measured length L, the
// contributors are combined by root sum of squares (taken as uncorrelated), and the
// expanded uncertainty is U = k u_c with k = 2.
#include <string>
#include <vector>

#include "cal/analysis/air.hpp"

namespace cal::unc {

// What the user knows about the set-up. Uncertainties named u_* are STANDARD uncertainties
// (one standard deviation); a calibration certificate's expanded value is divided by its k.
struct PositioningSetup {
  double length_m = 1.0;  // the measured travel L

  // Laser: certificate of the interferometer system (wavelength, electronics), U at k.
  double laser_cert_expanded_ppm = 0.1;  // length-proportional part (ppm of L)
  double laser_cert_expanded_um = 0.0;   // constant part (resolution, electronics)
  double laser_cert_k = 2.0;

  // Air: the conditions of the test and the standard uncertainties of the sensors.
  air::Conditions air;
  air::Equation equation = air::Equation::ciddor;
  double u_air_temperature_k = 0.1;
  double u_pressure_pa = 10.0;
  double u_humidity_pct = 2.0;  // relative humidity, % RH

  // Machine (material) temperature and its expansion coefficient.
  double material_degc = 20.0;
  double alpha_per_k = 11.5e-6;
  double u_material_temperature_k = 0.1;
  double u_alpha_per_k = 1.0e-6;

  // Environmental variation error E_VE from a drift test (range of the drift reading over
  // the duration of the test, um); rectangular: u = E_VE / (2 sqrt 3).
  double environmental_variation_um = 0.0;

  // Misalignment: lateral offset of the beam between the two ends of the travel (mm).
  // The cosine error L (1 - cos θ) ≈ offset² / (2 L) is one-sided; rectangular over
  // [0, e]: u = e / (2 sqrt 3).
  double misalignment_offset_mm = 0.0;

  // Dead path d; its error is d Δn where Δn is the change of the index during the test.
  // When the reading is dead-path corrected, the remaining uncertainty is that of the
  // index (d u_n); when not, the change of index itself, rectangular: d |Δn| / sqrt 3.
  double dead_path_m = 0.0;
  bool dead_path_corrected = true;
  double index_change_during_test = 0.0;  // |Δn| when not corrected (e.g. 1e-6 for 1 K)
};

struct Contributor {
  std::string name;
  std::string model;  // the formula, for the report
  double u_um = 0.0;  // standard uncertainty at L
};

struct Budget {
  std::vector<Contributor> contributors;
  double u_index = 0.0;  // standard uncertainty of n from the sensors and the equation
  double u_combined_um = 0.0;
  double k = 2.0;
  double expanded_um = 0.0;  // U = k u_c
  std::vector<std::string> warnings;
};

// Throws InputError for negative uncertainties, a length <= 0, or air conditions outside
// the equation's range (from air::refractive_index).
Budget positioning_budget(const PositioningSetup& s);

}  // namespace cal::unc
