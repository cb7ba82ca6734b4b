#include "cal/analysis/air.hpp"

#include <gtest/gtest.h>

#include "cal/analysis/error.hpp"

namespace {

using namespace cal::air;

Conditions at(double t_degc, double p_pa, double rh_pct, double wavelength_nm = 633.0) {
  Conditions c;
  c.temperature_degc = t_degc;
  c.pressure_pa = p_pa;
  c.humidity = Humidity::relative_pct(rh_pct);
  c.wavelength_vacuum_nm = wavelength_nm;
  return c;
}

// Reference values: the examples in the README of phn/ref_index (Prasanth Nair's
// implementation of the equations of the NIST EMT documentation, written independently of
// this code), 633 nm, 101325 Pa, CO2 450 umol/mol. Required agreement: 1e-12 in n, far
// below the 1e-8 the issue asks for, because both implement the same documented formulas.
struct Reference {
  double t_degc, rh_pct;
  Equation eq;
  double n;
};
constexpr Reference kRefIndexExamples[] = {
    {20, 20, Equation::ciddor, 1.0002716285340578}, {20, 20, Equation::edlen, 1.0002716291691649},
    {20, 80, Equation::edlen, 1.0002711197635226},  {20, 80, Equation::ciddor, 1.0002711183472626},
    {60, 80, Equation::edlen, 1.0002339748542823},  {60, 80, Equation::ciddor, 1.0002340241754055},
};

TEST(Air, MatchesIndependentImplementationOfNistEquations) {
  for (const auto& r : kRefIndexExamples) {
    const auto res = refractive_index(at(r.t_degc, 101325, r.rh_pct), r.eq);
    EXPECT_NEAR(res.n, r.n, 1e-12) << to_string(r.eq) << " t=" << r.t_degc << " RH=" << r.rh_pct;
  }
}

// NIST EMT modified-Edlén calculator (emtoolbox.nist.gov/Wavelength/Edlen.asp) outputs at
// 20 degC, 101.325 kPa, 30 %RH, printed to 9 decimals, as recorded in the KOTO/E14 "Gsim"
// Geant4 material table (GsimMaterialManager). Tolerance: half a unit of the last printed
// digit plus our own rounding, 6e-10.
TEST(Air, EdlenMatchesNistCalculatorOutputs) {
  constexpr std::pair<double, double> kTable[] = {
      {300, 1.000286349}, {325, 1.000283315}, {350, 1.000280985}, {375, 1.000279151},
      {400, 1.000277679}, {425, 1.000276478}, {450, 1.000275484}, {475, 1.000274653},
      {500, 1.000273949}, {525, 1.000273348}, {550, 1.000272831}, {575, 1.000272382},
      {600, 1.000271990}, {625, 1.000271646}, {650, 1.000271341}, {675, 1.000271071},
      {700, 1.000270830}};
  for (const auto& [nm, n] : kTable) {
    EXPECT_NEAR(refractive_index(at(20, 101325, 30, nm), Equation::edlen).n, n, 6e-10) << nm;
  }
  // The calculator's default conditions (20 degC, 101.325 kPa, 50 %RH) at 633 nm,
  // 1.000271374, as used in the NOVAC SpectralEvaluation tests.
  EXPECT_NEAR(refractive_index(at(20, 101325, 50), Equation::edlen).n, 1.000271374, 6e-10);
}

// Ciddor (1996), Appl. Opt. 35, 1566, Table 1 (dry air) and Table 3 (moist air), 633 nm,
// 450 umol/mol CO2, given as 1e8 (n - 1) to 0.1 (values as quoted in a public C++ unit
// test of the equation). Dry: tolerance 0.06e-8 (printed resolution). Moist: Ciddor used
// his own saturation vapour pressure formula, not IAPWS; tolerance 0.1e-8.
TEST(Air, CiddorMatchesCiddor1996Tables) {
  struct Row {
    double t_degc, p_pa, rh_pct, n_minus_1_e8, tol_e8;
  };
  constexpr Row kRows[] = {
      {20, 80000, 0, 21458.0, 0.06},   {20, 100000, 0, 26824.4, 0.06},
      {20, 120000, 0, 32191.6, 0.06},  {10, 100000, 0, 27774.7, 0.06},
      {30, 100000, 0, 25937.2, 0.06},  {20, 80000, 75, 21394.0, 0.1},
      {20, 120000, 75, 32127.8, 0.1},  {40, 120000, 75, 29941.8, 0.1},
      {50, 80000, 100, 19058.4, 0.1},  {50, 120000, 100, 28792.4, 0.1},
  };
  for (const auto& r : kRows) {
    const double n = refractive_index(at(r.t_degc, r.p_pa, r.rh_pct), Equation::ciddor).n;
    EXPECT_NEAR((n - 1.0) * 1e8, r.n_minus_1_e8, r.tol_e8) << r.t_degc << " " << r.p_pa << " "
                                                           << r.rh_pct;
  }
}

TEST(Air, CiddorStandardAirIsTheDispersionFormula) {
  // Ciddor (1996) defines standard air as dry, 15 degC, 101325 Pa, 450 umol/mol CO2, where
  // n - 1 = 0.05792105 / (238.0185 - σ²) + 0.00167917 / (57.362 - σ²), σ = 1/λ in 1/um
  // (as tabulated by refractiveindex.info). At 632.991 nm: 2.76530324127e-4; at 1550 nm:
  // 2.73260315767e-4 (evaluated by hand with a calculator).
  EXPECT_NEAR(refractive_index(at(15, 101325, 0, 632.991), Equation::ciddor).n - 1,
              2.76530324127e-4, 1e-11);
  EXPECT_NEAR(refractive_index(at(15, 101325, 0, 1550), Equation::ciddor).n - 1, 2.73260315767e-4,
              1e-11);
}

TEST(Air, ShopFloorEquationByHand) {
  // NIST shop-floor formula n = 1 + 7.86e-4 p/(273 + t) - 1.5e-11 RH (t² + 160), p in kPa:
  // 25 degC, 100 kPa, 40 %RH: 1 + 7.86e-4 x 100 / 298 - 1.5e-11 x 40 x 785 = 1.00026328739
  EXPECT_NEAR(refractive_index(at(25, 100000, 40), Equation::shop_floor).n, 1.00026328739, 1e-11);
  // And it agrees with Ciddor to within its stated 1.5e-7 near room conditions.
  for (double t : {18.0, 20.0, 24.0}) {
    const auto c = at(t, 100000, 45);
    EXPECT_NEAR(refractive_index(c, Equation::shop_floor).n,
                refractive_index(c, Equation::ciddor).n, 1.5e-7);
  }
}

TEST(Air, EdlenAndCiddorAgreeInTheLaboratory) {
  // NIST: the two equations agree to within about 1e-8 (less than their uncertainty) in
  // normal laboratory conditions at 633 nm.
  for (double t : {15.0, 20.0, 25.0}) {
    for (double p : {95000.0, 101325.0, 105000.0}) {
      for (double rh : {20.0, 50.0, 70.0}) {
        const auto c = at(t, p, rh);
        EXPECT_NEAR(refractive_index(c, Equation::edlen).n, refractive_index(c, Equation::ciddor).n,
                    1e-8)
            << t << " " << p << " " << rh;
      }
    }
  }
}

TEST(Air, SaturationVapourPressure) {
  // IAPWS-IF97 verification table (Table 35): T = 300 K -> ps = 0.353658941e-2 MPa,
  // T = 500 K -> 0.263889776e1 MPa.
  EXPECT_NEAR(saturation_vapour_pressure_water_pa(300.0 - 273.15), 3536.58941, 1e-4);
  EXPECT_NEAR(saturation_vapour_pressure_water_pa(500.0 - 273.15), 2.63889776e6, 1.0);
  // Over ice the equation is anchored at the triple point, 273.16 K: 611.657 Pa.
  EXPECT_NEAR(saturation_vapour_pressure_ice_pa(0.01), 611.657, 1e-9);
  // Vapour pressure of ice at -20 degC, CRC Handbook: 0.10326 kPa.
  EXPECT_NEAR(saturation_vapour_pressure_ice_pa(-20.0), 103.26, 0.05);
  // Below 0 degC the calculator uses ice, at and above water.
  EXPECT_DOUBLE_EQ(saturation_vapour_pressure_pa(-5.0), saturation_vapour_pressure_ice_pa(-5.0));
  EXPECT_DOUBLE_EQ(saturation_vapour_pressure_pa(5.0), saturation_vapour_pressure_water_pa(5.0));
  // Enhancement factor f = 1.00062 + 3.14e-8 p + 5.6e-7 t²: at 101325 Pa, 20 degC
  // 1.00062 + 0.0031816 + 0.000224 = 1.0040256
  EXPECT_NEAR(enhancement_factor(101325, 20), 1.0040256, 1e-7);
}

TEST(Air, HumidityAsRelativeDewPointOrPartialPressureAgree) {
  // NIST EMT A-II: pv = (RH/100) psv(t), or psv(td) for a dew point.
  Conditions rh = at(22, 100500, 0);
  const double psv_td = saturation_vapour_pressure_pa(10.0);
  rh.humidity = Humidity::relative_pct(100.0 * psv_td / saturation_vapour_pressure_pa(22.0));
  Conditions td = rh, pv = rh;
  td.humidity = Humidity::dew_point_degc(10.0);
  pv.humidity = Humidity::vapour_pressure_pa(psv_td);
  EXPECT_NEAR(water_vapour_pressure_pa(rh), psv_td, 1e-9);
  EXPECT_NEAR(water_vapour_pressure_pa(td), psv_td, 1e-9);
  for (auto eq : {Equation::edlen, Equation::ciddor}) {
    const double n = refractive_index(rh, eq).n;
    EXPECT_NEAR(refractive_index(pv, eq).n, n, 1e-14);
    // Ciddor's mole fraction takes f at the dew point for a dew point: a ~1e-11 effect.
    EXPECT_NEAR(refractive_index(td, eq).n, n, 1e-10);
  }
}

TEST(Air, Co2AndWavelengthDependence) {
  // NIST: a CO2 difference of 150 umol/mol changes n by about 2e-8.
  for (auto eq : {Equation::edlen, Equation::ciddor}) {
    Conditions c = at(20, 101325, 50);
    const double n450 = refractive_index(c, eq).n;
    c.co2_umol_per_mol = 600;
    EXPECT_NEAR(refractive_index(c, eq).n - n450, 2.2e-8, 0.3e-8) << to_string(eq);
  }
  // Normal dispersion: shorter wavelengths see a larger index.
  EXPECT_GT(refractive_index(at(20, 101325, 50, 532), Equation::ciddor).n,
            refractive_index(at(20, 101325, 50, 633), Equation::ciddor).n);
}

TEST(Air, OutOfRangeRefusedAndWarningRangeWarned) {
  auto message = [](const Conditions& c, Equation eq) -> std::string {
    try {
      refractive_index(c, eq);
    } catch (const cal::InputError& e) {
      return e.what();
    }
    return "";
  };
  EXPECT_NE(message(at(120, 101325, 50), Equation::ciddor).find("air temperature = 120 degC"),
            std::string::npos);
  EXPECT_NE(message(at(20, 5000, 50), Equation::edlen).find("pressure = 5000 Pa"),
            std::string::npos);
  EXPECT_NE(message(at(20, 101325, 50, 250), Equation::ciddor).find("wavelength"),
            std::string::npos);
  EXPECT_NE(message(at(20, 101325, 50, 532), Equation::shop_floor).find("shop-floor"),
            std::string::npos);
  EXPECT_NE(message(at(20, 101325, 101), Equation::ciddor).find("relative humidity = 101"),
            std::string::npos);
  Conditions wet = at(20, 101325, 50);
  wet.humidity = Humidity::dew_point_degc(25);
  EXPECT_NE(message(wet, Equation::edlen).find("dew point = 25"), std::string::npos);
  Conditions co2 = at(20, 101325, 50);
  co2.co2_umol_per_mol = 5000;
  EXPECT_NE(message(co2, Equation::ciddor).find("CO2"), std::string::npos);

  EXPECT_TRUE(refractive_index(at(20, 101325, 50), Equation::ciddor).warnings.empty());
  EXPECT_EQ(refractive_index(at(-10, 101325, 50), Equation::ciddor).warnings.size(), 1u);
  EXPECT_EQ(refractive_index(at(20, 50000, 50), Equation::ciddor).warnings.size(), 1u);
  EXPECT_EQ(refractive_index(at(20, 101325, 90), Equation::ciddor).warnings.size(), 1u);
  EXPECT_EQ(refractive_index(at(20, 101325, 50, 1064), Equation::edlen).warnings.size(), 1u);
  EXPECT_TRUE(refractive_index(at(20, 101325, 50, 1064), Equation::ciddor).warnings.empty());
  EXPECT_THROW(equation_from_string("lorentz"), cal::InputError);
}

}  // namespace
