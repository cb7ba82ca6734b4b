// Tests of the rigid-body kinematic model. Every expected value is derived by hand in the
// comment next to it from the conventions of kinematics.hpp (or from the exact rotation
// matrices written out in the test), never taken from the code under test.
#include "cal/analysis/kinematics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <set>
#include <string>

#include "../support/random_machine.hpp"
#include "cal/analysis/error.hpp"
#include "cal/analysis/squareness.hpp"

namespace {

using namespace cal::kinematics;
using cal::InputError;

constexpr std::array kMethods{Method::htm, Method::first_order};

ErrorFunction constant(double v) { return ErrorFunction::polynomial({v}); }

void expect_near(const Vec3& got, const Vec3& want, double tol, const std::string& what = "") {
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(got[i], want[i], tol) << what << " component " << i;
  }
}

double norm(const Vec3& v) { return std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]); }
Vec3 minus(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }

// ---------------------------------------------------------------------------------------------
// Error functions

TEST(KinematicsErrorFunction, PolynomialByHand) {
  // 1 + 2 q + 3 q^2: at q = 2, 1 + 4 + 12 = 17; at q = -1, 1 - 2 + 3 = 2.
  const auto f = ErrorFunction::polynomial({1.0, 2.0, 3.0});
  EXPECT_DOUBLE_EQ(f(2.0), 17.0);
  EXPECT_DOUBLE_EQ(f(-1.0), 2.0);
  EXPECT_DOUBLE_EQ(ErrorFunction{}(123.0), 0.0);  // default: zero
  // scaled(3): 3 + 6 q + 9 q^2 at q = 1 is 18.
  EXPECT_DOUBLE_EQ(f.scaled(3.0)(1.0), 18.0);
}

TEST(KinematicsErrorFunction, TableInterpolatesLinearlyAndRefusesExtrapolation) {
  const std::vector<double> q{0.0, 100.0, 200.0}, v{0.0, 10.0, -10.0};
  const auto f = ErrorFunction::table(q, v);
  EXPECT_DOUBLE_EQ(f(0.0), 0.0);
  EXPECT_DOUBLE_EQ(f(50.0), 5.0);             // halfway between 0 and 10
  EXPECT_DOUBLE_EQ(f(100.0), 10.0);           // a node
  EXPECT_DOUBLE_EQ(f(150.0), 0.0);            // halfway between 10 and -10
  EXPECT_DOUBLE_EQ(f(175.0), -5.0);           // three quarters from 10 to -10
  EXPECT_DOUBLE_EQ(f(200.0), -10.0);          // the last node
  EXPECT_DOUBLE_EQ(f(200.0 + 1e-12), -10.0);  // rounding at the end is not extrapolation
  EXPECT_DOUBLE_EQ(f.scaled(-2.0)(50.0), -10.0);
  EXPECT_THROW(f(200.5), InputError);
  EXPECT_THROW(f(-0.1), InputError);
  try {
    f(250.0);
    FAIL() << "no throw";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("250"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("outside"), std::string::npos) << e.what();
  }
}

TEST(KinematicsErrorFunction, BadInputIsRefused) {
  const std::vector<double> two{0.0, 1.0}, three{0.0, 1.0, 2.0}, one{0.0};
  const std::vector<double> flat{0.0, 1.0, 1.0}, nan_v{0.0, std::nan("")};
  const std::vector<double> none;
  EXPECT_THROW(ErrorFunction::table(two, three), InputError);   // sizes differ
  EXPECT_THROW(ErrorFunction::table(one, one), InputError);     // one point
  EXPECT_THROW(ErrorFunction::table(flat, three), InputError);  // not strictly increasing
  EXPECT_THROW(ErrorFunction::table(two, nan_v), InputError);   // value not finite
  EXPECT_THROW(ErrorFunction::table(nan_v, two), InputError);   // position not finite
  EXPECT_THROW(ErrorFunction::polynomial(none), InputError);
  EXPECT_THROW(ErrorFunction::polynomial({1.0, std::numeric_limits<double>::infinity()}),
               InputError);
}

// ---------------------------------------------------------------------------------------------
// Names

TEST(KinematicsNames, ComponentsAndTopologies) {
  std::set<std::string> names;
  for (Component c : all_components()) {
    names.insert(std::string(to_string(c)));
    EXPECT_EQ(component_from_string(to_string(c)), c);
  }
  EXPECT_EQ(names.size(), 18u);
  EXPECT_EQ(to_string(Component::E_CX), "E_CX");
  EXPECT_EQ(component_from_string("ecx"), Component::E_CX);  // controller spelling
  EXPECT_EQ(component_from_string("e_ay"), Component::E_AY);
  EXPECT_THROW(component_from_string("E_QX"), InputError);
  EXPECT_THROW(component_from_string("E_XXX"), InputError);
  // The enum reaches the right member: E_AY is the rotation about X of the Y axis, E_ZX the
  // Z straightness of X.
  Machine m;
  EXPECT_EQ(&component(m, Component::E_AY), &m.axes[Y].ea_urad);
  EXPECT_EQ(&component(m, Component::E_ZX), &m.axes[X].ez_um);
  EXPECT_EQ(&component(m, Component::E_BZ), &m.axes[Z].eb_urad);

  EXPECT_EQ(topology_from_string("xfyz"), Topology::xfyz);
  EXPECT_EQ(to_string(Topology::xyzf), "XYZF");
  EXPECT_EQ(workpiece_side_axes(Topology::fxyz), 0);
  EXPECT_EQ(workpiece_side_axes(Topology::xyfz), 2);
  // All 24 orders of F, X, Y, Z exist, each once; other strings are refused.
  std::set<std::string> topologies;
  for (Topology t : all_topologies()) {
    const std::string name(to_string(t));
    topologies.insert(name);
    EXPECT_EQ(topology_from_string(name), t);
    EXPECT_EQ(std::string(name).find('F'), static_cast<std::size_t>(workpiece_side_axes(t)));
  }
  EXPECT_EQ(topologies.size(), 24u);
  EXPECT_EQ(all_topologies().size(), 24u);
  // The first four keep their numeric values (stored configurations, seeds of the tests).
  EXPECT_EQ(static_cast<int>(Topology::fxyz), 0);
  EXPECT_EQ(static_cast<int>(Topology::xyzf), 3);
  EXPECT_EQ(topology_from_string("yfxz"), Topology::yfxz);
  EXPECT_EQ(workpiece_side_axes(Topology::yfxz), 1);
  EXPECT_EQ(chain_order(Topology::yfxz), (std::array<Axis, 3>{Y, X, Z}));
  EXPECT_EQ(chain_order(Topology::zfxy), (std::array<Axis, 3>{Z, X, Y}));
  EXPECT_EQ(chain_order(Topology::xyzf), (std::array<Axis, 3>{X, Y, Z}));
  EXPECT_THROW(topology_from_string("FXXZ"), InputError);   // X twice, no Y
  EXPECT_THROW(topology_from_string("XYZ"), InputError);    // no frame
  EXPECT_THROW(topology_from_string("FXYZF"), InputError);  // five letters
}

