#pragma once
// Refractive index of air for length interferometry.
//
// Three equations, implemented as documented by NIST's Engineering Metrology Toolbox
// ("Refractive Index of Air Calculator", J. A. Stone and J. H. Zimmerman):
//  - the modified Edlén equation with the Birch & Downs (1993, 1994) corrections,
//  - the Ciddor (1996) equation,
//  - the NIST "shop floor" simplified equation (HeNe 633 nm only).
// The saturation vapour pressure (IAPWS over water, over ice below 0 degC) and the
// enhancement factor follow the same documentation. Units are SI except where named.
#include <string>
#include <string_view>
#include <vector>

namespace cal::air {

enum class Equation { edlen, ciddor, shop_floor };

std::string_view to_string(Equation e);
// Accepts "edlen", "ciddor", "shop-floor" (also "shop_floor", "nist-shop-floor"); throws
// InputError.
Equation equation_from_string(std::string_view name);

// How the humidity of the air is given.
struct Humidity {
  enum class Kind { relative_pct, dew_point_degc, vapour_pressure_pa };
  Kind kind = Kind::relative_pct;
  double value = 50.0;

  static Humidity relative_pct(double rh) { return {Kind::relative_pct, rh}; }
  static Humidity dew_point_degc(double td) { return {Kind::dew_point_degc, td}; }
  static Humidity vapour_pressure_pa(double pv) { return {Kind::vapour_pressure_pa, pv}; }
};

struct Conditions {
  double temperature_degc = 20.0;
  double pressure_pa = 101325.0;
  Humidity humidity = Humidity::relative_pct(50.0);
  double co2_umol_per_mol = 450.0;
  double wavelength_vacuum_nm = 632.991;  // HeNe (iodine-stabilised value 632.991 nm)
};

// Saturation vapour pressure over liquid water (IAPWS-IF97 form used by NIST), valid
// (as used here) from -50 degC to 150 degC. Pa.
double saturation_vapour_pressure_water_pa(double t_degc);
// Saturation vapour pressure over ice (IAPWS 1993 sublimation equation), Pa.
double saturation_vapour_pressure_ice_pa(double t_degc);
// Over water at or above 0 degC, over ice below, as NIST's calculator does.
double saturation_vapour_pressure_pa(double t_degc);
// Enhancement factor f = alpha + beta p + gamma t^2 of moist air.
double enhancement_factor(double pressure_pa, double t_degc);
// Partial pressure of water vapour as NIST EMT A-II defines it: (RH/100) psv(t) from a
// relative humidity, psv(td) from a dew point (frost point below 0 degC), or as given.
double water_vapour_pressure_pa(const Conditions& c);
// Mole fraction of water vapour xv = f pv / p (the Ciddor equation's humidity input).
double water_vapour_mole_fraction(const Conditions& c);

struct Result {
  double n = 1.0;                       // refractive index of the air (phase index)
  double water_vapour_pressure_pa = 0;  // the p_v the equation used
  Equation equation = Equation::ciddor;
  std::vector<std::string> warnings;  // inputs where the equation's accuracy is degraded
};

// Refractive index. Inputs outside the equation's valid range throw InputError naming
// the input, its value and the range; inputs where NIST's calculator warns are accepted
// and listed in Result::warnings.
Result refractive_index(const Conditions& c, Equation eq = Equation::ciddor);

// Standard uncertainty of the equation itself (its fit to the underlying data), as stated
// by its authors / NIST, used in the uncertainty budget.
double equation_standard_uncertainty(Equation eq);

}  // namespace cal::air
