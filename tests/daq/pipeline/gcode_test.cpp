// Part programs against text written out by hand.
#include "cal/daq/gcode.hpp"

#include <gtest/gtest.h>

#include <limits>

#include "cal/analysis/error.hpp"

namespace {

using namespace cal::daq;
using cal::iso230_2::Direction;
using cal::iso230_2::MoveKind;

// Two targets, one run up: reposition to -2, measure 0 and 10, over-run to 12.
cal::iso230_2::Plan tiny() {
  cal::iso230_2::Plan p;
  p.targets_mm = {0, 10};
  p.moves = {{MoveKind::reposition, 1, Direction::up, 0, -2.0},
             {MoveKind::measure, 1, Direction::up, 1, 0.0},
             {MoveKind::measure, 1, Direction::up, 2, 10.0},
             {MoveKind::overrun, 1, Direction::up, 0, 12.0}};
  return p;
}

TEST(Gcode, LinearFanucDwellInMilliseconds) {
  EXPECT_EQ(linear_program(tiny(), {}, Dialect::fanuc),
            "%\nO1000 (ISO 230-2 test of X: 2 targets, 4 moves)\nG21 G90 G17 G94\n"
            "G01 X-2.0000 F2000\nG01 X0.0000 F2000\nG04 P4000\nG01 X10.0000 F2000\nG04 P4000\n"
            "G01 X12.0000 F2000\nM30\n%\n");
}

TEST(Gcode, LinearHeidenhainNumberedWithDwellCycle) {
  EXPECT_EQ(linear_program(tiny(), {.dwell_s = 2.5}, Dialect::heidenhain),
            "0 BEGIN PGM ISO2302 MM\n1 ; ISO 230-2 test of X: 2 targets, 4 moves\n"
            "2 L X-2.0000 F2000\n3 L X+0.0000 F2000\n4 CYCL DEF 9.0 DWELL TIME\n5 CYCL DEF 9.1 "
            "DWELL 2.5000\n"
            "6 L X+10.0000 F2000\n7 CYCL DEF 9.0 DWELL TIME\n8 CYCL DEF 9.1 DWELL 2.5000\n"
            "9 L X+12.0000 F2000\n10 END PGM ISO2302 MM\n");
}

TEST(Gcode, LinearSiemensDwellInSeconds) {
  EXPECT_EQ(
      linear_program(tiny(), {.axis = 'Y', .feed_mm_per_min = 1500}, Dialect::siemens),
      "; ISO 230-2 test of Y: 2 targets, 4 moves\nG71 G90 G17 G94\nG1 Y-2.0000 F1500\n"
      "G1 Y0.0000 F1500\nG4 F4.0000\nG1 Y10.0000 F1500\nG4 F4.0000\nG1 Y12.0000 F1500\nM30\n");
}

TEST(Gcode, CircleInHalfCircleArcs) {
  // R 10 about (0, 0), no overshoot: feed-in from (11.5, 0) to (10, 0), then ccw 0 -> 180 ->
  // 360 (centre offsets I from each arc's start: -10, then +10), dwell, cw back.
  const BallbarProgram b{.radius_mm = 10,
                         .feed_mm_per_min = 1000,
                         .feed_in_mm = 1.5,
                         .dwell_s = 1,
                         .overshoot_deg = 0};
  EXPECT_EQ(
      circle_program(b, {}, Dialect::fanuc),
      "%\nO1000 (ballbar circle R 10.0000 mm at F1000, overshoot 0.0000 deg)\nG21 G90 G17 G94\n"
      "G01 X11.5000 Y0.0000 F1000\nG01 X10.0000 Y0.0000 F1000\nG04 P1000\n"
      "G03 X-10.0000 Y0.0000 I-10.0000 J0.0000 F1000\nG03 X10.0000 Y0.0000 I10.0000 J0.0000 F1000\n"
      "G04 P1000\n"
      "G02 X-10.0000 Y0.0000 I-10.0000 J0.0000 F1000\nG02 X10.0000 Y0.0000 I10.0000 J0.0000 F1000\n"
      "G01 X11.5000 Y0.0000 F1000\nM30\n%\n");
  const std::string h = circle_program(b, {}, Dialect::heidenhain);
  EXPECT_NE(h.find("CC X+0.0000 Y+0.0000\n"), std::string::npos) << h;
  EXPECT_NE(h.find("C X-10.0000 Y+0.0000 DR+ F1000\n"), std::string::npos) << h;
  EXPECT_NE(h.find("C X+10.0000 Y+0.0000 DR- F1000\n"), std::string::npos) << h;
  const std::string s = circle_program(b, {}, Dialect::siemens);
  EXPECT_NE(s.find("G3 X-10.0000 Y0.0000 I=-10.0000 J=0.0000 F1000\n"), std::string::npos) << s;
}

TEST(Gcode, LinearFanucDwellInSecondsWithX) {
  // The same program with G04 X (seconds, decimal point) instead of G04 P (ms).
  EXPECT_EQ(
      linear_program(tiny(), {.dwell_s = 2.5, .fanuc_dwell = FanucDwell::x_s}, Dialect::fanuc),
      "%\nO1000 (ISO 230-2 test of X: 2 targets, 4 moves)\nG21 G90 G17 G94\n"
      "G01 X-2.0000 F2000\nG01 X0.0000 F2000\nG04 X2.500\nG01 X10.0000 F2000\nG04 X2.500\n"
      "G01 X12.0000 F2000\nM30\n%\n");
}

TEST(Gcode, DwellMustOutlastTheTriggerDwellPlusSettling) {
  // Trigger dwell 1.5 s + 0.5 s of settling = 2 s: 1.9 s and exactly 2 s are refused, 2.1 s is
  // accepted.
  const LinearProgram too_short{.dwell_s = 1.9, .trigger_dwell_s = 1.5};
  EXPECT_THROW(linear_program(tiny(), too_short, Dialect::siemens), cal::InputError);
  EXPECT_THROW(linear_program(tiny(), {.dwell_s = 2.0, .trigger_dwell_s = 1.5}, Dialect::fanuc),
               cal::InputError);
  EXPECT_NO_THROW(
      linear_program(tiny(), {.dwell_s = 2.1, .trigger_dwell_s = 1.5}, Dialect::heidenhain));
  try {
    linear_program(tiny(), too_short, Dialect::fanuc);
  } catch (const cal::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("program at least 2 s"), std::string::npos) << e.what();
  }
}