// ---------------------------------------------------------------------------------------------
// Single terms, derived by hand

// A pure positioning error appears 1:1 in its own direction, in every topology and by both
// methods (no rotation: the HTM product is a sum of translations). E_XX = 0.01 um/mm at
// x = 300 is 3 um; E_YY = 1.5 um; E_ZZ = 1e-5 um/mm^2 * 200^2 = 0.4 um. Tolerance: rounding
// of mm-sized doubles, ~1e-13 mm = 1e-10 um.
TEST(KinematicsVolumetric, PositioningErrorsAppearOneToOne) {
  for (Topology t : all_topologies()) {
    Machine m;
    m.topology = t;
    m.axes[X].ex_um = ErrorFunction::polynomial({0.0, 0.01});
    m.axes[Y].ey_um = constant(1.5);
    m.axes[Z].ez_um = ErrorFunction::polynomial({0.0, 0.0, 1e-5});
    m.tool_offset_mm = {5.0, -3.0, -120.0};
    m.table_offset_mm = {-200.0, 80.0, 10.0};
    for (Method method : kMethods) {
      expect_near(volumetric_error_um(m, {300.0, -150.0, 200.0}, method), {3.0, 1.5, 0.4}, 1e-9,
                  std::string(to_string(t)));
    }
  }
}

// Abbe error of the X yaw on the tool side (FXYZ). E_CX = 20 urad, tool offset (0, 0, -100),
// position (100, 200, 50). The X carriage carries Y and Z, so its arm is the vector from its
// reference point to the tool tip: a = (tx, y + ty, z + tz) = (0, 200, -50) mm.
// First order: eps x a = (eb az - ec ay, ec ax - ea az, ea ay - eb ax) = (-ec ay, 0, 0)
//   = (-20e-6 * 200 mm, 0, 0) = (-4 um, 0, 0): the x error is -E_CX * (y + ty).
// Exact: tip = (x, 0, 0) + Rz(ec) a, nominal = (x, 0, 0) + a, so
//   e = (-200 sin ec, 200 (cos ec - 1), 0) mm.
TEST(KinematicsVolumetric, AbbeOfXYawOnToolSide) {
  Machine m;
  m.axes[X].ec_urad = constant(20.0);
  m.tool_offset_mm = {0.0, 0.0, -100.0};
  const Vec3 p{100.0, 200.0, 50.0};
  expect_near(volumetric_error_um(m, p, Method::first_order), {-4.0, 0.0, 0.0}, 1e-12);
  const double ec = 20e-6;
  expect_near(volumetric_error_um(m, p, Method::htm),
              {-200.0 * std::sin(ec) * 1e3, 200.0 * (std::cos(ec) - 1.0) * 1e3, 0.0}, 1e-9);
  const auto r = volumetric_error(m, p, Method::htm);
  expect_near(r.rotation_urad, {0.0, 0.0, 20.0}, 1e-9);
}

// The same yaw when X moves the table (XFYZ): the rotation is about the table reference point,
// so the arm is the whole vector from there to the tool tip, p + table + tool. With table
// offset (-300, 50, 0), tool (0, 0, -100), p = (100, 200, 50):
//   a = (100 - 300, 200 + 50, 50 - 100) = (-200, 250, -50) mm,
//   first order eps x a = (-ec ay, ec ax, 0) = (-20e-6 * 250, 20e-6 * -200, 0) mm = (-5, -4, 0) um.
// Exact: tip = Rz(ec) a, nominal = a: e = (ax (c - 1) - ay s, ax s + ay (c - 1), 0).
TEST(KinematicsVolumetric, AbbeOfXYawOnTableSide) {
  Machine m;
  m.topology = Topology::xfyz;
  m.axes[X].ec_urad = constant(20.0);
  m.tool_offset_mm = {0.0, 0.0, -100.0};
  m.table_offset_mm = {-300.0, 50.0, 0.0};
  const Vec3 p{100.0, 200.0, 50.0};
  expect_near(volumetric_error_um(m, p, Method::first_order), {-5.0, -4.0, 0.0}, 1e-12);
  const double s = std::sin(20e-6), c = std::cos(20e-6), ax = -200.0, ay = 250.0;
  expect_near(volumetric_error_um(m, p, Method::htm),
              {(ax * (c - 1) - ay * s) * 1e3, (ax * s + ay * (c - 1)) * 1e3, 0.0}, 1e-9);
}

