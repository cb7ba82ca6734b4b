#include "cal/analysis/air.hpp"

#include <fmt/format.h>

#include <cmath>

#include "cal/analysis/enum_names.hpp"
#include "cal/analysis/error.hpp"

namespace cal::air {
namespace {

constexpr double kKelvinOffset = 273.15;

// An input range: values outside [lo, hi] are refused, values outside [warn_lo, warn_hi]
// (a sub-range) are accepted with a warning.
struct Range {
  std::string_view name;
  std::string_view unit;
  double lo, hi;
  double warn_lo, warn_hi;
};

void check(const Range& r, double v, Equation eq, std::vector<std::string>& warnings) {
  if (!std::isfinite(v) || v < r.lo || v > r.hi) {
    throw InputError(
        fmt::format("{} = {} {} is outside the valid range {} .. {} {} of the {} equation", r.name,
                    v, r.unit, r.lo, r.hi, r.unit, to_string(eq)));
  }
  if (v < r.warn_lo || v > r.warn_hi) {
    warnings.push_back(
        fmt::format("{} = {} {} is outside {} .. {} {}, where the {} equation is "
                    "tested; its uncertainty is larger there",
                    r.name, v, r.unit, r.warn_lo, r.warn_hi, r.unit, to_string(eq)));
  }
}

struct Ranges {
  Range wavelength, temperature, pressure, humidity, co2;
};

// Valid ranges and warning ranges of NIST's calculator: wavelength 300 .. 1700 nm, pressure
// 10 .. 140 kPa, temperature -40 .. 100 degC, humidity 0 .. 100 %, CO2 0 .. 2000 umol/mol;
// it warns outside 350 .. 1600 nm, 60 .. 120 kPa, 0 .. 40 degC and above 85 %RH. The
// Edlén equation was fitted to data between 350 and 650 nm, so it warns outside those.
// The shop-floor equation is NIST's simplification for 633 nm near room conditions; its
// ranges are ours (see docs/refractive-index.md).
Ranges ranges_for(Equation eq) {
  const Range temperature{"air temperature", "degC", -40, 100, 0, 40};
  const Range pressure{"pressure", "Pa", 10e3, 140e3, 60e3, 120e3};
  const Range humidity{"relative humidity", "%", 0, 100, 0, 85};
  const Range co2{"CO2 mole fraction", "umol/mol", 0, 2000, 0, 2000};
  switch (eq) {
    case Equation::ciddor:
      return {{"wavelength", "nm", 300, 1700, 350, 1600}, temperature, pressure, humidity, co2};
    case Equation::edlen:
      return {{"wavelength", "nm", 300, 1700, 350, 650}, temperature, pressure, humidity, co2};
    case Equation::shop_floor:
      break;
  }
  return {{"wavelength", "nm", 632.5, 633.5, 632.5, 633.5},
          {"air temperature", "degC", 0, 40, 15, 30},
          {"pressure", "Pa", 60e3, 120e3, 80e3, 110e3},
          humidity,
          co2};
}

double relative_humidity_pct(const Conditions& c, double pv_pa) {
  return 100.0 * pv_pa / saturation_vapour_pressure_pa(c.temperature_degc);
}

// Modified Edlén equation, Birch & Downs (1993) with the 1994 correction, as written in
// NIST EMT "Refractive Index of Air Calculator: Equations" (Edlén section).
double edlen(double t, double p, double pv, double lambda_um, double co2) {
  constexpr double A = 8342.54, B = 2406147, C = 15998, D = 96095.43, E = 0.601, F = 0.00972,
                   G = 0.003661;
  const double S = 1.0 / (lambda_um * lambda_um);
  double ns_minus_1 = 1e-8 * (A + B / (130.0 - S) + C / (38.9 - S));
  // Birch & Downs assume 450 umol/mol of CO2; the CO2 dependence of the dispersion term is
  // Edlén's (1966) 1 + 0.540 (x - x0), as also used by Bönsch & Potulski (1998).
  ns_minus_1 *= 1.0 + 0.540 * (co2 - 450.0) * 1e-6;
  const double X = (1.0 + 1e-8 * (E - F * t) * p) / (1.0 + G * t);
  const double ntp = 1.0 + p * ns_minus_1 * X / D;
  return ntp - 1e-10 * (292.75 / (t + kKelvinOffset)) * (3.7345 - 0.0401 * S) * pv;
}

// Ciddor (1996), Appl. Opt. 35, 1566, with the constants NIST EMT lists.
double ciddor(double t, double p, double xv, double lambda_um, double co2) {
  constexpr double w0 = 295.235, w1 = 2.6422, w2 = -0.032380, w3 = 0.004028;
  constexpr double k0 = 238.0185, k1 = 5792105, k2 = 57.362, k3 = 167917;
  constexpr double a0 = 1.58123e-6, a1 = -2.9331e-8, a2 = 1.1043e-10;
  constexpr double b0 = 5.707e-6, b1 = -2.051e-8;
  constexpr double c0 = 1.9898e-4, c1 = -2.376e-6;
  constexpr double d = 1.83e-11, e = -0.765e-8;
  constexpr double pR1 = 101325, TR1 = 288.15, Za = 0.9995922115, rho_vs = 0.00985938;
  constexpr double R = 8.314472, Mv = 0.018015;

  const double S = 1.0 / (lambda_um * lambda_um);
  const double ras = 1e-8 * (k1 / (k0 - S) + k3 / (k2 - S));
  const double rvs = 1.022e-8 * (w0 + w1 * S + w2 * S * S + w3 * S * S * S);
  const double Ma = 0.0289635 + 1.2011e-8 * (co2 - 400.0);
  const double raxs = ras * (1.0 + 5.34e-7 * (co2 - 450.0));
  const double T = t + kKelvinOffset;
  const double Zm =
      1.0 - (p / T) * (a0 + a1 * t + a2 * t * t + (b0 + b1 * t) * xv + (c0 + c1 * t) * xv * xv) +
      (p / T) * (p / T) * (d + e * xv * xv);
  const double rho_axs = pR1 * Ma / (Za * R * TR1);
  const double rho_v = xv * p * Mv / (Zm * R * T);
  const double rho_a = (1.0 - xv) * p * Ma / (Zm * R * T);
  return 1.0 + (rho_a / rho_axs) * raxs + (rho_v / rho_vs) * rvs;
}

// NIST shop-floor equation: n = 1 + 7.86e-4 p/(273 + t) - 1.5e-11 RH (t^2 + 160),
// p in kPa, t in degC, RH in percent. For 633 nm only.
double shop_floor(double t, double p_pa, double rh_pct) {
  return 1.0 + 7.86e-4 * (p_pa / 1000.0) / (273.0 + t) - 1.5e-11 * rh_pct * (t * t + 160.0);
}

// The shown name first; the other spellings are accepted on input.
constexpr EnumName<Equation> kEquationNames[] = {
    {Equation::edlen, "edlen"},           {Equation::edlen, "edlen-birch-downs"},
    {Equation::ciddor, "ciddor"},         {Equation::shop_floor, "shop-floor"},
    {Equation::shop_floor, "shop_floor"}, {Equation::shop_floor, "nist-shop-floor"}};
static_assert(cal::names_every_value(kEquationNames));
}  // namespace

std::string_view to_string(Equation e) { return name_of(kEquationNames, e); }

Equation equation_from_string(std::string_view name) {
  return parse_name(kEquationNames, name, "refractive-index equation");
}

double saturation_vapour_pressure_water_pa(double t_degc) {
  constexpr double K1 = 1.16705214528e+03, K2 = -7.24213167032e+05, K3 = -1.70738469401e+01,
                   K4 = 1.20208247025e+04, K5 = -3.23255503223e+06, K6 = 1.49151086135e+01,
                   K7 = -4.82326573616e+03, K8 = 4.05113405421e+05, K9 = -2.38555575678e-01,
                   K10 = 6.50175348448e+02;
  const double T = t_degc + kKelvinOffset;
  const double omega = T + K9 / (T - K10);
  const double A = omega * omega + K1 * omega + K2;
  const double B = K3 * omega * omega + K4 * omega + K5;
  const double C = K6 * omega * omega + K7 * omega + K8;
  const double X = -B + std::sqrt(B * B - 4.0 * A * C);
  return 1e6 * std::pow(2.0 * C / X, 4);
}

double saturation_vapour_pressure_ice_pa(double t_degc) {
  constexpr double A1 = -13.928169, A2 = 34.7078238;
  const double theta = (t_degc + kKelvinOffset) / 273.16;
  const double Y = A1 * (1.0 - std::pow(theta, -1.5)) + A2 * (1.0 - std::pow(theta, -1.25));
  return 611.657 * std::exp(Y);
}

double saturation_vapour_pressure_pa(double t_degc) {
  return t_degc >= 0.0 ? saturation_vapour_pressure_water_pa(t_degc)
                       : saturation_vapour_pressure_ice_pa(t_degc);
}

double enhancement_factor(double pressure_pa, double t_degc) {
  constexpr double alpha = 1.00062, beta = 3.14e-8, gamma = 5.6e-7;
  return alpha + beta * pressure_pa + gamma * t_degc * t_degc;
}

// NIST EMT A-II: the partial pressure is pv = (RH/100) psv(t) for a relative humidity, and
// pv = psv(td) for a dew point (over ice below 0 degC: a frost point). The enhancement
// factor enters only the mole fraction xv = f pv / p that the Ciddor equation uses; the
// Edlén equation takes pv itself.
double water_vapour_pressure_pa(const Conditions& c) {
  switch (c.humidity.kind) {
    case Humidity::Kind::relative_pct:
      if (!std::isfinite(c.humidity.value) || c.humidity.value < 0 || c.humidity.value > 100) {
        throw InputError(
            fmt::format("relative humidity = {} % is outside 0 .. 100 %", c.humidity.value));
      }
      return c.humidity.value / 100.0 * saturation_vapour_pressure_pa(c.temperature_degc);
    case Humidity::Kind::dew_point_degc: {
      const double td = c.humidity.value;
      if (!std::isfinite(td) || td > c.temperature_degc + 1e-9 || td < -100.0) {
        throw InputError(fmt::format(
            "dew point = {} degC must lie between -100 degC and the air temperature {} degC", td,
            c.temperature_degc));
      }
      return saturation_vapour_pressure_pa(td);
    }
    case Humidity::Kind::vapour_pressure_pa:
      if (!std::isfinite(c.humidity.value) || c.humidity.value < 0) {
        throw InputError(
            fmt::format("water vapour pressure = {} Pa must be >= 0", c.humidity.value));
      }
      return c.humidity.value;
  }
  return 0.0;
}

namespace {
// xv = f pv / p, with f at the temperature where the vapour is saturated: the dew point
// when one is given, else the air temperature.
double mole_fraction(const Conditions& c, double pv_pa) {
  const double t_f =
      c.humidity.kind == Humidity::Kind::dew_point_degc ? c.humidity.value : c.temperature_degc;
  return enhancement_factor(c.pressure_pa, t_f) * pv_pa / c.pressure_pa;
}
}  // namespace

double water_vapour_mole_fraction(const Conditions& c) {
  return mole_fraction(c, water_vapour_pressure_pa(c));
}

Result refractive_index(const Conditions& c, Equation eq) {
  Result r;
  r.equation = eq;
  const Ranges rg = ranges_for(eq);
  check(rg.wavelength, c.wavelength_vacuum_nm, eq, r.warnings);
  check(rg.temperature, c.temperature_degc, eq, r.warnings);
  check(rg.pressure, c.pressure_pa, eq, r.warnings);
  check(rg.co2, c.co2_umol_per_mol, eq, r.warnings);
  const double pv = water_vapour_pressure_pa(c);
  const double rh = relative_humidity_pct(c, pv);
  // A dew point or vapour pressure may imply RH slightly above 100 % through rounding.
  check(rg.humidity, rh > 100.0 && rh < 100.5 ? 100.0 : rh, eq, r.warnings);
  r.water_vapour_pressure_pa = pv;

  const double t = c.temperature_degc, p = c.pressure_pa;
  const double lambda_um = c.wavelength_vacuum_nm / 1000.0;
  switch (eq) {
    case Equation::edlen:
      r.n = edlen(t, p, pv, lambda_um, c.co2_umol_per_mol);
      break;
    case Equation::ciddor:
      r.n = ciddor(t, p, mole_fraction(c, pv), lambda_um, c.co2_umol_per_mol);
      break;
    case Equation::shop_floor:
      r.n = shop_floor(t, p, rh);
      break;
  }
  return r;
}

double equation_standard_uncertainty(Equation eq) {
  switch (eq) {
    case Equation::edlen:
      return 1e-8;  // Birch & Downs: about 1e-8 (1 sigma) in typical laboratory conditions.
    case Equation::ciddor:
      return 1e-8;
    case Equation::shop_floor:
      return 1.5e-7;  // NIST: the shop-floor equation agrees to about 1.5e-7.
  }
  return 0.0;
}

}  // namespace cal::air
