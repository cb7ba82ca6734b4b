// Volumetric compensation from the model: the correction, its residual (the verification loop:
// inject known errors, compensate, apply, measure what remains) and the one-dimensional cross
// tables. Expected values are derived by hand in the comments from the conventions of
// kinematics.hpp, never taken from the code under test.
#include "cal/analysis/volumetric_comp.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include "../support/random_machine.hpp"
#include "cal/analysis/error.hpp"

namespace {

using namespace cal::kinematics;
using namespace cal::volcomp;
using cal::InputError;

ErrorFunction constant(double v) { return ErrorFunction::polynomial({v}); }
double norm(const Vec3& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }

void expect_near(const Vec3& got, const Vec3& want, double tol, const std::string& what = "") {
  for (std::size_t i = 0; i < 3; ++i) EXPECT_NEAR(got[i], want[i], tol) << what << " [" << i << "]";
}

// A positioning error E_XX = 0.01 um/mm (10 um/m). At x = 500 mm the error is 5 um and the
// correction -5 um; driven to x - 0.005 mm the machine errs by 0.01 * 499.995 = 4.99995 um, so
// the residual is -5 + 4.99995 = -5e-5 um: the slope times the correction, second order.
TEST(VolumetricCorrection, PositioningByHand) {
  Machine m;
  m.axes[X].ex_um = ErrorFunction::polynomial({0.0, 0.01});
  const Vec3 p{500.0, 100.0, 50.0};
  const Vec3 c = correction_um(m, p);
  expect_near(c, {-5.0, 0.0, 0.0}, 1e-12);
  expect_near(residual_um(m, p, c), {-5e-5, 0.0, 0.0}, 1e-10);  // 5 - 4.99995 cancels digits
}

// Squareness E_C0Y = 30 urad (Y leans to -X, x error -30e-3 y um). Carried by Y (default): the
// correction is x += 30e-3 y = 12 um at y = 400; what remains is the exact rotation's
// y (cos c - 1) = -400 * 4.5e-10 mm ~ -1.8e-4 um in y. Carried by X: y += 30e-3 x = 15 um at
// x = 500, and the residual is the rigid turn of the frame by c about Z, (-c y, c x, 0) =
// (-12, 15, 0) um, with the actual X and Y now square: X' = (1, c), Y = (-c, 1), X'.Y = 0.
TEST(VolumetricCorrection, SquarenessOnEitherCarrier) {
  Machine m;
  m.squareness.c0y_urad = 30.0;
  const Vec3 p{500.0, 400.0, 0.0};
  const Vec3 by_y = correction_um(m, p);
  expect_near(by_y, {12.0, 0.0, 0.0}, 1e-12);
  expect_near(residual_um(m, p, by_y), {0.0, 0.0, 0.0}, 5e-4);
  Carriers x_carries;
  x_carries.xy = X;
  const Vec3 by_x = correction_um(m, p, x_carries);
  expect_near(by_x, {0.0, 15.0, 0.0}, 1e-12);
  expect_near(residual_um(m, p, by_x), {-12.0, 15.0, 0.0}, 1e-3);
  // Square after correction: the residual along X alone and along Y alone are perpendicular
  // displacements of a rotation: unit travel X -> (1, c), Y -> (-c, 1).
  const Vec3 rx =
      residual_um(m, {1000.0, 0.0, 0.0}, correction_um(m, {1000.0, 0.0, 0.0}, x_carries));
  const Vec3 ry =
      residual_um(m, {0.0, 1000.0, 0.0}, correction_um(m, {0.0, 1000.0, 0.0}, x_carries));
  const double dot =
      (1000.0 + rx[0] * 1e-3) * (ry[0] * 1e-3) + (rx[1] * 1e-3) * (1000.0 + ry[1] * 1e-3);
  EXPECT_NEAR(dot / 1e6, 0.0, 1e-9);  // cos of the angle: < 1e-3 urad from 90 deg
  // E_B0Z and E_A0Z on Z (default) and on X / Y: z error terms by hand, b = 20, a = 10 urad,
  // p = (500, 400, 300): by Z, x -= b z = -6, y += a z = +3; by X and Y, z -= b x = -10 and
  // z += a y = +4.
  Machine n;
  n.squareness.b0z_urad = 20.0;
  n.squareness.a0z_urad = 10.0;
  const Vec3 q{500.0, 400.0, 300.0};
  expect_near(correction_um(n, q), {-6.0, 3.0, 0.0}, 1e-12);
  Carriers xy_carry;
  xy_carry.xz = X;
  xy_carry.yz = Y;
  expect_near(correction_um(n, q, xy_carry), {0.0, 0.0, -10.0 + 4.0}, 1e-12);
}

TEST(VolumetricCorrection, CarrierMustBeInItsPlane) {
  Carriers c;
  c.xy = Z;
  EXPECT_THROW(validate(c), InputError);
  EXPECT_THROW(correction_um(Machine{}, {0, 0, 0}, c), InputError);
  Carriers d;
  d.yz = X;
  try {
    validate(d);
    FAIL() << "no throw";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("E_A0Z"), std::string::npos) << e.what();
  }
}