// Pitch of Y (E_AY, about X) with a tool length and a lateral offset, FXYZ. The Y carriage
// carries Z: arm a = (tx, ty, z + tz). Tool (0, 20, -150), z = 100: a = (0, 20, -50).
// First order eps x a with eps = (ea, 0, 0): (0, -ea az, ea ay) = (0, 30e-6*50, 30e-6*20) mm
//   = (0, 1.5, 0.6) um: the y error is -E_AY * (z + tz), the z error +E_AY * ty.
// Exact: Rx(ea) a - a = (0, ay (c - 1) - az s, ay s + az (c - 1)).
TEST(KinematicsVolumetric, PitchOfYWithToolOffsets) {
  Machine m;
  m.axes[Y].ea_urad = constant(30.0);
  m.tool_offset_mm = {0.0, 20.0, -150.0};
  const Vec3 p{-40.0, 250.0, 100.0};
  expect_near(volumetric_error_um(m, p, Method::first_order), {0.0, 1.5, 0.6}, 1e-12);
  const double s = std::sin(30e-6), c = std::cos(30e-6), ay = 20.0, az = -50.0;
  expect_near(volumetric_error_um(m, p, Method::htm),
              {0.0, (ay * (c - 1) - az * s) * 1e3, (ay * s + az * (c - 1)) * 1e3}, 1e-9);
}

// Squareness, p = (100, 400, 300), E_C0Y = 50, E_B0Z = 40, E_A0Z = 25 urad. Directions
// u_Y = Rz(c)(0,1,0) = (-sin c, cos c, 0), u_Z = Ry(b)Rx(a)(0,0,1) = (cos a sin b, -sin a,
// cos a cos b). First order: e_x = -c y + b z = -0.020 + 0.012 mm = -8 um, e_y = -a z =
// -7.5 um, e_z = 0. Exact: e = y (u_Y - (0,1,0)) + z (u_Z - (0,0,1)). Same in all topologies.
TEST(KinematicsVolumetric, SquarenessSigns) {
  const double c = 50e-6, b = 40e-6, a = 25e-6, y = 400.0, z = 300.0;
  const Vec3 exact{(-y * std::sin(c) + z * std::cos(a) * std::sin(b)) * 1e3,
                   (y * (std::cos(c) - 1) - z * std::sin(a)) * 1e3,
                   z * (std::cos(a) * std::cos(b) - 1) * 1e3};
  for (Topology t : all_topologies()) {
    Machine m;
    m.topology = t;
    m.squareness = {50.0, 40.0, 25.0};
    m.tool_offset_mm = {0.0, 0.0, -100.0};
    m.table_offset_mm = {10.0, 20.0, 30.0};
    const Vec3 p{100.0, y, z};
    expect_near(volumetric_error_um(m, p, Method::first_order), {-8.0, -7.5, 0.0}, 1e-12);
    expect_near(volumetric_error_um(m, p, Method::htm), exact, 1e-9);
  }
}

// Where F sits changes the Abbe arms. E_BX = 40 urad (pitch of X, about Y), p = (500, 0, 0),
// no offsets. X on the tool side (left of F in the name: FXYZ, YFXZ, ...): X's reference point
// moves with it and the other axes are at 0, arm = (0, 0, 0): no error. With X on the table
// side the arm is the table travel (500, 0, 0):
// eps x a = (0, 0, -eb ax) = (0, 0, -40e-6 * 500 mm) = (0, 0, -20 um).
TEST(KinematicsVolumetric, TopologyChangesArms) {
  for (Topology t : all_topologies()) {
    Machine m;
    m.topology = t;
    m.axes[X].eb_urad = constant(40.0);
    const std::string name(to_string(t));
    const double ez = name.find('X') < name.find('F') ? -20.0 : 0.0;
    expect_near(volumetric_error_um(m, {500.0, 0.0, 0.0}, Method::first_order), {0.0, 0.0, ez},
                1e-12, std::string(to_string(t)));
    // Second order (40e-6)^2 * 500 mm / 2 = 4e-7 mm: 1e-3 um is a safe bound.
    expect_near(volumetric_error_um(m, {500.0, 0.0, 0.0}, Method::htm), {0.0, 0.0, ez}, 1e-3,
                std::string(to_string(t)));
  }
}

// A machine with all 21 errors as distinct constants (so every product is identifiable).
Machine constant_machine(Topology t) {
  Machine m;
  m.topology = t;
  double v = 1.0;
  for (Component c : all_components()) {
    component(m, c) = constant(v);  // E_XX = 1, E_YX = 2, ... E_CZ = 18 (um or urad)
    v += 1.0;
  }
  m.squareness = {19.0, 20.0, 21.0};
  m.tool_offset_mm = {7.0, -11.0, -130.0};
  m.table_offset_mm = {-210.0, 90.0, 40.0};
  return m;
}

// The first-order formula of docs/kinematics.md written out term by term for FXYZ and XYZF,
// independently of the arm loop in the code. Values in um and urad; urad * mm = 1e-3 um.
// Constants (constant_machine): translations E_XX=1 E_YX=2 E_ZX=3 | E_XY=7 E_YY=8 E_ZY=9 |
// E_XZ=13 E_YZ=14 E_ZZ=15; rotations (ea, eb, ec): X (4, 5, 6), Y (10, 11, 12), Z (16, 17, 18);
// E_C0Y = 19, E_B0Z = 20, E_A0Z = 21.
TEST(KinematicsVolumetric, FirstOrderClosedFormFXYZ) {
  const Machine m = constant_machine(Topology::fxyz);
  const double x = 120.0, y = -60.0, z = 240.0, tx = 7.0, ty = -11.0, tz = -130.0;
  const double k = 1e-3;
  // FXYZ arms: X -> (tx, y + ty, z + tz), Y -> (tx, ty, z + tz), Z -> (tx, ty, tz).
  const double ex = 1 + 7 + 13 + k * (5 * (z + tz) - 6 * (y + ty))  // X: eb az - ec ay
                    + k * (11 * (z + tz) - 12 * ty)                 // Y
                    + k * (17 * tz - 18 * ty)                       // Z
                    + k * (-19 * y + 20 * z);                       // -C0Y y + B0Z z
  const double ey = 2 + 8 + 14 + k * (6 * tx - 4 * (z + tz))        // X: ec ax - ea az
                    + k * (12 * tx - 10 * (z + tz))                 // Y
                    + k * (18 * tx - 16 * tz)                       // Z
                    + k * (-21 * z);                                // -A0Z z
  const double ez = 3 + 9 + 15 + k * (4 * (y + ty) - 5 * tx)        // X: ea ay - eb ax
                    + k * (10 * ty - 11 * tx)                       // Y
                    + k * (16 * ty - 17 * tx);                      // Z
  const auto r = volumetric_error(m, {x, y, z}, Method::first_order);
  expect_near(r.translation_um, {ex, ey, ez}, 1e-9);
  expect_near(r.rotation_urad, {4 + 10 + 16, 5 + 11 + 17, 6 + 12 + 18}, 1e-12);
}

