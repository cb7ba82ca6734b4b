// Part programs against text written out by hand.
#include "cal/daq/gcode.hpp"

#include <gtest/gtest.h>

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

TEST(Gcode, RefusesBadSettings) {
  EXPECT_THROW(linear_program(tiny(), {.dwell_s = 0}, Dialect::fanuc), cal::InputError);
  EXPECT_THROW(dialect_from_string("mazak"), cal::InputError);
  EXPECT_THROW(circle_program({.radius_mm = -1}, {}, Dialect::fanuc), cal::InputError);
}

}  // namespace
