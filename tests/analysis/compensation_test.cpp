#include "cal/analysis/compensation.hpp"

#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "cal/analysis/error.hpp"

namespace {

using namespace cal::comp;

TEST(Compensation, CountsToVacuumDisplacement) {
  // Linear interferometer: one count per fringe = lambda / 2 = 316.4955 nm;
  // 1e6 counts = 0.3164955 m.
  EXPECT_NEAR(vacuum_displacement_m(1'000'000, {632.991, 1, 1.0}), 0.3164955, 1e-15);
  // Plane mirror (2 passes), 4 counts per fringe: 632.991 / 4 / 4 = 39.5619375 nm per count.
  EXPECT_NEAR(vacuum_displacement_m(-1000, {632.991, 2, 4.0}), -39.5619375e-6, 1e-18);
  EXPECT_THROW(vacuum_displacement_m(1, {632.991, 0, 1.0}), cal::InputError);
}

TEST(Compensation, AirLengthAndDeadPath) {
  // 1 / 1.00027 = 0.99973007288032 (long division)
  EXPECT_NEAR(air_length_m(1.0, 1.00027), 0.99973007288032, 1e-14);
  // Datum set at n0 = 1.000271; now n = 1.000270. The reading carries d (n - n0) / n
  // = 0.5 m x (-1e-6) / 1.00027 = -4.99865036e-7 m, so the correction adds 4.99865036e-7 m.
  EXPECT_NEAR(dead_path_corrected_m(0.2, 0.5, 1.000271, 1.000270), 0.2 + 4.99865036e-7, 1e-15);
  EXPECT_DOUBLE_EQ(dead_path_corrected_m(0.2, 0.0, 1.000271, 1.000270), 0.2);
  EXPECT_THROW(dead_path_corrected_m(0.2, -0.1, 1.0, 1.0), cal::InputError);
}

TEST(Compensation, MaterialSensorsAveragedAndDisabled) {
  std::vector<MaterialSensor> s{{"bed", 20.4, true}, {"screw", 21.0, true}, {"loose", 35.0, false}};
  EXPECT_DOUBLE_EQ(material_temperature_degc(s), 20.7);
  s[1].enabled = false;
  EXPECT_DOUBLE_EQ(material_temperature_degc(s), 20.4);
  s[0].enabled = false;
  EXPECT_THROW(material_temperature_degc(s), cal::InputError);
  s[0] = {"bed", std::numeric_limits<double>::quiet_NaN(), true};
  try {
    material_temperature_degc(s);
    FAIL();
  } catch (const cal::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'bed'"), std::string::npos);
  }
}

TEST(Compensation, ThermalNormalisationTo20C) {
  // Steel at 25 degC: 1 m / (1 + 11.5e-6 x 5) = 1 / 1.0000575 = 0.99994250331 m
  EXPECT_NEAR(normalise_to_20c_m(1.0, 11.5e-6, 25.0), 0.99994250331, 1e-11);
  EXPECT_DOUBLE_EQ(normalise_to_20c_m(0.7, 11.5e-6, 20.0), 0.7);
}

TEST(Compensation, CombinedFactorInPpm) {
  // n = 1.00027, steel 11.5 ppm/K at 20 degC: air (1/n - 1) 1e6 = -269.927120 ppm, material 0.
  auto f = combined_factor(1.00027, 11.5e-6, 20.0);
  EXPECT_NEAR(f.air_ppm, -269.92712, 1e-5);
  EXPECT_NEAR(f.material_ppm, 0.0, 1e-12);
  EXPECT_NEAR(f.total_ppm, f.air_ppm, 1e-9);
  // Material at 25 degC adds 1/1.0000575 - 1 = -57.496694 ppm; the total is the product
  // 0.99973007288 x 0.99994250331 - 1 = -327.408293 ppm (not the sum, -327.42381).
  f = combined_factor(1.00027, 11.5e-6, 25.0);
  EXPECT_NEAR(f.material_ppm, -57.496694, 1e-5);
  EXPECT_NEAR(f.total_ppm, -327.408293, 1e-5);
  EXPECT_THROW(combined_factor(0.999, 11.5e-6, 20.0), cal::InputError);
  EXPECT_THROW(combined_factor(1.00027, 0.5, 20.0), cal::InputError);
}

}  // namespace