TEST(KinematicsVolumetric, FirstOrderClosedFormXYZF) {
  const Machine m = constant_machine(Topology::xyzf);
  const double x = 120.0, y = -60.0, z = 240.0, k = 1e-3;
  // All axes carry the workpiece; each arm runs from the table reference point to the tool
  // tip and includes the travel of the axis itself and of the axes nearer the frame:
  // X -> p + w + t, Y -> (0, y, z) + w + t, Z -> (0, 0, z) + w + t, with w + t = (-203, 79, -90).
  const double sx = -203.0, sy = 79.0, sz = -90.0;
  const double ex = 1 + 7 + 13 + k * (5 * (z + sz) - 6 * (y + sy)) +
                    k * (11 * (z + sz) - 12 * (y + sy)) + k * (17 * (z + sz) - 18 * sy) +
                    k * (-19 * y + 20 * z);
  const double ey = 2 + 8 + 14 + k * (6 * (x + sx) - 4 * (z + sz)) + k * (12 * sx - 10 * (z + sz)) +
                    k * (18 * sx - 16 * (z + sz)) + k * (-21 * z);
  const double ez = 3 + 9 + 15 + k * (4 * (y + sy) - 5 * (x + sx)) + k * (10 * (y + sy) - 11 * sx) +
                    k * (16 * sy - 17 * sx);
  expect_near(volumetric_error_um(m, {x, y, z}, Method::first_order), {ex, ey, ez}, 1e-9);
}

// XYFZ (cross table: Y on the bed carries X carries the work; Z head on the column), the
// topology of the classic knee-type and bed-type vertical mills. Both table axes rotate about
// the table reference point, so their arms run from there to the tool tip; Y's arm leaves out
// X, which Y carries below it:
//   a_X = (x, y, z) + w + t,  a_Y = (0, y, z) + w + t,  a_Z = t,   w + t = (-203, 79, -90).
// Written out with (eps x a) = (eb az - ec ay, ec ax - ea az, ea ay - eb ax):
TEST(KinematicsVolumetric, FirstOrderClosedFormXYFZ) {
  const Machine m = constant_machine(Topology::xyfz);
  const double x = 120.0, y = -60.0, z = 240.0, k = 1e-3;
  const double tx = 7.0, ty = -11.0, tz = -130.0, sx = -203.0, sy = 79.0, sz = -90.0;
  const double ex = 1 + 7 + 13 + k * (5 * (z + sz) - 6 * (y + sy))  // X
                    + k * (11 * (z + sz) - 12 * (y + sy))           // Y
                    + k * (17 * tz - 18 * ty)                       // Z
                    + k * (-19 * y + 20 * z);                       // squareness
  const double ey = 2 + 8 + 14 + k * (6 * (x + sx) - 4 * (z + sz))  // X
                    + k * (12 * sx - 10 * (z + sz))                 // Y
                    + k * (18 * tx - 16 * tz)                       // Z
                    + k * (-21 * z);
  const double ez = 3 + 9 + 15 + k * (4 * (y + sy) - 5 * (x + sx))  // X
                    + k * (10 * (y + sy) - 11 * sx)                 // Y
                    + k * (16 * ty - 17 * tx);                      // Z
  expect_near(volumetric_error_um(m, {x, y, z}, Method::first_order), {ex, ey, ez}, 1e-9);
}