using cal::test::random_machine;  // all 21 errors as cubics of realistic size
using cal::test::scaled;

struct LoopResult {
  double error_max_um = 0.0, residual_max_um = 0.0;
};

// The verification loop on a 5 x 5 x 5 grid over 800 x 600 x 500 mm: the exact (HTM) error of
// the machine before, and the exact residual after driving it to p + correction(p).
LoopResult loop(const Machine& m) {
  LoopResult r;
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 5; ++j) {
      for (int k = 0; k < 5; ++k) {
        const Vec3 p{200.0 * i, 150.0 * j, -125.0 * k};
        r.error_max_um = std::max(r.error_max_um, norm(volumetric_error_um(m, p, Method::htm)));
        r.residual_max_um =
            std::max(r.residual_max_um, norm(residual_um(m, p, correction_um(m, p))));
      }
    }
  }
  return r;
}

// The residual after compensation is second order in the errors: its terms are
// (1) the error's change over the correction, |de/dp| |c| ~ 1e-4 * 100 um ~ 0.01 um, and
// (2) the exact model minus the first order, ~ |eps|^2 L ~ (1e-4)^2 * 1000 mm ~ 0.01 um.
// Bound stated and checked: the largest residual is below 1e-3 of the largest error (observed:
// 0.004 to 0.015 um against 73 to 128 um, a ratio of 6e-5 to 1.2e-4), and doubling every error
// multiplies it by 4 (accepted 4 +- 0.1; the third-order terms change the ratio by ~|eps| * 4
// ~ 1e-3). On four topologies, one of them a horizontal machining centre (ZFXY).
TEST(VolumetricCorrection, VerificationLoopResidualIsSecondOrder) {
  for (Topology t : {Topology::fxyz, Topology::xyfz, Topology::yfxz, Topology::zfxy}) {
    const Machine base = random_machine(t, 100 + static_cast<std::uint64_t>(t));
    const LoopResult one = loop(base);
    const LoopResult two = loop(scaled(base, 2.0));
    const std::string name(to_string(t));
    EXPECT_GT(one.error_max_um, 20.0) << name;  // a machine with errors worth compensating
    EXPECT_LT(one.residual_max_um, 1e-3 * one.error_max_um) << name;
    EXPECT_NEAR(two.residual_max_um / one.residual_max_um, 4.0, 0.1) << name;
    RecordProperty(name + "_error_max_um", std::to_string(one.error_max_um));
    RecordProperty(name + "_residual_max_um", std::to_string(one.residual_max_um));
  }
}

// ---------------------------------------------------------------------------------------------
// Cross tables

std::array<AxisGrid, 3> grid_800_600_500() {
  return {AxisGrid{0.0, 100.0, 9}, AxisGrid{0.0, 100.0, 7}, AxisGrid{-500.0, 100.0, 6}};
}