// R 10 in the ZX plane (G18) about X 5, Z -20, by radius: u = Z, v = X, so the ccw (G03) circle
// runs from +Z towards +X. Start at 0 deg: (Z -10, X 5); feed-in from 2 mm outside (Z -8).
// Without overshoot, 360 deg in 4 quarter arcs: ccw through (X 15, Z -20), (X 5, Z -30),
// (X -5, Z -20), back to (X 5, Z -10); cw back the other way.
TEST(Gcode, CircleInTheZxPlaneByRadiusInQuarterArcs) {
  const BallbarProgram b{
      .radius_mm = 10, .feed_mm_per_min = 500, .feed_in_mm = 2, .dwell_s = 2, .overshoot_deg = 0};
  const CircleProgramSetup zx{
      .centre_x_mm = 5, .centre_z_mm = -20, .plane = Plane::zx, .arcs = ArcForm::radius};
  EXPECT_EQ(circle_program(b, zx, Dialect::fanuc),
            "%\nO1000 (ballbar circle R 10.0000 mm at F500, overshoot 0.0000 deg)\n"
            "G21 G90 G18 G94\n"
            "G01 X5.0000 Z-8.0000 F500\nG01 X5.0000 Z-10.0000 F500\nG04 P2000\n"
            "G03 X15.0000 Z-20.0000 R10.0000 F500\nG03 X5.0000 Z-30.0000 R10.0000 F500\n"
            "G03 X-5.0000 Z-20.0000 R10.0000 F500\nG03 X5.0000 Z-10.0000 R10.0000 F500\n"
            "G04 P2000\n"
            "G02 X-5.0000 Z-20.0000 R10.0000 F500\nG02 X5.0000 Z-30.0000 R10.0000 F500\n"
            "G02 X15.0000 Z-20.0000 R10.0000 F500\nG02 X5.0000 Z-10.0000 R10.0000 F500\n"
            "G01 X5.0000 Z-8.0000 F500\nM30\n%\n");
  EXPECT_EQ(
      circle_program(b, zx, Dialect::heidenhain),
      "0 BEGIN PGM BALLBAR MM\n"
      "1 ; ballbar circle R 10.0000 mm at F500, overshoot 0.0000 deg\n"
      "2 L X+5.0000 Z-8.0000 F500\n3 L X+5.0000 Z-10.0000 F500\n"
      "4 CYCL DEF 9.0 DWELL TIME\n5 CYCL DEF 9.1 DWELL 2.0000\n"
      "6 CR X+15.0000 Z-20.0000 R+10.0000 DR+ F500\n7 CR X+5.0000 Z-30.0000 R+10.0000 DR+ F500\n"
      "8 CR X-5.0000 Z-20.0000 R+10.0000 DR+ F500\n9 CR X+5.0000 Z-10.0000 R+10.0000 DR+ F500\n"
      "10 CYCL DEF 9.0 DWELL TIME\n11 CYCL DEF 9.1 DWELL 2.0000\n"
      "12 CR X-5.0000 Z-20.0000 R+10.0000 DR- F500\n13 CR X+5.0000 Z-30.0000 R+10.0000 DR- F500\n"
      "14 CR X+15.0000 Z-20.0000 R+10.0000 DR- F500\n15 CR X+5.0000 Z-10.0000 R+10.0000 DR- F500\n"
      "16 L X+5.0000 Z-8.0000 F500\n17 END PGM BALLBAR MM\n");
  // By centre, Heidenhain states the centre once, in the plane's two axes.
  const std::string h = circle_program(
      b, {.centre_x_mm = 5, .centre_z_mm = -20, .plane = Plane::zx}, Dialect::heidenhain);
  EXPECT_NE(h.find("CC X+5.0000 Z-20.0000\n"), std::string::npos) << h;
  EXPECT_NE(h.find("C X+5.0000 Z-30.0000 DR+ F500\n"), std::string::npos) << h;
}