// YFXZ: the Makino S33 vertical machining centre of the calibration study this project comes
// from (table in Y on the bed; the spindle moves in X, and the X carriage carries the Z ram).
// Chain order Y | X, Z with one table axis, so
//   a_Y = (x, y, z) + w + t   (Y rotates the table about its reference point),
//   a_X = (0, 0, z) + t       (X carries Z: its arm is Z's travel plus the tool),
//   a_Z = t.
// Written out, with t = (7, -11, -130) and w + t = (-203, 79, -90):
//   e_x = E_XX + E_XY + E_XZ + E_BX (z + tz) - E_CX ty + E_BY (z + sz) - E_CY (y + sy)
//         + E_BZ tz - E_CZ ty - E_C0Y y + E_B0Z z
//   e_y = E_YX + E_YY + E_YZ + E_CX tx - E_AX (z + tz) + E_CY (x + sx) - E_AY (z + sz)
//         + E_CZ tx - E_AZ tz - E_A0Z z
//   e_z = E_ZX + E_ZY + E_ZZ + E_AX ty - E_BX tx + E_AY (y + sy) - E_BY (x + sx)
//         + E_AZ ty - E_BZ tx
// Compared with FXYZ (X carries Y carries Z), X loses the y Abbe arm in its yaw (-E_CX ty
// instead of -E_CX (y + ty)) and Y's yaw gains x: the table's yaw turns the workpiece under a
// tool that stands x away.
TEST(KinematicsVolumetric, FirstOrderClosedFormYFXZ) {
  const Machine m = constant_machine(Topology::yfxz);
  const double x = 120.0, y = -60.0, z = 240.0, k = 1e-3;
  const double tx = 7.0, ty = -11.0, tz = -130.0, sx = -203.0, sy = 79.0, sz = -90.0;
  const double ex = 21 + k * (5 * (z + tz) - 6 * ty)       // X: E_BX (z + tz) - E_CX ty
                    + k * (11 * (z + sz) - 12 * (y + sy))  // Y: E_BY (z + sz) - E_CY (y + sy)
                    + k * (17 * tz - 18 * ty)              // Z
                    + k * (-19 * y + 20 * z);              // squareness
  const double ey = 24 + k * (6 * tx - 4 * (z + tz))       // X: E_CX tx - E_AX (z + tz)
                    + k * (12 * (x + sx) - 10 * (z + sz))  // Y: E_CY (x + sx) - E_AY (z + sz)
                    + k * (18 * tx - 16 * tz)              // Z
                    + k * (-21 * z);
  const double ez = 27 + k * (4 * ty - 5 * tx)             // X: E_AX ty - E_BX tx
                    + k * (10 * (y + sy) - 11 * (x + sx))  // Y: E_AY (y + sy) - E_BY (x + sx)
                    + k * (16 * ty - 17 * tx);             // Z
  const auto r = volumetric_error(m, {x, y, z}, Method::first_order);
  expect_near(r.translation_um, {ex, ey, ez}, 1e-9);
  expect_near(r.rotation_urad, {4 + 10 + 16, 5 + 11 + 17, 6 + 12 + 18}, 1e-12);
}

// ZFXY, a horizontal machining centre: the table moves in Z towards the spindle, the column
// moves in X and carries the head in Y. Arms: a_Z = (x, y, z) + w + t, a_X = (0, y, 0) + t,
// a_Y = t.
TEST(KinematicsVolumetric, FirstOrderClosedFormZFXY) {
  const Machine m = constant_machine(Topology::zfxy);
  const double x = 120.0, y = -60.0, z = 240.0, k = 1e-3;
  const double tx = 7.0, ty = -11.0, tz = -130.0, sx = -203.0, sy = 79.0, sz = -90.0;
  const double ex = 21 + k * (5 * tz - 6 * (y + ty))       // X: E_BX tz - E_CX (y + ty)
                    + k * (11 * tz - 12 * ty)              // Y
                    + k * (17 * (z + sz) - 18 * (y + sy))  // Z on the table
                    + k * (-19 * y + 20 * z);
  const double ey = 24 + k * (6 * tx - 4 * tz)             // X
                    + k * (12 * tx - 10 * tz)              // Y
                    + k * (18 * (x + sx) - 16 * (z + sz))  // Z
                    + k * (-21 * z);
  const double ez = 27 + k * (4 * (y + ty) - 5 * tx)        // X
                    + k * (10 * ty - 11 * tx)               // Y
                    + k * (16 * (y + sy) - 17 * (x + sx));  // Z
  expect_near(volumetric_error_um(m, {x, y, z}, Method::first_order), {ex, ey, ez}, 1e-9);
}

// The exact model of YFXZ for single errors, against rotation matrices written out here.
// Roll of X, E_AX = 30 urad: X is on the tool side and carries Z, arm a = (tx, ty, z + tz)
// = (5, 20, 250 - 100) = (5, 20, 150); the tip moves by Rx(ea) a - a
//   = (0, ay (c - 1) - az s, ay s + az (c - 1)).
// Yaw of the table axis Y, E_CY = 25 urad: the table turns about its reference point, arm
// a = p + w + t = (300 + 40, 200 - 60, 250 - 100) = (340, 140, 150); Rz(ec) a - a
//   = (ax (c - 1) - ay s, ax s + ay (c - 1), 0).
TEST(KinematicsVolumetric, ExactSingleTermsYFXZ) {
  const Vec3 p{300.0, 200.0, 250.0};
  Machine roll;
  roll.topology = Topology::yfxz;
  roll.axes[X].ea_urad = constant(30.0);
  roll.tool_offset_mm = {5.0, 20.0, -100.0};
  roll.table_offset_mm = {40.0, -80.0, 0.0};
  {
    const double s = std::sin(30e-6), c = std::cos(30e-6), ay = 20.0, az = 150.0;
    expect_near(volumetric_error_um(roll, p, Method::htm),
                {0.0, (ay * (c - 1) - az * s) * 1e3, (ay * s + az * (c - 1)) * 1e3}, 1e-9);
  }
  Machine yaw;
  yaw.topology = Topology::yfxz;
  yaw.axes[Y].ec_urad = constant(25.0);
  yaw.tool_offset_mm = {0.0, 0.0, -100.0};
  yaw.table_offset_mm = {40.0, -60.0, 0.0};
  {
    const double s = std::sin(25e-6), c = std::cos(25e-6), ax = 340.0, ay = 140.0;
    expect_near(volumetric_error_um(yaw, p, Method::htm),
                {(ax * (c - 1) - ay * s) * 1e3, (ax * s + ay * (c - 1)) * 1e3, 0.0}, 1e-9);
    // First order: (-ec ay, ec ax, 0) = (-25e-6 * 140, 25e-6 * 340, 0) mm = (-3.5, 8.5, 0) um.
    expect_near(volumetric_error_um(yaw, p, Method::first_order), {-3.5, 8.5, 0.0}, 1e-12);
  }
}

