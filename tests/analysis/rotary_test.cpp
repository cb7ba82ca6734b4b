// Tests of the rotary axes (rotary.hpp). Every expected value is derived by hand in the comment
// next to it, from the conventions of rotary.hpp (rotation about the actual axis average line,
// errors of the moving member relative to its carrier), or written out with rotation matrices
// in this file; the sphere-probing fit is checked against the injected truth. Nothing is taken
// from the code under test.
#include "cal/analysis/rotary.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "cal/analysis/error.hpp"

namespace {

using namespace cal::kinematics;
using cal::InputError;

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// Small 3-vector / 3x3 helpers, written out so that the expectations do not use the code's
// own rotations.
using M3 = std::array<Vec3, 3>;  // rows
Vec3 add(const Vec3& a, const Vec3& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
Vec3 sub(const Vec3& a, const Vec3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
Vec3 scale(double k, const Vec3& a) { return {k * a[0], k * a[1], k * a[2]}; }
double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
double norm(const Vec3& a) { return std::sqrt(dot(a, a)); }
Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
Vec3 mv(const M3& m, const Vec3& v) { return {dot(m[0], v), dot(m[1], v), dot(m[2], v)}; }
M3 transpose(const M3& m) {
  return {{{m[0][0], m[1][0], m[2][0]}, {m[0][1], m[1][1], m[2][1]}, {m[0][2], m[1][2], m[2][2]}}};
}
M3 mul(const M3& a, const M3& b) {
  const M3 bt = transpose(b);
  M3 r{};
  for (std::size_t i = 0; i < 3; ++i) {
    for (std::size_t j = 0; j < 3; ++j) r[i][j] = dot(a[i], bt[j]);
  }
  return r;
}
// Right-handed rotations by deg about X, Y, Z.
M3 rot_x(double deg) {
  const double c = std::cos(deg * kDeg), s = std::sin(deg * kDeg);
  return {{{1, 0, 0}, {0, c, -s}, {0, s, c}}};
}
M3 rot_y(double deg) {
  const double c = std::cos(deg * kDeg), s = std::sin(deg * kDeg);
  return {{{c, 0, s}, {0, 1, 0}, {-s, 0, c}}};
}
M3 rot_z(double deg) {
  const double c = std::cos(deg * kDeg), s = std::sin(deg * kDeg);
  return {{{c, -s, 0}, {s, c, 0}, {0, 0, 1}}};
}
// Rodrigues: v turned by phi (rad) about the unit vector n.
Vec3 rodrigues(const Vec3& n, double phi, const Vec3& v) {
  return add(add(scale(std::cos(phi), v), scale(std::sin(phi), cross(n, v))),
             scale(dot(n, v) * (1 - std::cos(phi)), n));
}

void expect_near(const Vec3& got, const Vec3& want, double tol, const std::string& what) {
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_NEAR(got[i], want[i], tol) << what << " component " << i;
  }
}

ErrorFunction constant(double v) { return ErrorFunction::polynomial({v}); }

// ---------------------------------------------------------------------------------------------
// The machines of the tests.
//
// A/C trunnion (table-table): the workpiece sits on C, C on the A cradle, A on the bed
// (topology FXYZ: the linear axes carry the tool). Both pivots at c = (0, 0, -250): the C axis
// crosses the A axis 250 mm below the spindle gauge point at home. Location errors:
//   C: E_X0C = 12 um, E_Y0C = -7 um, E_A0C = 35 urad, E_B0C = -20 urad
//   A: E_Y0A = 9 um, E_Z0A = -15 um, E_B0A = -25 urad, E_C0A = 40 urad
// Tool: 100 mm long, pointing down.
constexpr Vec3 kPivot{0, 0, -250};
constexpr double kX0C = 12, kY0C = -7, kA0C = 35, kB0C = -20;
constexpr double kY0A = 9, kZ0A = -15, kB0A = -25, kC0A = 40;
constexpr Vec3 kTool{0, 0, -100};

FiveAxisMachine trunnion(double k = 1.0) {
  FiveAxisMachine m;
  m.linear.topology = Topology::fxyz;
  m.linear.tool_offset_mm = kTool;
  RotaryAxis c;
  c.letter = RotaryLetter::c;
  c.side = Side::table;
  c.pivot_mm = kPivot;
  c.location_position_um = {k * kX0C, k * kY0C, 0};
  c.location_orientation_urad = {k * kA0C, k * kB0C, 0};
  RotaryAxis a;
  a.letter = RotaryLetter::a;
  a.side = Side::table;
  a.pivot_mm = kPivot;
  a.location_position_um = {0, k * kY0A, k * kZ0A};
  a.location_orientation_urad = {0, k * kB0A, k * kC0A};
  m.rotary = {c, a};
  return m;
}

// The linear position that puts the nominal tool tip on the workpiece point w (workpiece frame)
// for the trunnion at (C, A) = (c_deg, a_deg): w turned by C about the C axis, then by A about
// the A axis (both through kPivot), minus the tool offset.
Vec3 command_for(const Vec3& w, double c_deg, double a_deg) {
  const Vec3 on_table = add(kPivot, mv(mul(rot_x(a_deg), rot_z(c_deg)), sub(w, kPivot)));
  return sub(on_table, kTool);
}

// First-order displacement of a point v (relative to the pivot) moved by a joint turning by R
// about a line with position error o (um) and orientation error e (urad), derived in
// docs/kinematics.md: J_act x - J_nom x = (I - R) o + e x (R v) - R (e x v). Result in um.
Vec3 joint_displacement_um(const M3& r, const Vec3& o_um, const Vec3& e_urad, const Vec3& v_mm) {
  const Vec3 io = sub(o_um, mv(r, o_um));
  const Vec3 tilt_um = scale(1e-3, sub(cross(e_urad, mv(r, v_mm)), mv(r, cross(e_urad, v_mm))));
  return add(io, tilt_um);
}

// ---------------------------------------------------------------------------------------------
// Names

// A spindle B axis (pivot 180 mm above the tool reference point, the tool 100 mm below it) with
// its location errors: position (X, 0, Z) um and orientation (A, 0, C) urad.
FiveAxisMachine spindle_b(const Vec3& location_position_um, const Vec3& location_orientation_urad) {
  FiveAxisMachine m;
  m.linear.tool_offset_mm = {0, 0, -100};
  RotaryAxis b;
  b.letter = RotaryLetter::b;
  b.side = Side::spindle;
  b.pivot_mm = {0, 0, 180};
  b.location_position_um = location_position_um;
  b.location_orientation_urad = location_orientation_urad;
  m.rotary = {b};
  return m;
}

TEST(RotaryNames, LocationErrorNamesFollowIso2301) {
  EXPECT_EQ(location_error_names(RotaryLetter::c),
            (std::array<std::string, 4>{"E_X0C", "E_Y0C", "E_A0C", "E_B0C"}));
  EXPECT_EQ(location_error_names(RotaryLetter::a),
            (std::array<std::string, 4>{"E_Y0A", "E_Z0A", "E_B0A", "E_C0A"}));
  EXPECT_EQ(location_error_names(RotaryLetter::b),
            (std::array<std::string, 4>{"E_X0B", "E_Z0B", "E_A0B", "E_C0B"}));
  EXPECT_EQ(rotary_letter_from_string("b"), RotaryLetter::b);
  EXPECT_EQ(to_string(RotaryLetter::c), "C");
  EXPECT_THROW(rotary_letter_from_string("D"), InputError);
  EXPECT_THROW(rotary_letter_from_string("AB"), InputError);
}

// ---------------------------------------------------------------------------------------------
// The chain

TEST(RotaryModel, WithoutRotaryAxesItIsTheThreeAxisModel) {
  FiveAxisMachine m;
  m.linear.topology = Topology::xfyz;
  m.linear.tool_offset_mm = {5, -3, -120};
  m.linear.table_offset_mm = {-200, 100, 50};
  m.linear.axes[X].ec_urad = ErrorFunction::polynomial({3, 0.02});
  m.linear.axes[Y].ex_um = ErrorFunction::polynomial({1, 0.01, 1e-5});
  m.linear.axes[Z].ea_urad = constant(-7);
  m.linear.squareness.c0y_urad = 12;
  const Vec3 p{150, -80, -40};
  for (Method method : {Method::htm, Method::first_order}) {
    const auto five = five_axis_error(m, p, {}, method);
    const auto three = volumetric_error(m.linear, p, method);
    expect_near(five.translation_um, three.translation_um, 1e-9, "translation");
    expect_near(five.rotation_urad, three.rotation_urad, 1e-9, "rotation");
  }
}

TEST(RotaryModel, TableAxisTurnsTheLinearErrorIntoTheWorkpieceFrame) {
  // A perfect C table on an XFYZ machine with linear errors: the tool's error relative to the
  // table frame is the 3-axis error e3; the workpiece frame is the table frame turned by the
  // C angle, so the error read in it is Rz(-C) e3. At C = 90: Rz(-90) (x, y, z) = (y, -x, z).
  FiveAxisMachine m;
  m.linear.topology = Topology::xfyz;
  m.linear.tool_offset_mm = {0, 0, -80};
  m.linear.axes[X].ey_um = ErrorFunction::polynomial({2, 0.03});
  m.linear.axes[Y].eb_urad = constant(15);
  RotaryAxis c;
  c.pivot_mm = {30, -40, -300};
  m.rotary = {c};
  const Vec3 p{120, 60, -20};
  for (Method method : {Method::htm, Method::first_order}) {
    const Vec3 e3 = volumetric_error(m.linear, p, method).translation_um;
    const Vec3 e5 = five_axis_error(m, p, std::vector{90.0}, method).translation_um;
    expect_near(e5, {e3[1], -e3[0], e3[2]}, 1e-9, "C = 90");
  }
}

// The first-order equations of a tilting rotary table (A/C trunnion) with the eight location
// errors, for a point on the table: the form of the sphere / R-test equations of Tsutsumi &
// Saito (IJMTM 43(8) 2003 771-780) and Ibaraki, Oyama & Otsubo (IJMTM 51(3) 2011 190-200); the
// derivation below is ours (the papers' text was not available), from the conventions of
// rotary.hpp.
//
// Workpiece point W = pivot + (r, 0, h), r = 120, h = 80. The table (with W on it) turned by C
// about the actual C line moves W, relative to where the control believes it is, by
//   d_C = ( E_X0C (1 - cos C) + E_Y0C sin C + h (E_B0C (1 - cos C) - E_A0C sin C),
//           E_Y0C (1 - cos C) - E_X0C sin C - h (E_A0C (1 - cos C) + E_B0C sin C),
//           r (E_A0C sin C + E_B0C (1 - cos C)) )
// (from (I - R) o + e x (R v) - R (e x v), v = (r, 0, h)): the position errors give a circle
// eccentric by (E_X0C, E_Y0C) through W, the tilt a height change r E_A0C sin C. Turned by A
// about the actual A line (C = 0):
//   d_A = ( h (E_C0A sin A - E_B0A (1 - cos A)),
//           E_Y0A (1 - cos A) + E_Z0A sin A + r (E_C0A (1 - cos A) - E_B0A sin A),
//           E_Z0A (1 - cos A) - E_Y0A sin A - r (E_B0A (1 - cos A) + E_C0A sin A) ).
// The tool stands where the control put it, so the tool relative to the workpiece is -d, and
// read in the workpiece frame (turned by R = Rz(C) or Rx(A)): e = -R^T d. The orientation error
// of the tool relative to the workpiece: e_rot = eps - R^T eps, i.e. for C
//   ( E_A0C (1 - cos C) - E_B0C sin C,  E_B0C (1 - cos C) + E_A0C sin C,  0 )
// and for A ( 0,  E_B0A (1 - cos A) - E_C0A sin A,  E_C0A (1 - cos A) + E_B0A sin A ).
TEST(RotaryModel, TiltingRotaryTableFirstOrderEquationsByHand) {
  const FiveAxisMachine m = trunnion();
  const double r = 120, h = 80;
  const Vec3 w = add(kPivot, {r, 0, h});
  for (double deg : {-135.0, -90.0, -30.0, 0.0, 45.0, 90.0, 180.0}) {
    const double c = std::cos(deg * kDeg), s = std::sin(deg * kDeg);
    const double mm = 1e-3;  // urad x mm = 1e-3 um
    {
      SCOPED_TRACE("C = " + std::to_string(deg));
      const Vec3 d{kX0C * (1 - c) + kY0C * s + h * mm * (kB0C * (1 - c) - kA0C * s),
                   kY0C * (1 - c) - kX0C * s - h * mm * (kA0C * (1 - c) + kB0C * s),
                   r * mm * (kA0C * s + kB0C * (1 - c))};
      const Vec3 want = scale(-1, mv(transpose(rot_z(deg)), d));
      const Vec3 want_rot{kA0C * (1 - c) - kB0C * s, kB0C * (1 - c) + kA0C * s, 0};
      const std::vector angles{deg, 0.0};
      const auto fo = five_axis_error(m, command_for(w, deg, 0), angles, Method::first_order);
      expect_near(fo.translation_um, want, 1e-9, "first order");
      expect_near(fo.rotation_urad, want_rot, 1e-9, "first order rotation");
      const auto ex = five_axis_error(m, command_for(w, deg, 0), angles, Method::htm);
      // Second order: |eps| |o| + |eps|^2 |v| = 40e-6 * 14 um + 1.6e-9 * 145e3 um < 1e-3 um.
      expect_near(ex.translation_um, want, 2e-3, "exact");
      // Second order in the orientation: |eps|^2 = 1.6e-9 rad = 1.6e-3 urad.
      expect_near(ex.rotation_urad, want_rot, 4e-3, "exact rotation");
    }
    {
      SCOPED_TRACE("A = " + std::to_string(deg));
      const Vec3 d{h * mm * (kC0A * s - kB0A * (1 - c)),
                   kY0A * (1 - c) + kZ0A * s + r * mm * (kC0A * (1 - c) - kB0A * s),
                   kZ0A * (1 - c) - kY0A * s - r * mm * (kB0A * (1 - c) + kC0A * s)};
      const Vec3 want = scale(-1, mv(transpose(rot_x(deg)), d));
      const Vec3 want_rot{0, kB0A * (1 - c) - kC0A * s, kC0A * (1 - c) + kB0A * s};
      const std::vector angles{0.0, deg};
      const auto fo = five_axis_error(m, command_for(w, 0, deg), angles, Method::first_order);
      expect_near(fo.translation_um, want, 1e-9, "first order");
      expect_near(fo.rotation_urad, want_rot, 1e-9, "first order rotation");
      const auto ex = five_axis_error(m, command_for(w, 0, deg), angles, Method::htm);
      expect_near(ex.translation_um, want, 2e-3, "exact");
      // Second order in the orientation: |eps|^2 = 1.6e-9 rad = 1.6e-3 urad.
      expect_near(ex.rotation_urad, want_rot, 4e-3, "exact rotation");
    }
  }
}

TEST(RotaryModel, TrunnionBothAxesTurnedFirstOrderByHand) {
  // Both axes turned: W is moved by C about the C line (d_C, in the A cradle's frame), the
  // cradle then by A: the displacement in the bed frame is Rx(A) d_C + d_A(Rz(C) v), and the
  // error of the tool in the workpiece frame -Rz(C)^T Rx(A)^T of that.
  const FiveAxisMachine m = trunnion();
  const Vec3 w = add(kPivot, {-60, 140, 35});
  const Vec3 v = sub(w, kPivot);
  for (const auto& [cd, ad] :
       std::vector<std::pair<double, double>>{{30, -60}, {-120, 45}, {200, 95}}) {
    const Vec3 dc = joint_displacement_um(rot_z(cd), {kX0C, kY0C, 0}, {kA0C, kB0C, 0}, v);
    const Vec3 da =
        joint_displacement_um(rot_x(ad), {0, kY0A, kZ0A}, {0, kB0A, kC0A}, mv(rot_z(cd), v));
    const Vec3 d = add(mv(rot_x(ad), dc), da);
    const Vec3 want = scale(-1, mv(transpose(mul(rot_x(ad), rot_z(cd))), d));
    const std::vector angles{cd, ad};
    const auto fo = five_axis_error(m, command_for(w, cd, ad), angles, Method::first_order);
    expect_near(fo.translation_um, want, 1e-9, "first order C " + std::to_string(cd));
    const auto ex = five_axis_error(m, command_for(w, cd, ad), angles, Method::htm);
    expect_near(ex.translation_um, want, 5e-3, "exact C " + std::to_string(cd));
  }
}

TEST(RotaryModel, SwivelHeadFirstOrderByHand) {
  // A B swivel head (spindle side) on an FXYZ machine: pivot 180 mm above the gauge point,
  // tool 100 mm: v = tool - pivot = (0, 0, -L), L = 280. Location errors E_X0B = 10 um,
  // E_Z0B = -6 um, E_A0B = 30 urad, E_C0B = -45 urad. The tip moves with the head, so the error
  // is +d, with d from (I - R) o + e x (R v) - R (e x v), R = Ry(B):
  //   e = ( E_X0B (1 - cos B) - E_Z0B sin B,
  //        -L (E_A0B (1 - cos B) + E_C0B sin B),
  //         E_Z0B (1 - cos B) + E_X0B sin B );
  // orientation: e - R e = ( E_A0B (1 - cos B) - E_C0B sin B, 0, E_C0B (1 - cos B) + E_A0B sin B ).
  // Check of the first line: B = 180 mirrors the tip through the line at x = E_X0B: +2 E_X0B.
  const double x0 = 10, z0 = -6, a0 = 30, c0 = -45, L = 280;
  const FiveAxisMachine m = spindle_b({x0, 0, z0}, {a0, 0, c0});
  for (double deg : {-90.0, -20.0, 60.0, 180.0}) {
    const double c = std::cos(deg * kDeg), s = std::sin(deg * kDeg);
    const Vec3 want{x0 * (1 - c) - z0 * s, -L * 1e-3 * (a0 * (1 - c) + c0 * s),
                    z0 * (1 - c) + x0 * s};
    const Vec3 want_rot{a0 * (1 - c) - c0 * s, 0, c0 * (1 - c) + a0 * s};
    const std::vector angles{deg};
    const auto fo = five_axis_error(m, {10, 20, 30}, angles, Method::first_order);
    expect_near(fo.translation_um, want, 1e-9, "first order B " + std::to_string(deg));
    expect_near(fo.rotation_urad, want_rot, 1e-9, "first order rotation");
    const auto ex = five_axis_error(m, {10, 20, 30}, angles, Method::htm);
    expect_near(ex.translation_um, want, 2e-3, "exact B " + std::to_string(deg));
  }
  // The nominal tip: the tool turned by B about the pivot: (0,0,180) + Ry(B) (0,0,-280) + p.
  const Vec3 tip = five_axis_nominal_tip_mm(m, {10, 20, 30}, std::vector{90.0});
  expect_near(tip, {10 - 280, 20, 30 + 180}, 1e-9, "nominal tip at B = 90");
}

TEST(RotaryModel, ForkHeadHeadHeadByHand) {
  // A C/B fork head (both axes on the spindle side; C carries B, B carries the spindle): the
  // C pivot on the ram axis 400 mm up, the B pivot 150 mm up, tool 120 mm long. The tip is
  // Jc(Jb(t)); to first order its displacement is
  //   Rz(C) d_B(t - c_B) + d_C(Ry(B)(t - c_B) + c_B - c_C)
  // with d from (I - R) o + e x (R v) - R (e x v), and the tool moves with the head, so e = +d.
  // Exactly, each joint is Rodrigues' rotation about its actual line (n_C = Ry(b) Rx(a) z,
  // n_B = Rz(c) Rx(a) y), composed: pC + oC + rod(nC, C, (pB + oB + rod(nB, B, t - pB - oB))
  // - pC - oC).
  FiveAxisMachine m;
  m.linear.topology = Topology::fxyz;
  m.linear.tool_offset_mm = {0, 0, -120};
  RotaryAxis c, b;
  c.letter = RotaryLetter::c;
  c.side = Side::spindle;
  c.pivot_mm = {0, 0, 400};
  c.location_position_um = {15, -10, 0};
  c.location_orientation_urad = {-30, 25, 0};
  b.letter = RotaryLetter::b;
  b.side = Side::spindle;
  b.pivot_mm = {0, 0, 150};
  b.location_position_um = {-8, 0, 12};
  b.location_orientation_urad = {40, 0, -35};
  m.rotary = {c, b};
  const Vec3 t{0, 0, -120}, pc{0, 0, 400}, pb{0, 0, 150};
  for (const auto& [cd, bd] :
       std::vector<std::pair<double, double>>{{90, 30}, {-45, -60}, {170, 100}}) {
    const Vec3 db = joint_displacement_um(rot_y(bd), {-8, 0, 12}, {40, 0, -35}, sub(t, pb));
    const Vec3 dc = joint_displacement_um(rot_z(cd), {15, -10, 0}, {-30, 25, 0},
                                          sub(add(mv(rot_y(bd), sub(t, pb)), pb), pc));
    const Vec3 want = add(mv(rot_z(cd), db), dc);
    const std::vector angles{cd, bd};
    const auto fo = five_axis_error(m, {5, 6, 7}, angles, Method::first_order);
    expect_near(fo.translation_um, want, 1e-9, "first order C " + std::to_string(cd));
    const double ca = -30e-6, cb = 25e-6, ba = 40e-6, bc = -35e-6;
    const Vec3 nc{std::cos(ca) * std::sin(cb), -std::sin(ca), std::cos(ca) * std::cos(cb)};
    const Vec3 nb{-std::sin(bc) * std::cos(ba), std::cos(bc) * std::cos(ba), std::sin(ba)};
    const Vec3 oc{0.015, -0.010, 0}, ob{-0.008, 0, 0.012};
    const Vec3 after_b = add(add(pb, ob), rodrigues(nb, bd * kDeg, sub(sub(t, pb), ob)));
    const Vec3 act = add(add(pc, oc), rodrigues(nc, cd * kDeg, sub(sub(after_b, pc), oc)));
    const Vec3 nom = add(pc, mv(rot_z(cd), sub(add(pb, mv(rot_y(bd), sub(t, pb))), pc)));
    const auto ex = five_axis_error(m, {5, 6, 7}, angles, Method::htm);
    expect_near(ex.translation_um, scale(1e3, sub(act, nom)), 1e-7,
                "exact C " + std::to_string(cd));
    expect_near(five_axis_nominal_tip_mm(m, {5, 6, 7}, angles), add(nom, {5, 6, 7}), 1e-9,
                "nominal");
  }
}

TEST(RotaryModel, ExactModelIsTheRotationAboutTheActualLine) {
  // Large errors (0.3 mm, 2 mrad), where first order is visibly off: the exact model must equal
  // the rotation about the actual line written with Rodrigues' formula.
  // Table C: actual line through pivot + o, direction Ry(b) Rx(a) z = (cos a sin b, -sin a,
  // cos a cos b). The control puts the tool tip at P = pivot + Rz(C) (W - pivot) (bed frame);
  // the actual workpiece point under it is the inverse rotation about the actual line:
  //   pivot + o + rod(n, -C, P - pivot - o),   e = that - W.
  FiveAxisMachine m;
  m.linear.tool_offset_mm = kTool;
  RotaryAxis c;
  c.pivot_mm = kPivot;
  const Vec3 o{0.3, -0.2, 0};  // mm
  const double a = 2e-3, b = -1.5e-3;
  c.location_position_um = {300, -200, 0};
  c.location_orientation_urad = {2000, -1500, 0};
  m.rotary = {c};
  const Vec3 n{std::cos(a) * std::sin(b), -std::sin(a), std::cos(a) * std::cos(b)};
  const Vec3 w = add(kPivot, {140, -50, 60});
  for (double deg : {37.0, 150.0, -100.0}) {
    const Vec3 p_tip = add(kPivot, mv(rot_z(deg), sub(w, kPivot)));
    const Vec3 actual = add(add(kPivot, o), rodrigues(n, -deg * kDeg, sub(sub(p_tip, kPivot), o)));
    const Vec3 want = scale(1e3, sub(actual, w));
    const auto ex = five_axis_error(m, sub(p_tip, kTool), std::vector{deg}, Method::htm);
    expect_near(ex.translation_um, want, 1e-7, "table C " + std::to_string(deg));
    const auto fo = five_axis_error(m, sub(p_tip, kTool), std::vector{deg}, Method::first_order);
    EXPECT_GT(norm(sub(fo.translation_um, want)), 0.05) << "first order is not exact here";
  }
  // Spindle B: the tip is pivot + o + rod(n_B, B, tool - pivot - o) with
  // n_B = Rz(c) Rx(a) y = (-sin c cos a, cos c cos a, sin a); nominal pivot + Ry(B)(tool - pivot).
  const FiveAxisMachine h = spindle_b({250, 0, -400}, {1800, 0, -2500});
  const double ha = 1.8e-3, hc = -2.5e-3;
  const Vec3 nb{-std::sin(hc) * std::cos(ha), std::cos(hc) * std::cos(ha), std::sin(ha)};
  const Vec3 piv{0, 0, 180}, ob{0.25, 0, -0.4}, tool{0, 0, -100};
  for (double deg : {-70.0, 45.0, 120.0}) {
    const Vec3 act = add(add(piv, ob), rodrigues(nb, deg * kDeg, sub(sub(tool, piv), ob)));
    const Vec3 nom = add(piv, mv(rot_y(deg), sub(tool, piv)));
    const auto ex = five_axis_error(h, {0, 0, 0}, std::vector{deg}, Method::htm);
    expect_near(ex.translation_um, scale(1e3, sub(act, nom)), 1e-7,
                "head B " + std::to_string(deg));
  }
}

TEST(RotaryModel, ComponentErrorSignsOnTheTableSide) {
  // Table C with only E_CC = kappa (the table turns kappa further than commanded): the workpiece
  // point under the tool is W turned by -kappa about the C line, e = -kappa z x (W - pivot).
  // With only E_XC = delta (the table shifted +delta in X of the carrier): e = -Rz(C)^T delta.
  const Vec3 w = add(kPivot, {100, 40, 20});
  const double deg = 60;
  FiveAxisMachine m;
  m.linear.tool_offset_mm = kTool;
  RotaryAxis c;
  c.pivot_mm = kPivot;
  c.motion.ec_urad = constant(50);
  m.rotary = {c};
  const Vec3 p = sub(add(kPivot, mv(rot_z(deg), sub(w, kPivot))), kTool);
  const Vec3 want_cc = scale(-50e-3, cross({0, 0, 1}, sub(w, kPivot)));  // (2, -5, 0) um
  expect_near(five_axis_error(m, p, std::vector{deg}, Method::first_order).translation_um, want_cc,
              1e-9, "E_CC");
  expect_near(five_axis_error(m, p, std::vector{deg}, Method::htm).translation_um, want_cc, 1e-3,
              "E_CC exact");
  m.rotary[0].motion = {};
  m.rotary[0].motion.ex_um = constant(4);
  const Vec3 want_xc = scale(-1, mv(transpose(rot_z(deg)), {4, 0, 0}));
  expect_near(five_axis_error(m, p, std::vector{deg}, Method::htm).translation_um, want_xc, 1e-9,
              "E_XC");
}

TEST(RotaryModel, MethodsAgreeToSecondOrder) {
  // Every error of a table C + head B machine on an XYFZ chain (linear errors, location and
  // component errors), all scaled by k: the difference between the exact and the first-order
  // model is of second order, so it scales by 4 when k doubles (accepted 4 +- 2 %), and at
  // k = 1 (errors up to 60 um and 80 urad, arms up to 0.6 m) it stays below 0.05 um, the bound
  // |eps|^2 |arm| + |eps| |delta| summed over the factors, ~ 5 * (6.4e-9 * 600 mm + 8e-5 * 60 um).
  auto machine = [](double k) {
    FiveAxisMachine m;
    m.linear.topology = Topology::xyfz;
    m.linear.tool_offset_mm = {0, 0, -120};
    m.linear.table_offset_mm = {-150, 80, -300};
    m.linear.axes[X].ex_um = ErrorFunction::polynomial({k * 2, k * 0.03});
    m.linear.axes[X].ec_urad = ErrorFunction::polynomial({k * 10, k * 0.05});
    m.linear.axes[Y].ea_urad = ErrorFunction::polynomial({k * -20, k * 0.02});
    m.linear.axes[Z].ey_um = ErrorFunction::polynomial({k * 5, 0, k * 1e-4});
    m.linear.squareness.a0z_urad = k * 30;
    RotaryAxis c;
    c.pivot_mm = {20, -10, -320};
    c.location_position_um = {k * 40, k * -25, 0};
    c.location_orientation_urad = {k * 60, k * 45, 0};
    c.motion.ez_um = ErrorFunction::polynomial({0, k * 0.01});
    c.motion.ec_urad = ErrorFunction::polynomial({k * 8, k * 0.05});
    RotaryAxis b;
    b.letter = RotaryLetter::b;
    b.side = Side::spindle;
    b.pivot_mm = {0, 0, 200};
    b.location_position_um = {k * 60, 0, k * 30};
    b.location_orientation_urad = {k * -80, 0, k * 50};
    b.motion.eb_urad = ErrorFunction::polynomial({0, k * 0.2});
    m.rotary = {c, b};
    return m;
  };
  std::mt19937 rng(36);
  std::uniform_real_distribution<double> lin(-300, 300), ang(-150, 150);
  std::vector<std::pair<Vec3, std::vector<double>>> points;
  for (int i = 0; i < 20; ++i)
    points.push_back({{lin(rng), lin(rng), lin(rng)}, {ang(rng), ang(rng) / 2}});
  auto rss = [&](double k, bool rotation) {
    double sum = 0;
    for (const auto& [p, a] : points) {
      const auto ex = five_axis_error(machine(k), p, a, Method::htm);
      const auto fo = five_axis_error(machine(k), p, a, Method::first_order);
      const Vec3 d = rotation ? sub(ex.rotation_urad, fo.rotation_urad)
                              : sub(ex.translation_um, fo.translation_um);
      sum += dot(d, d);
    }
    return std::sqrt(sum);
  };
  for (bool rotation : {false, true}) {
    const double r1 = rss(1, rotation), r2 = rss(2, rotation), r4 = rss(4, rotation);
    EXPECT_GT(r1, 0.0);
    EXPECT_NEAR(r2 / r1, 4.0, 0.08) << (rotation ? "rotation" : "translation");
    EXPECT_NEAR(r4 / r2, 4.0, 0.08) << (rotation ? "rotation" : "translation");
  }
  for (const auto& [p, a] : points) {
    const auto ex = five_axis_error(machine(1), p, a, Method::htm);
    const auto fo = five_axis_error(machine(1), p, a, Method::first_order);
    EXPECT_LT(norm(sub(ex.translation_um, fo.translation_um)), 0.05);
    EXPECT_GT(norm(ex.translation_um), 5.0);  // the errors themselves are far larger
  }
}

TEST(RotaryModel, RefusesWhatItCannotModel) {
  FiveAxisMachine m = trunnion();
  EXPECT_THROW(five_axis_error(m, {0, 0, 0}, std::vector{0.0}, Method::htm), InputError);
  EXPECT_THROW(five_axis_error(m, {0, 0, 0}, std::vector{0.0, kNaN}, Method::htm), InputError);
  EXPECT_THROW(five_axis_error(m, {0, kNaN, 0}, std::vector{0.0, 0.0}, Method::htm), InputError);
  FiveAxisMachine three = m;
  three.rotary.push_back(m.rotary[0]);
  EXPECT_THROW(five_axis_error(three, {0, 0, 0}, std::vector{0.0, 0.0, 0.0}, Method::htm),
               InputError);
  FiveAxisMachine order = m;
  order.rotary[0].side = Side::spindle;  // a spindle axis before a table axis
  EXPECT_THROW(five_axis_error(order, {0, 0, 0}, std::vector{0.0, 0.0}, Method::htm), InputError);
  FiveAxisMachine along = m;
  along.rotary[0].location_position_um[2] = 5;  // "E_Z0C": along C's own line
  EXPECT_THROW(five_axis_error(along, {0, 0, 0}, std::vector{0.0, 0.0}, Method::htm), InputError);
  FiveAxisMachine about = m;
  about.rotary[1].location_orientation_urad[0] = 5;  // "E_A0A": a zero offset, belongs in E_AA
  EXPECT_THROW(five_axis_error(about, {0, 0, 0}, std::vector{0.0, 0.0}, Method::htm), InputError);
  FiveAxisMachine table = m;
  const std::vector<double> at{-30.0, 30.0}, val{1.0, 2.0};
  table.rotary[0].motion.ez_um = ErrorFunction::table(at, val);
  try {
    five_axis_error(table, {0, 0, 0}, std::vector{45.0, 0.0}, Method::htm);
    ADD_FAILURE() << "an angle outside the table was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("E_ZC"), std::string::npos) << what;
    EXPECT_NE(what.find("45 deg"), std::string::npos) << what;
  }
}

// ---------------------------------------------------------------------------------------------
// Sphere probing

// The probed centre of a sphere fixed at S on the workpiece, the trunnion at (C, A): the linear
// position at which the ACTUAL tool tip is on S, plus the tool offset (what the control
// reports). From the model: start at the nominal command, and correct by how far the actual tip
// misses S, read in the workpiece frame and turned back into the bed frame (Rx(A) Rz(C)); the
// map from the linear position to the tip is affine, so a few steps converge.
Vec3 probe(const FiveAxisMachine& m, const Vec3& s, double c_deg, double a_deg) {
  Vec3 p = command_for(s, c_deg, a_deg);
  const M3 back = mul(rot_x(a_deg), rot_z(c_deg));
  const std::vector angles{c_deg, a_deg};
  for (int it = 0; it < 6; ++it) {
    // Actual tip minus S: the error at p plus how far p's nominal tip already is from S.
    const Vec3 e_um = five_axis_error(m, p, angles, Method::htm).translation_um;
    const Vec3 miss = add(scale(1e-3, e_um), sub(five_axis_nominal_tip_mm(m, p, angles), s));
    p = sub(p, mv(back, miss));
  }
  return add(p, kTool);
}

const Vec3 kSphere = add(kPivot, {150, 30, 100});  // on the C table: radius 153 mm, 100 mm up

std::vector<ProbedCentre> probe_c(const FiveAxisMachine& m, int n, double noise_um, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, noise_um * 1e-3);
  std::vector<ProbedCentre> out;
  for (int k = 0; k < n; ++k) {
    const double deg = 360.0 * k / n;
    Vec3 c = probe(m, kSphere, deg, 0);
    for (double& x : c) x += noise(rng);
    out.push_back({deg, c});
  }
  return out;
}

TEST(RotarySphereProbing, SimulatedCentresAreTheRotationAboutTheActualLine) {
  // The C line: through pivot + (E_X0C, E_Y0C, 0), direction Ry(E_B0C) Rx(E_A0C) z; the centre
  // probed at C is S turned by C about it (Rodrigues).
  const FiveAxisMachine m = trunnion();
  const double a = kA0C * 1e-6, b = kB0C * 1e-6;
  const Vec3 n{std::cos(a) * std::sin(b), -std::sin(a), std::cos(a) * std::cos(b)};
  const Vec3 o{kX0C * 1e-3, kY0C * 1e-3, 0};
  for (double deg : {0.0, 75.0, 200.0}) {
    const Vec3 want = add(add(kPivot, o), rodrigues(n, deg * kDeg, sub(sub(kSphere, kPivot), o)));
    expect_near(probe(m, kSphere, deg, 0), want, 1e-9, "C = " + std::to_string(deg));
  }
}

// The library's simulated probe (probed_centre_mm, what the CLI's simulated touch probe uses)
// is this file's: the centre turned about the actual line, both axes, with the trunnion's
// component and linear errors.
TEST(RotarySphereProbing, TheLibrarysSimulatedProbeIsTheTestsOwn) {
  const FiveAxisMachine m = trunnion();
  for (const auto& [c, a] :
       {std::pair{0.0, 0.0}, {75.0, 0.0}, {200.0, 0.0}, {0.0, -60.0}, {120.0, 35.0}}) {
    const std::vector angles{c, a};
    expect_near(probed_centre_mm(m, kSphere, angles), probe(m, kSphere, c, a), 1e-9,
                "C, A = " + std::to_string(c) + ", " + std::to_string(a));
  }
  // A spindle axis turned: what the control reports for the turned tool, in
  // rotary_head_test.cpp.
}

TEST(RotarySphereProbing, RecoversTheLocationErrorsWithoutNoise) {
  const FiveAxisMachine m = trunnion();
  const auto fit = fit_axis_line(RotaryLetter::c, kPivot, probe_c(m, 8, 0.0, 1));
  // Injected: E_X0C 12, E_Y0C -7 um; E_A0C 35, E_B0C -20 urad. The fit's own rounding and the
  // simulation's (1e-12 mm) are far below 1e-4 um and 1e-3 urad.
  expect_near(fit.position_um, {kX0C, kY0C, 0}, 1e-4, "position");
  expect_near(fit.orientation_urad, {kA0C, kB0C, 0}, 1e-3, "orientation");
  // Radius and height of the circle: S relative to the actual line (through pivot + o, along
  // n = Ry(E_B0C) Rx(E_A0C) z): w = S - pivot - o, height w.n, radius |w - (w.n) n|; about
  // 152.963 mm and 99.996 mm, against 152.971 and 100 for the nominal line.
  const double a = kA0C * 1e-6, b = kB0C * 1e-6;
  const Vec3 n{std::cos(a) * std::sin(b), -std::sin(a), std::cos(a) * std::cos(b)};
  const Vec3 w = sub(sub(kSphere, kPivot), {kX0C * 1e-3, kY0C * 1e-3, 0});
  EXPECT_NEAR(fit.radius_mm, norm(sub(w, scale(dot(w, n), n))), 1e-9);
  EXPECT_NEAR(fit.plane_offset_mm, dot(w, n), 1e-9);
  EXPECT_LT(fit.rms_um, 1e-5);
  // The A axis of the same trunnion, probed at C = 0 over -90 .. +90 deg (7 angles): injected
  // E_Y0A 9, E_Z0A -15 um; E_B0A -25, E_C0A 40 urad.
  std::vector<ProbedCentre> a_centres;
  for (int k = 0; k < 7; ++k) {
    const double deg = -90.0 + 30.0 * k;
    a_centres.push_back({deg, probe(m, kSphere, 0, deg)});
  }
  const auto fa = fit_axis_line(RotaryLetter::a, kPivot, a_centres);
  expect_near(fa.position_um, {0, kY0A, kZ0A}, 1e-4, "A position");
  expect_near(fa.orientation_urad, {0, kB0A, kC0A}, 1e-3, "A orientation");
}

// Linear axes' errors in the probed centres: the trunnion above with X positioning (20 um/m
// plus 3 um), X yaw (15 urad plus 0.05 urad/mm) and Y straightness in X (E_XY, 0.02 um/mm)
// added. Unremoved, they pass into the C axis's fitted line: its position moves by about the
// X error at the pivot's X plus the yaw's tilt of the 350 mm tool-and-sphere lever, micrometres.
// Removed with the same linear errors (what a volumetric campaign measured), the fit gives the
// injected location errors again, to first order in the errors: the second-order remainder
// (products of um-level errors over 100 mm levers) is below 1e-3 um and 0.01 urad.
TEST(RotarySphereProbing, LinearAxisErrorsAreRemovedFromTheCentresBeforeTheFit) {
  FiveAxisMachine m = trunnion();
  m.linear.axes[X].ex_um = ErrorFunction::polynomial({3, 0.02});
  m.linear.axes[X].ec_urad = ErrorFunction::polynomial({15, 0.05});
  m.linear.axes[Y].ex_um = ErrorFunction::polynomial({0, 0.02});
  const auto centres = probe_c(m, 12, 0.0, 1);
  const auto raw = fit_axis_line(RotaryLetter::c, kPivot, centres);
  // The bias the linear errors leave when nothing is removed (guards the test: were it below
  // the tolerance, the correction would prove nothing).
  EXPECT_GT(std::abs(raw.position_um[0] - kX0C) + std::abs(raw.position_um[1] - kY0C), 1.0);

  Machine linear = m.linear;  // the measured linear axes, no rotary axis
  const auto corrected = remove_linear_errors(linear, centres);
  ASSERT_EQ(corrected.centres.size(), centres.size());
  // Nothing along Z: no linear error here moves the tip in Z (no E_Z?, the tool along -Z
  // is not moved by the yaw). X and Y are the errors at each centre's own position.
  for (const auto& e : corrected.correction_um) EXPECT_NEAR(e[2], 0.0, 1e-9);
  const auto fit = fit_axis_line(RotaryLetter::c, kPivot, corrected.centres);
  expect_near(fit.position_um, {kX0C, kY0C, 0}, 1e-3, "position after removal");
  expect_near(fit.orientation_urad, {kA0C, kB0C, 0}, 1e-2, "orientation after removal");
  // A position outside a linear error table is refused, not extrapolated.
  linear.axes[X].ex_um = ErrorFunction::table(std::vector{-10.0, 10.0}, std::vector{0.0, 1.0});
  EXPECT_THROW(remove_linear_errors(linear, centres), cal::InputError);
  std::vector<ProbedCentre> nan = centres;
  nan[3].centre_mm[1] = std::nan("");
  EXPECT_THROW(remove_linear_errors(m.linear, nan), cal::InputError);
}

TEST(RotarySphereProbing, RecoversTheLocationErrorsWithinTheirUncertaintyUnderNoise) {
  // 12 centres evenly over 360 deg, Gaussian noise sigma = 1 um per coordinate (seeded). For
  // evenly spaced centres on a circle of radius R = 153 mm, H = 100 mm above the pivot's plane,
  // least squares gives (derivation in docs/kinematics.md):
  //   u(E_A0C) = u(E_B0C) = sigma sqrt(2 / N) / R          = 2.67 urad
  //   u(E_X0C) = u(E_Y0C) = sigma sqrt(2 / N) sqrt(1 + H^2/R^2) = 0.488 um
  // Accepted: the recovered value within 4 u of the injected one (each of 4 seeds), the
  // reported u within 2 % of these when the probe's sigma is given, and the sigma estimated
  // from the residuals (18 degrees of freedom) within 40 % of the injected one.
  const FiveAxisMachine m = trunnion();
  const double sigma = 1.0, n = 12, r = std::hypot(150.0, 30.0), hgt = 100.0;
  const double u_tilt = sigma * std::sqrt(2 / n) / r * 1e3;
  const double u_pos = sigma * std::sqrt(2 / n) * std::sqrt(1 + hgt * hgt / (r * r));
  for (unsigned seed : {1u, 2u, 3u, 4u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const auto centres = probe_c(m, 12, sigma, seed);
    const auto given = fit_axis_line(RotaryLetter::c, kPivot, centres, sigma);
    EXPECT_NEAR(given.position_u_um[0], u_pos, 0.02 * u_pos);
    EXPECT_NEAR(given.position_u_um[1], u_pos, 0.02 * u_pos);
    EXPECT_NEAR(given.orientation_u_urad[0], u_tilt, 0.02 * u_tilt);
    EXPECT_NEAR(given.orientation_u_urad[1], u_tilt, 0.02 * u_tilt);
    EXPECT_NEAR(given.position_um[0], kX0C, 4 * u_pos);
    EXPECT_NEAR(given.position_um[1], kY0C, 4 * u_pos);
    EXPECT_NEAR(given.orientation_urad[0], kA0C, 4 * u_tilt);
    EXPECT_NEAR(given.orientation_urad[1], kB0C, 4 * u_tilt);
    const auto est = fit_axis_line(RotaryLetter::c, kPivot, centres);
    EXPECT_EQ(est.dof, 18);
    EXPECT_NEAR(est.sigma_um, sigma, 0.4 * sigma);
    EXPECT_DOUBLE_EQ(est.position_um[0], given.position_um[0]);  // same fit, other sigma
    EXPECT_NEAR(est.position_u_um[0] / given.position_u_um[0], est.sigma_um / sigma, 1e-9);
  }
}

TEST(RotarySphereProbing, ResidualsAreTheAxisErrorMotion) {
  // A C table with no location error and two error motions given as tables at 30 deg steps:
  // axial E_ZC = 2 cos(2C) um and angular positioning E_CC = 20 cos(2C) urad. Probed at the
  // 12 table nodes, without noise. The fit takes up the mean and the first harmonic (they are
  // location errors and the set-up); the second harmonic is left whole in the residuals:
  //   axial_k = 2 cos(2 C_k) um,  tangential_k = R E_CC = 153 mm * 20 urad cos(2 C_k)
  //   = 3.06 cos(2 C_k) um,  radial_k = 0.
  FiveAxisMachine m = trunnion(0.0);
  std::vector<double> at, ez, ec;
  for (int k = 0; k <= 12; ++k) {
    at.push_back(30.0 * k);
    ez.push_back(2 * std::cos(2 * 30.0 * k * kDeg));
    ec.push_back(20 * std::cos(2 * 30.0 * k * kDeg));
  }
  m.rotary[0].motion.ez_um = ErrorFunction::table(at, ez);
  m.rotary[0].motion.ec_urad = ErrorFunction::table(at, ec);
  const auto fit = fit_axis_line(RotaryLetter::c, kPivot, probe_c(m, 12, 0.0, 1));
  const double r = std::hypot(150.0, 30.0);
  for (std::size_t k = 0; k < 12; ++k) {
    const double c2 = std::cos(2 * 30.0 * static_cast<double>(k) * kDeg);
    EXPECT_NEAR(fit.axial_um[k], 2 * c2, 1e-4) << k;
    EXPECT_NEAR(fit.tangential_um[k], r * 20e-3 * c2, 1e-4) << k;
    EXPECT_NEAR(fit.radial_um[k], 0.0, 1e-4) << k;
  }
  expect_near(fit.position_um, {0, 0, 0}, 1e-4, "no location error");
  expect_near(fit.orientation_urad, {0, 0, 0}, 1e-3, "no location error");
}

TEST(RotarySphereProbing, ThreeAnglesFitExactlyAndNeedAProbeUncertainty) {
  const FiveAxisMachine m = trunnion();
  std::vector<ProbedCentre> c;
  for (double deg : {0.0, 120.0, 240.0}) c.push_back({deg, probe(m, kSphere, deg, 0)});
  const auto est = fit_axis_line(RotaryLetter::c, kPivot, c);
  EXPECT_EQ(est.dof, 0);
  expect_near(est.position_um, {kX0C, kY0C, 0}, 1e-4, "position");
  expect_near(est.orientation_urad, {kA0C, kB0C, 0}, 1e-3, "orientation");
  EXPECT_TRUE(std::isnan(est.position_u_um[0]));  // no redundancy, no probe sigma
  const auto given = fit_axis_line(RotaryLetter::c, kPivot, c, 1.0);
  EXPECT_TRUE(std::isfinite(given.position_u_um[0]));
  EXPECT_GT(given.position_u_um[0], 0.0);
}

TEST(RotarySphereProbing, RefusesBadInput) {
  const FiveAxisMachine m = trunnion();
  auto at = [&](double deg) { return ProbedCentre{deg, probe(m, kSphere, deg, 0)}; };
  const std::vector two{at(0), at(90), at(360)};  // 360 is 0 again: two distinct angles
  EXPECT_THROW(fit_axis_line(RotaryLetter::c, kPivot, two), InputError);
  std::vector<ProbedCentre> nan{at(0), at(90), at(180)};
  nan[1].centre_mm[2] = kNaN;
  EXPECT_THROW(fit_axis_line(RotaryLetter::c, kPivot, nan), InputError);
  std::vector<ProbedCentre> nan_angle{at(0), at(90), at(180)};
  nan_angle[2].angle_deg = kInf;
  EXPECT_THROW(fit_axis_line(RotaryLetter::c, kPivot, nan_angle), InputError);
  const std::vector<ProbedCentre> line{{0, {0, 0, 0}}, {90, {10, 10, 0}}, {180, {20, 20, 0}}};
  try {
    fit_axis_line(RotaryLetter::c, kPivot, line);
    ADD_FAILURE() << "collinear centres accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("collinear"), std::string::npos) << e.what();
  }
  const std::vector<ProbedCentre> same{{0, {1, 2, 3}}, {90, {1, 2, 3}}, {180, {1, 2, 3}}};
  EXPECT_THROW(fit_axis_line(RotaryLetter::c, kPivot, same), InputError);
  // A circle in the XZ plane is a B axis's, not C's.
  const std::vector<ProbedCentre> xz{{0, {100, 0, 0}}, {90, {0, 0, -100}}, {180, {-100, 0, 0}}};
  EXPECT_THROW(fit_axis_line(RotaryLetter::c, {0, 0, 0}, xz), InputError);
  EXPECT_NO_THROW(fit_axis_line(RotaryLetter::b, {0, 0, 0}, xz));
  EXPECT_THROW(fit_axis_line(RotaryLetter::c, kPivot, std::vector{at(0), at(90), at(180)}, -1.0),
               InputError);
  EXPECT_THROW(fit_axis_line(RotaryLetter::c, {kNaN, 0, 0}, std::vector{at(0), at(90), at(180)}),
               InputError);
}

}  // namespace