TEST(Gcode, SiemensYzPlaneByCentreAndByRadius) {
  // R 10 about the origin in YZ (G19): u = Y, v = Z. From (Y 10, Z 0) the first half circle
  // ends at (Y -10, Z 0) with the centre -10 in Y from the start (J=-10, K=0); by radius the
  // first quarter ends at (Y 0, Z 10).
  const BallbarProgram b{.radius_mm = 10, .feed_mm_per_min = 500, .overshoot_deg = 0};
  const std::string c = circle_program(b, {.plane = Plane::yz}, Dialect::siemens);
  EXPECT_NE(c.find("G71 G90 G19 G94\n"), std::string::npos) << c;
  EXPECT_NE(c.find("G1 Y11.5000 Z0.0000 F500\n"), std::string::npos) << c;
  EXPECT_NE(c.find("G3 Y-10.0000 Z0.0000 J=-10.0000 K=0.0000 F500\n"), std::string::npos) << c;
  EXPECT_NE(c.find("G4 F1.0000\n"), std::string::npos) << c;
  const std::string r =
      circle_program(b, {.plane = Plane::yz, .arcs = ArcForm::radius}, Dialect::siemens);
  EXPECT_NE(r.find("G3 Y0.0000 Z10.0000 CR=10.0000 F500\n"), std::string::npos) << r;
  EXPECT_NE(r.find("G2 Y0.0000 Z-10.0000 CR=10.0000 F500\n"), std::string::npos) << r;
}

TEST(Gcode, OvershootSplitsTheSweepEvenly) {
  // Overshoot 45 deg: 450 deg per direction. By centre: 3 pieces of 150 deg; from 0 deg the ccw
  // arcs end at 150, 300 and 450 = 90 deg, i.e. (R cos 150, R sin 150) = (-8.6603, 5.0000) ...
  const BallbarProgram b{.radius_mm = 10, .feed_mm_per_min = 1000, .overshoot_deg = 45};
  const std::string f = circle_program(b, {}, Dialect::fanuc);
  EXPECT_NE(f.find("G03 X-8.6603 Y5.0000 I-10.0000 J0.0000 F1000\n"), std::string::npos) << f;
  EXPECT_NE(f.find("G03 X0.0000 Y10.0000 I-5.0000 J8.6603 F1000\n"), std::string::npos) << f;
  // ... and the cw arcs go back from 90 deg: 90 - 150 = -60 deg, (5.0000, -8.6603).
  EXPECT_NE(f.find("G02 X5.0000 Y-8.6603 I0.0000 J-10.0000 F1000\n"), std::string::npos) << f;
  auto count = [](const std::string& t, const std::string& what) {
    std::size_t n = 0;
    for (auto at = t.find(what); at != std::string::npos; at = t.find(what, at + 1)) ++n;
    return n;
  };
  EXPECT_EQ(count(f, "G03 "), 3u);
  EXPECT_EQ(count(f, "G02 "), 3u);
  // By radius: 450 / 90 = 5 quarter arcs each way.
  const std::string r = circle_program(b, {.arcs = ArcForm::radius}, Dialect::fanuc);
  EXPECT_EQ(count(r, "G03 "), 5u);
  EXPECT_EQ(count(r, "G02 "), 5u);
}