// Offsets act where the chain says: the table offset has no effect when nothing is on the
// table side (FXYZ), and in XYZF (tool on the frame) only tool + table matters, since both sit
// at the end of every arm. Exact by construction of the chain, so rounding tolerance.
TEST(KinematicsVolumetric, OffsetsActOnTheirSideOfTheChain) {
  Machine a = constant_machine(Topology::fxyz);
  Machine b = a;
  b.table_offset_mm = {500.0, -400.0, 300.0};
  const Vec3 p{120.0, -60.0, 240.0};
  for (Method method : kMethods) {
    expect_near(volumetric_error_um(a, p, method), volumetric_error_um(b, p, method), 1e-9);
  }
  Machine c = constant_machine(Topology::xyzf), d = c;
  d.tool_offset_mm = {c.tool_offset_mm[0] + c.table_offset_mm[0],
                      c.tool_offset_mm[1] + c.table_offset_mm[1],
                      c.tool_offset_mm[2] + c.table_offset_mm[2]};
  d.table_offset_mm = {0.0, 0.0, 0.0};
  for (Method method : kMethods) {
    expect_near(volumetric_error_um(c, p, method), volumetric_error_um(d, p, method), 1e-9);
  }
  // ... while for XFYZ the tool offset reaches the Z roll but the table offset does not:
  // E_CZ = 30 urad, arm of Z = tool = (0, 100, 0): e_x = -ec ay = -3 um.
  Machine e;
  e.topology = Topology::xfyz;
  e.axes[Z].ec_urad = constant(30.0);
  e.tool_offset_mm = {0.0, 100.0, 0.0};
  e.table_offset_mm = {0.0, 1000.0, 0.0};
  expect_near(volumetric_error_um(e, p, Method::first_order), {-3.0, 0.0, 0.0}, 1e-12);
}

// Orientation: first order is the plain sum of the angular errors; exact for a single rotation.
TEST(KinematicsVolumetric, OrientationError) {
  Machine m;
  m.axes[X].ea_urad = constant(10.0);
  m.axes[Y].eb_urad = constant(20.0);
  m.axes[Z].ec_urad = constant(30.0);
  const Vec3 p{10.0, 20.0, 30.0};
  expect_near(volumetric_error(m, p, Method::first_order).rotation_urad, {10.0, 20.0, 30.0}, 1e-12);
  // The exact composition differs by products of two angles, |eps|^2 / 2 ~ 1e-9 rad = 1e-3 urad.
  expect_near(volumetric_error(m, p, Method::htm).rotation_urad, {10.0, 20.0, 30.0}, 2e-3);
  Machine single;
  single.topology = Topology::xyfz;
  single.axes[Y].eb_urad = constant(-45.0);
  expect_near(volumetric_error(single, p, Method::htm).rotation_urad, {0.0, -45.0, 0.0}, 1e-9);
}

// ---------------------------------------------------------------------------------------------
// Second-order agreement of the two methods

using cal::test::random_machine;  // all 21 errors as cubics of realistic size
using cal::test::scaled;

// Root-sum-square over the points of |htm - first order| (translation, and orientation).
std::pair<double, double> rss_difference(const Machine& m, const std::vector<Vec3>& points) {
  double dt = 0.0, dr = 0.0;
  for (const Vec3& p : points) {
    const auto a = volumetric_error(m, p, Method::htm);
    const auto b = volumetric_error(m, p, Method::first_order);
    dt += std::pow(norm(minus(a.translation_um, b.translation_um)), 2);
    dr += std::pow(norm(minus(a.rotation_urad, b.rotation_urad)), 2);
  }
  return {std::sqrt(dt), std::sqrt(dr)};
}

// The first-order expansion drops exactly the terms of second and higher order in the errors,
// so scaling every error by k scales htm - first_order by k^2 (plus k^3 terms). Here
// |eps| <~ 2e-4 rad per axis at k = 1 and |delta| / arm <~ 1e-4, so the cubic terms change the
// ratio d(2k)/d(k) = 4 by a relative <~ |eps| k <~ 1e-3 at k = 4 (rounding, ~1e-10 um, is far
// below d ~ 1e-3 um): we accept 4 +- 0.5 % (observed: 4.0000 to 4.0001). The translation difference
// must also be small against the error itself (second order: relative ~|eps| ~ 1e-4; we accept <
// 1e-3).
TEST(KinematicsVolumetric, MethodsAgreeToSecondOrder) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(0.0, 800.0);
  std::vector<Vec3> points;
  for (int i = 0; i < 20; ++i) points.push_back({u(rng), u(rng) - 400.0, u(rng) - 600.0});
  for (Topology t : all_topologies()) {
    const Machine base = random_machine(t, 7 + static_cast<std::uint64_t>(t));
    double previous_t = 0.0, previous_r = 0.0;
    for (double k : {0.5, 1.0, 2.0, 4.0}) {
      const auto [dt, dr] = rss_difference(scaled(base, k), points);
      if (previous_t > 0.0) {
        EXPECT_NEAR(dt / previous_t, 4.0, 0.02) << to_string(t) << " k = " << k;
        EXPECT_NEAR(dr / previous_r, 4.0, 0.02) << to_string(t) << " k = " << k;
      }
      previous_t = dt;
      previous_r = dr;
    }
    double size = 0.0;
    for (const Vec3& p : points) {
      size += std::pow(norm(volumetric_error_um(base, p, Method::first_order)), 2);
    }
    EXPECT_LT(rss_difference(base, points).first, 1e-3 * std::sqrt(size)) << to_string(t);
    EXPECT_GT(rss_difference(base, points).first, 0.0);  // the methods are not identical
  }
}

// ---------------------------------------------------------------------------------------------
// Maps