// Without angular errors the error is a sum of one-axis functions, so the tables hold it all:
// E_XX = 0.01 x, E_YX = 2e-5 x^2 (a bow), E_ZY = 3 um, E_XZ = -0.004 z, E_C0Y = 15 urad.
// Sampled at 100 mm the bow's interpolation between nodes is off by at most
// 2e-5 * (100/2)^2 = 0.05 um, so the check is at nodes (exact) and between them within 0.05.
TEST(CrossTables, HoldEveryOneAxisErrorExactly) {
  Machine m;
  m.topology = Topology::yfxz;
  m.axes[X].ex_um = ErrorFunction::polynomial({0.0, 0.01});
  m.axes[X].ey_um = ErrorFunction::polynomial({0.0, 0.0, 2e-5});
  m.axes[Y].ez_um = constant(3.0);
  m.axes[Z].ex_um = ErrorFunction::polynomial({0.0, -0.004});
  m.squareness.c0y_urad = 15.0;
  const auto t = cross_tables(m, grid_800_600_500(), {400.0, 300.0, -200.0});
  ASSERT_EQ(t.tables.size(), 9u);
  // The X -> Y table is the correction of the bow, -2e-5 x^2 (relative to the reference:
  // the constant at x = 400, -3.2 um, is in Y's own table): at x = 800, -(12.8 - 3.2) = -9.6.
  EXPECT_NEAR(t.at(X, Y).correction_um.back(), -9.6, 1e-9);
  EXPECT_NEAR(t.at(Y, X).correction_um[4], 15e-3 * 400.0, 1e-9);  // squareness on Y: +c y
  for (const Vec3& p : {Vec3{0.0, 0.0, -500.0}, Vec3{800.0, 600.0, 0.0}, Vec3{300.0, 200.0, -100.0},
                        Vec3{350.0, 250.0, -150.0}}) {
    const Vec3 e = volumetric_error_um(m, p, Method::first_order);
    expect_near(table_correction_um(t, p), {-e[0], -e[1], -e[2]}, 0.05);
  }
  const Vec3 node{300.0, 200.0, -100.0};
  const Vec3 e = volumetric_error_um(m, node, Method::first_order);
  expect_near(table_correction_um(t, node), {-e[0], -e[1], -e[2]}, 1e-9);
}

// A yaw that varies along X, E_CX = 0.02 urad/mm (20 urad per metre), on FXYZ: the x error has
// the product -E_CX(x) (y + ty). Frozen at the reference (250, 200, 0), the tables leave
// -(E_CX(x) - E_CX(250)) (y - 200) e_x: at p = (450, 500, 0), -(0.02 * 200) * 300 * 1e-3 =
// -1.2 um in x, and nothing on the lines through the reference.
TEST(CrossTables, LeaveTheProductTermsFrozenAtTheReference) {
  Machine m;
  m.axes[X].ec_urad = ErrorFunction::polynomial({5.0, 0.02});
  m.tool_offset_mm = {0.0, 30.0, -100.0};
  const auto t = cross_tables(m, grid_800_600_500(), {250.0, 200.0, 0.0});
  auto left = [&](const Vec3& p) {
    const Vec3 e = volumetric_error_um(m, p, Method::first_order);
    const Vec3 c = table_correction_um(t, p);
    return Vec3{e[0] + c[0], e[1] + c[1], e[2] + c[2]};
  };
  expect_near(left({450.0, 500.0, 0.0}), {-1.2, 0.0, 0.0}, 1e-9);
  expect_near(left({700.0, 200.0, -300.0}), {0.0, 0.0, 0.0}, 1e-9);  // y at the reference
  expect_near(left({250.0, 600.0, -300.0}), {0.0, 0.0, 0.0}, 1e-9);  // x at the reference
}

TEST(CrossTables, BadGridsAndPositionsAreRefused) {
  Machine m;
  auto g = grid_800_600_500();
  EXPECT_THROW(cross_tables(m, g, {900.0, 0.0, 0.0}), InputError);  // reference outside X
  g[1].interval_mm = 0.0;
  EXPECT_THROW(cross_tables(m, g, {0.0, 0.0, 0.0}), InputError);
  g = grid_800_600_500();
  g[2].points = 1;
  EXPECT_THROW(cross_tables(m, g, {0.0, 0.0, -500.0}), InputError);
  g = grid_800_600_500();
  g[0].start_mm = std::nan("");
  EXPECT_THROW(cross_tables(m, g, {0.0, 0.0, 0.0}), InputError);
  const auto t = cross_tables(m, grid_800_600_500(), {0.0, 0.0, 0.0});
  EXPECT_THROW(table_correction_um(t, {801.0, 0.0, 0.0}), InputError);
  // A model table that does not cover the grid names the component.
  Machine short_table;
  const std::vector<double> q{0.0, 400.0}, v{0.0, 1.0};
  short_table.axes[X].ex_um = ErrorFunction::table(q, v);
  try {
    cross_tables(short_table, grid_800_600_500(), {0.0, 0.0, 0.0});
    FAIL() << "no throw";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("E_XX"), std::string::npos) << e.what();
  }
}

}  // namespace