TEST(Gcode, PlaneNames) {
  EXPECT_EQ(plane_from_string("xy"), Plane::xy);
  EXPECT_EQ(plane_from_string("XZ"), Plane::zx);
  EXPECT_EQ(plane_from_string("G18"), Plane::zx);
  EXPECT_EQ(plane_from_string("YZ"), Plane::yz);
  EXPECT_THROW(plane_from_string("XX"), cal::InputError);
}

TEST(Gcode, RefusesBadSettings) {
  EXPECT_THROW(linear_program(tiny(), {.dwell_s = 0}, Dialect::fanuc), cal::InputError);
  EXPECT_THROW(dialect_from_string("mazak"), cal::InputError);
  EXPECT_THROW(circle_program({.radius_mm = -1}, {}, Dialect::fanuc), cal::InputError);
  EXPECT_THROW(linear_program(tiny(), {.axis = 'Q'}, Dialect::fanuc), cal::InputError);
  EXPECT_THROW(linear_program(tiny(), {.feed_mm_per_min = 0}, Dialect::fanuc), cal::InputError);
  EXPECT_THROW(linear_program({}, {}, Dialect::fanuc), cal::InputError);  // no moves
}

// Issue 15: nothing non-finite, absurd or outside the dialect's syntax reaches a program,
// whatever the caller checked before.
TEST(Gcode, NeverWritesNonFiniteOrAbsurdNumbers) {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  constexpr double inf = std::numeric_limits<double>::infinity();
  for (const auto d : {Dialect::fanuc, Dialect::heidenhain, Dialect::siemens}) {
    EXPECT_THROW(circle_program({.radius_mm = inf}, {}, d), cal::InputError);
    EXPECT_THROW(circle_program({.radius_mm = 10}, {.centre_x_mm = nan}, d), cal::InputError);
    EXPECT_THROW(circle_program({.radius_mm = 10}, {.centre_y_mm = inf}, d), cal::InputError);
    EXPECT_THROW(circle_program({.radius_mm = 10, .feed_mm_per_min = inf}, {}, d), cal::InputError);
    EXPECT_THROW(circle_program({.radius_mm = 10, .overshoot_deg = 1e9}, {}, d), cal::InputError);
    EXPECT_THROW(linear_program(tiny(), {.feed_mm_per_min = nan}, d), cal::InputError);
    EXPECT_THROW(linear_program(tiny(), {.dwell_s = inf}, d), cal::InputError);
    cal::iso230_2::Plan far = tiny();
    far.moves.front().position_mm = -1e9;  // what overrun_mm = 1e9 gave: G01 X-1000000000
    EXPECT_THROW(linear_program(far, {}, d), cal::InputError);
    far.moves.front().position_mm = nan;
    EXPECT_THROW(linear_program(far, {}, d), cal::InputError);
  }
  // A refused program is refused whole: no partial text with "nan" or "inf" comes back.
  try {
    circle_program({.radius_mm = 10}, {.centre_x_mm = nan}, Dialect::fanuc);
    FAIL();
  } catch (const cal::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not a finite value"), std::string::npos) << e.what();
  }
}

TEST(Gcode, ProgramNamesStayWithinTheSyntax) {
  // Heidenhain writes the name into BEGIN PGM; a line break would start a new block.
  EXPECT_THROW(linear_program(tiny(), {.name = "A\nM30"}, Dialect::heidenhain), cal::InputError);
  EXPECT_THROW(linear_program(tiny(), {.name = "A B"}, Dialect::heidenhain), cal::InputError);
  EXPECT_THROW(linear_program(tiny(), {.name = ""}, Dialect::fanuc), cal::InputError);
  EXPECT_THROW(circle_program({.radius_mm = 10}, {.name = "X)M30("}, Dialect::fanuc),
               cal::InputError);
  EXPECT_NE(linear_program(tiny(), {.name = "AXIS_X2"}, Dialect::heidenhain)
                .find("0 BEGIN PGM AXIS_X2 MM"),
            std::string::npos);
}

}  // namespace