// E_XX = 0.01 um/mm, E_ZZ = 2 um, E_C0Y = 50 urad: e = (0.01 x - 0.05 y, 0, 2) um by the
// first-order formula (50 urad * y mm = 0.05 y um). Grid 3 x 2 x 2 over (0..200, 0..100,
// 0..50): positions (100 i, 100 j, 50 k), point index i + 3 (j + 2 k).
// e_x over the grid: x in {0, 100, 200} gives {0, 1, 2}, y in {0, 100} subtracts {0, 5}:
// min -5 at (0, 100, z), max 2 at (200, 0, z). |e| = sqrt(e_x^2 + 4): largest at e_x = -5,
// sqrt(29), first reached at (0, 100, 0).
TEST(KinematicsMap, GridOrderValuesAndSummary) {
  Machine m;
  m.axes[X].ex_um = ErrorFunction::polynomial({0.0, 0.01});
  m.axes[Z].ez_um = constant(2.0);
  m.squareness.c0y_urad = 50.0;
  const Grid g{{0.0, 0.0, 0.0}, {200.0, 100.0, 50.0}, {3, 2, 2}};
  const auto map = volumetric_error_map(m, g, Method::first_order);
  ASSERT_EQ(map.size(), 12u);
  ASSERT_EQ(map.errors_um.size(), 36u);
  ASSERT_EQ(map.rotations_urad.size(), 36u);
  for (std::size_t k = 0; k < 2; ++k) {
    for (std::size_t j = 0; j < 2; ++j) {
      for (std::size_t i = 0; i < 3; ++i) {
        const std::size_t p = i + 3 * (j + 2 * k);
        const double x = 100.0 * static_cast<double>(i), y = 100.0 * static_cast<double>(j);
        EXPECT_DOUBLE_EQ(map.positions_mm[3 * p], x);
        EXPECT_DOUBLE_EQ(map.positions_mm[3 * p + 1], y);
        EXPECT_DOUBLE_EQ(map.positions_mm[3 * p + 2], 50.0 * static_cast<double>(k));
        EXPECT_NEAR(map.errors_um[3 * p], 0.01 * x - 0.05 * y, 1e-12);
        EXPECT_NEAR(map.errors_um[3 * p + 1], 0.0, 1e-12);
        EXPECT_NEAR(map.errors_um[3 * p + 2], 2.0, 1e-12);
      }
    }
  }
  const auto s = summarize(map);
  EXPECT_NEAR(s.max_norm_um, std::sqrt(29.0), 1e-12);
  expect_near(s.max_norm_at_mm, {0.0, 100.0, 0.0}, 0.0);
  expect_near(s.min_um, {-5.0, 0.0, 2.0}, 1e-12);
  expect_near(s.max_um, {2.0, 0.0, 2.0}, 1e-12);
  expect_near(s.range_um, {7.0, 0.0, 0.0}, 1e-12);
  // The HTM map differs only by the exact squareness rotation: 100 (cos 50e-6 - 1) mm ~ -1e-4 um.
  const auto exact = volumetric_error_map(m, g, Method::htm);
  for (std::size_t i = 0; i < 36; ++i) EXPECT_NEAR(exact.errors_um[i], map.errors_um[i], 1e-3);
}

// Contributions over the grid of GridOrderValuesAndSummary (x in {0, 100, 200}, y in {0, 100},
// z in {0, 50}): E_C0Y = 50 urad gives |e| = 0.05 y: max 5 um, RMS sqrt((0 + 25) / 2) =
// 3.5355; E_XX = 0.01 um/mm gives 0.01 x: max 2, RMS sqrt((0 + 1 + 4) / 3) = 1.2910. Ranked
// largest first; the other 19 contribute nothing.
TEST(KinematicsMap, ContributionsRanked) {
  Machine m;
  m.axes[X].ex_um = ErrorFunction::polynomial({0.0, 0.01});
  m.squareness.c0y_urad = 50.0;
  const auto c = contributions(m, {{0.0, 0.0, 0.0}, {200.0, 100.0, 50.0}, {3, 2, 2}});
  ASSERT_EQ(c.size(), 21u);
  EXPECT_EQ(c[0].name, "E_C0Y");
  EXPECT_NEAR(c[0].max_norm_um, 5.0, 1e-12);
  EXPECT_NEAR(c[0].rms_um, std::sqrt(12.5), 1e-12);
  EXPECT_EQ(c[1].name, "E_XX");
  EXPECT_EQ(c[1].axis, X);
  EXPECT_NEAR(c[1].max_norm_um, 2.0, 1e-12);
  EXPECT_NEAR(c[1].rms_um, std::sqrt(5.0 / 3.0), 1e-12);
  for (std::size_t i = 2; i < c.size(); ++i) EXPECT_EQ(c[i].max_norm_um, 0.0) << c[i].name;
}

TEST(KinematicsMap, SinglePointAxisUsesMin) {
  Machine m;
  m.axes[Y].ey_um = ErrorFunction::polynomial({0.0, 0.1});  // 0.1 um/mm
  const auto map =
      volumetric_error_map(m, {{0.0, 30.0, 0.0}, {0.0, 999.0, 0.0}, {1, 1, 1}}, Method::htm);
  ASSERT_EQ(map.size(), 1u);
  EXPECT_DOUBLE_EQ(map.positions_mm[1], 30.0);
  EXPECT_NEAR(map.errors_um[1], 3.0, 1e-9);
}

// ---------------------------------------------------------------------------------------------
// Squareness conventions

