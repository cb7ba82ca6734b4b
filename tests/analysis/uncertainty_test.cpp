#include "cal/analysis/uncertainty.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "cal/analysis/error.hpp"

namespace {

using cal::unc::positioning_budget;
using cal::unc::PositioningSetup;

double component(const cal::unc::Budget& b, std::string_view name_start) {
  for (const auto& c : b.contributors)
    if (c.name.rfind(name_start, 0) == 0) return c.u_um;
  ADD_FAILURE() << "no contributor " << name_start;
  return NAN;
}

PositioningSetup hand_setup() {
  PositioningSetup s;
  s.length_m = 1.0;
  s.laser_cert_expanded_ppm = 0.1;  // U = 0.1 um at 1 m, k = 2 -> u = 0.05 um
  s.laser_cert_expanded_um = 0.0;
  s.u_air_temperature_k = 0.0;  // air sensors perfect: only the equation's 1e-8 remains
  s.u_pressure_pa = 0.0;
  s.u_humidity_pct = 0.0;
  s.material_degc = 21.2;
  s.alpha_per_k = 11.5e-6;
  s.u_material_temperature_k = 0.1;    // 1e6 um x 11.5e-6 x 0.1 = 1.15 um
  s.u_alpha_per_k = 1e-6;              // 1e6 um x 1.2 K x 1e-6 = 1.2 um
  s.environmental_variation_um = 0.5;  // 0.5 / (2 sqrt 3) = 0.1443376 um
  s.misalignment_offset_mm = 0.5;      // (500 um)^2 / (2e6 um) = 0.125 um; / (2 sqrt 3) = 0.0360844
  s.dead_path_m = 0.0;
  return s;
}

TEST(Uncertainty, HandCalculatedBudget) {
  const auto b = positioning_budget(hand_setup());
  EXPECT_NEAR(component(b, "laser"), 0.05, 1e-12);
  EXPECT_NEAR(component(b, "material temperature"), 1.15, 1e-12);
  EXPECT_NEAR(component(b, "expansion coefficient"), 1.2, 1e-9);
  EXPECT_NEAR(component(b, "environmental variation"), 0.1443376, 1e-7);
  EXPECT_NEAR(component(b, "misalignment"), 0.0360844, 1e-7);
  EXPECT_NEAR(component(b, "ciddor equation"), 0.01, 1e-12);
  EXPECT_NEAR(component(b, "air temperature"), 0.0, 1e-15);
  // sum of squares 0.0025 + 0.0001 + 1.3225 + 1.44 + 0.0208333 + 0.0013021 = 2.7872354
  // u_c = 1.6695015, U = 2 u_c = 3.3390031
  EXPECT_NEAR(b.u_combined_um, 1.6695015, 1e-6);
  EXPECT_NEAR(b.expanded_um, 3.3390031, 2e-6);
  EXPECT_DOUBLE_EQ(b.k, 2.0);
}

TEST(Uncertainty, AirSensitivitiesMatchTheShopFloorRuleOfThumb) {
  // Differentiating the NIST shop-floor equation n - 1 = 7.86e-4 p/(273 + t) - 1.5e-11 RH (t²+160)
  // at 20 degC, 101.325 kPa, 50 %RH gives dn/dt = -7.86e-4 x 101.325 / 293² - 1.5e-11 x 50 x 40
  // = -9.277e-7 - 3.0e-8 = -9.58e-7 /K, dn/dp = 7.86e-4 / 293 = 2.683e-9 /Pa and
  // dn/dRH = -1.5e-11 x 560 = -8.4e-9 /%. The Ciddor budget must agree within 3 %.
  auto s = hand_setup();
  s.u_air_temperature_k = 1.0;
  s.u_pressure_pa = 1.0;
  s.u_humidity_pct = 1.0;
  const auto b = positioning_budget(s);
  EXPECT_NEAR(component(b, "air temperature"), 0.958, 0.03 * 0.958);
  EXPECT_NEAR(component(b, "air pressure"), 0.002683, 0.03 * 0.002683);
  EXPECT_NEAR(component(b, "humidity"), 0.0084, 0.1 * 0.0084);  // RH term differs by equation
}

TEST(Uncertainty, DeadPathCorrectedOrNot) {
  auto s = hand_setup();
  s.dead_path_m = 0.2;
  s.dead_path_corrected = false;
  s.index_change_during_test = 1e-6;  // about 1 K of air temperature change
  // 0.2e6 um x 1e-6 / sqrt 3 = 0.1154701 um
  EXPECT_NEAR(component(positioning_budget(s), "dead path"), 0.1154701, 1e-7);
  s.dead_path_corrected = true;
  // Corrected: d u(n), u(n) = the equation's 1e-8 here -> 0.002 um
  EXPECT_NEAR(component(positioning_budget(s), "dead path"), 0.002, 1e-9);
}

TEST(Uncertainty, BadSetupsAreRefused) {
  auto s = hand_setup();
  s.length_m = 0;
  EXPECT_THROW(positioning_budget(s), cal::InputError);
  s = hand_setup();
  s.u_pressure_pa = -1;
  EXPECT_THROW(positioning_budget(s), cal::InputError);
  s = hand_setup();
  s.air.temperature_degc = 150;  // outside the Ciddor range
  EXPECT_THROW(positioning_budget(s), cal::InputError);
}

}  // namespace