// The conversion between `daq analyse squareness` (alpha, positive when the angle between the
// positive axis directions exceeds 90 deg) and the model's location errors, checked on all
// three planes against two independent things: (1) the measurement itself, simulated: a machine
// with only that location error is "measured" by the two straightness runs of
// squareness::from_straightness (reference axis A moving with the deviation read in +B, then B
// moving with the deviation read in +A), the deviations taken from the model; (2) the geometry:
// the angle between the actual axis directions of the exact model, acos(u_A . u_B) - 90 deg.
// With a location error of +25 urad:
//   XY: e_x = -E_C0Y y, the run along Y reads slope -25 um/m, alpha = -(0 - 25) = +25:
//       E_C0Y = +alpha (Y leans to -X, the angle opens);
//   XZ: e_x = +E_B0Z z, the run along Z reads +25 um/m, alpha = -25: E_B0Z = -alpha (Z leans
//       to +X, the angle closes);
//   YZ: e_y = -E_A0Z z, the run along Z reads -25 um/m, alpha = +25: E_A0Z = +alpha.
TEST(KinematicsSquareness, ConventionConversionOnAllThreePlanes) {
  struct Case {
    Plane plane;
    Axis a, b;  // reference axis, other axis
    double expected_alpha;
  };
  const std::array cases{Case{Plane::xy, X, Y, 25.0}, Case{Plane::xz, X, Z, -25.0},
                         Case{Plane::yz, Y, Z, 25.0}};
  for (const Case& c : cases) {
    Machine m;
    m.squareness.of(c.plane) = 25.0;
    cal::squareness::Run along_a, along_b;
    for (int k = 0; k <= 10; ++k) {
      const double q = 50.0 * k;  // 0 .. 500 mm
      Vec3 pa{}, pb{};
      pa[c.a] = q;
      pb[c.b] = q;
      along_a.position_mm.push_back(q);
      along_a.deviation_um.push_back(volumetric_error_um(m, pa, Method::htm)[c.b]);
      along_b.position_mm.push_back(q);
      along_b.deviation_um.push_back(volumetric_error_um(m, pb, Method::htm)[c.a]);
    }
    const double alpha = cal::squareness::from_straightness(along_a, along_b).squareness_um_per_m;
    const std::string what(to_string(c.plane));
    // The exact model's cos(25e-6) terms change the runs by ~1e-10 um/m.
    EXPECT_NEAR(alpha, c.expected_alpha, 1e-6) << what;
    EXPECT_NEAR(location_error_from_angle_over_90(c.plane, alpha), 25.0, 1e-6) << what;
    EXPECT_NEAR(angle_over_90_from_location_error(c.plane, 25.0), c.expected_alpha, 0.0) << what;
    // Geometry: the actual directions are the unit travel of each axis in the exact model.
    Vec3 ua{}, ub{};
    ua[c.a] = 1000.0;
    ub[c.b] = 1000.0;
    const Vec3 ea = volumetric_error_um(m, ua, Method::htm);
    const Vec3 eb = volumetric_error_um(m, ub, Method::htm);
    Vec3 da{}, db{};
    for (std::size_t i = 0; i < 3; ++i) {
      da[i] = ua[i] + ea[i] * 1e-3;
      db[i] = ub[i] + eb[i] * 1e-3;
    }
    const double cosine = (da[0] * db[0] + da[1] * db[1] + da[2] * db[2]) / (norm(da) * norm(db));
    const double over_90_urad = (std::acos(cosine) - std::numbers::pi / 2) * 1e6;
    EXPECT_NEAR(over_90_urad, c.expected_alpha, 1e-4) << what;
  }
  EXPECT_EQ(location_error_name(Plane::xz), "E_B0Z");
  EXPECT_EQ(plane_from_string("zx"), Plane::xz);  // the same plane, either order
  EXPECT_EQ(plane_from_string("YZ"), Plane::yz);
  EXPECT_THROW(plane_from_string("XX"), InputError);
}

// ---------------------------------------------------------------------------------------------
// Bad input

TEST(KinematicsBadInput, TableOutsideItsRangeNamesTheComponent) {
  Machine m;
  const std::vector<double> q{0.0, 500.0}, v{0.0, 4.0};
  m.axes[X].ey_um = ErrorFunction::table(q, v);
  // Inside: E_YX(250) = 2 um appears in y (straightness of X, 1:1).
  expect_near(volumetric_error_um(m, {250.0, 0.0, 0.0}, Method::htm), {0.0, 2.0, 0.0}, 1e-9);
  try {
    volumetric_error_um(m, {600.0, 0.0, 0.0}, Method::htm);
    FAIL() << "no throw";
  } catch (const InputError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("E_YX"), std::string::npos) << w;
    EXPECT_NE(w.find("600"), std::string::npos) << w;
  }
  EXPECT_THROW(volumetric_error_map(m, {{0, 0, 0}, {600, 0, 0}, {7, 1, 1}}, Method::first_order),
               InputError);
}

TEST(KinematicsBadInput, NonFiniteInputsAndBadGrids) {
  Machine m;
  const double nan = std::nan("");
  EXPECT_THROW(volumetric_error_um(m, {nan, 0.0, 0.0}, Method::htm), InputError);
  Machine t = m;
  t.tool_offset_mm[2] = nan;
  EXPECT_THROW(volumetric_error_um(t, {0.0, 0.0, 0.0}, Method::htm), InputError);
  Machine w = m;
  w.table_offset_mm[0] = std::numeric_limits<double>::infinity();
  EXPECT_THROW(volumetric_error_um(w, {0.0, 0.0, 0.0}, Method::first_order), InputError);
  Machine s = m;
  s.squareness.b0z_urad = nan;
  EXPECT_THROW(volumetric_error_um(s, {0.0, 0.0, 0.0}, Method::htm), InputError);

  EXPECT_THROW(volumetric_error_map(m, {{0, 0, 0}, {1, 1, 1}, {0, 2, 2}}, Method::htm),
               InputError);  // no points
  EXPECT_THROW(volumetric_error_map(m, {{0, 5, 0}, {1, 1, 1}, {2, 2, 2}}, Method::htm),
               InputError);  // max < min
  EXPECT_THROW(volumetric_error_map(m, {{0, 0, nan}, {1, 1, 1}, {2, 2, 2}}, Method::htm),
               InputError);
  EXPECT_THROW(
      volumetric_error_map(m, {{0, 0, 0}, {1, 1, 1}, {100000, 100000, 100000}}, Method::htm),
      InputError);  // 1e15 points
  EXPECT_THROW(summarize(ErrorMap{}), InputError);
}

}  // namespace
