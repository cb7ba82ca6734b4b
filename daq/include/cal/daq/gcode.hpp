#pragma once
// Part programs for the tests, in the dialects of the common controls (docs/circle.md, "The
// standard set and its part program", has the syntax of each and where it comes from):
// - Fanuc / ISO 6983: G90 G01 X.. F..; dwell G04 P<ms> (P counts ms, no decimal point) or
//   G04 X<s> (seconds, decimal point); arcs G02 (cw) / G03 (ccw) with the incremental centre
//   I J (G17), I K (G18) or J K (G19), or with R (+ for arcs up to 180 degrees); M30.
// - Heidenhain conversational: BEGIN PGM .. MM, L X+.. F..; dwell CYCL DEF 9.0 DWELL TIME /
//   CYCL DEF 9.1 DWELL <s>; arcs by the centre CC X.. Y.. (absolute) and C X.. Y.. DR+ (ccw) /
//   DR- (cw), or CR X.. Y.. R+.. DR+/-; END PGM.
// - Siemens SINUMERIK: G90 G1 X.. F..; dwell G4 F<s>; arcs G2/G3 with I= J= (incremental
//   centre, the SINUMERIK default) or CR=+..; M30.
// The ISO 230-2 program visits every move of the plan in the plan's order (measure, over-run,
// reposition) with a dwell at each measure move; the circle program feeds in along the radius,
// dwells, runs the ccw circle with its overshoot arcs before and after, dwells, runs the cw
// circle back, and feeds out, matching BallbarSegmenter. Numbers are written with 4 decimals
// (0.1 um: below any machine's programming resolution, so nothing is rounded twice).
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cal/analysis/iso230_2_targets.hpp"
#include "cal/daq/ballbar.hpp"

namespace cal::daq {

enum class Dialect { fanuc, heidenhain, siemens };
Dialect dialect_from_string(std::string_view s);  // fanuc | iso | heidenhain | siemens | sinumerik

// The working plane of a circle. The in-plane axes (u, v) are ordered so that a turn from u to
// v is counter-clockwise seen from the positive third axis (u x v = w, right-handed), which is
// the sense of G03 / DR+ in every dialect: XY (G17), ZX (G18: u = Z, v = X), YZ (G19).
enum class Plane { xy, zx, yz };
Plane plane_from_string(std::string_view s);  // XY | ZX | XZ | YZ (any case); G17 | G18 | G19

// How arcs are written: by their centre (I J K / CC) or by their radius (R / CR=). Radius arcs
// are split into pieces of at most 90 degrees: an arc of exactly 180 degrees by radius is
// ill-conditioned (the rounded end point can lie a hair more than 2R from the start) and
// controls alarm on it.
enum class ArcForm { centre, radius };

// Fanuc's dwell word: P in milliseconds (integer) or X in seconds (with a decimal point).
enum class FanucDwell { p_ms, x_s };

struct LinearProgram {
  char axis = 'X';
  double feed_mm_per_min = 2000.0;
  double dwell_s = 4.0;  // at each measure move
  std::string name = "ISO2302";
  // The stability trigger's dwell: when > 0 the program's dwell must exceed it by at least
  // settle_s (the servo settles for a while after the block ends; the trigger needs dwell_s of
  // stillness after that), else InputError.
  double trigger_dwell_s = 0.0;
  double settle_s = 0.5;
  FanucDwell fanuc_dwell = FanucDwell::p_ms;
};

std::string linear_program(const iso230_2::Plan& plan, const LinearProgram& p, Dialect d);

struct CircleProgramSetup {
  // The centre of the circle (the table ball); only the plane's two coordinates are used.
  double centre_x_mm = 0.0, centre_y_mm = 0.0, centre_z_mm = 0.0;
  std::string name = "BALLBAR";
  Plane plane = Plane::xy;
  ArcForm arcs = ArcForm::centre;
  FanucDwell fanuc_dwell = FanucDwell::p_ms;
};

// By centre, arcs are split into pieces of at most 180 degrees (a full circle in one block is
// not portable between controls); by radius, at most 90 degrees (see ArcForm).
std::string circle_program(const BallbarProgram& b, const CircleProgramSetup& s, Dialect d);

std::string plane_name(Plane p);  // "XY", "ZX", "YZ"

// One test of a ballbar set: its plane and its program (radius, feed, arc, start, overshoot).
struct BallbarSetTest {
  Plane plane = Plane::xy;
  BallbarProgram program;
};

// The standard set (docs/circle.md, "The standard set"; the numbers are caldaq's defaults, not a
// standard's: public material gives no template): for each radius, each plane, each feed in
// that order. XY is a full circle measured from 0 deg (the ccw move starts there, as a single
// test's); ZX and YZ are partial arcs of partial_arc_deg symmetric about +Z (the spindle is in
// the way of a full circle below the ball): ZX (Z first) measures -110..110 deg, YZ -20..200
// deg for 220 deg, each with partial_overshoot_deg before and after.
struct BallbarSetConfig {
  std::vector<Plane> planes{Plane::xy, Plane::zx, Plane::yz};
  std::vector<double> feeds_mm_per_min{1000.0};
  std::vector<double> radii_mm{100.0};
  double partial_arc_deg = 220.0;
  double overshoot_deg = 45.0;          // full circles
  double partial_overshoot_deg = 10.0;  // partial arcs: the tool stays above 30 deg below the ball
  double sample_rate_hz = 1000.0;
  double feed_in_mm = 1.5;
  double dwell_s = 1.0;
};
std::vector<BallbarSetTest> ballbar_set(const BallbarSetConfig& c);  // throws InputError

// The whole set in one program. Each test as circle_program writes one (feed-in, dwell, ccw
// arc with its overshoots, dwell, cw arc back, feed-out), with a comment naming it. Between
// tests the tool moves on the sphere of radius R + feed-in about the ball, so the bar stays
// on (the bar reads +feed-in throughout; the next feed-in starts the next test): one arc when
// both lie in one plane, else two through a pole on the axis the planes share (+-X between XY
// and ZX, +-Y between XY and YZ, +Z between ZX and YZ), never under the ball. Where the radius
// changes, the program stops (M00 / M0 / STOP) for the bar to come off, moves out along the
// radius to the new R + feed-in, and stops again for the new bar.
std::string circle_set_program(std::span<const BallbarSetTest> tests, const CircleProgramSetup& s,
                               Dialect d);

// One arc of the path between two tests on the sphere about the ball: in `plane`, from an
// angle (caldaq's, from the plane's first axis towards the second) by a signed sweep (+ ccw).
struct SetArc {
  Plane plane = Plane::xy;
  double from_deg = 0.0, sweep_deg = 0.0;
};
// The arcs circle_set_program writes from (p1, a1) to (p2, a2) on the sphere (the same path, so
// that the simulated machine runs what the program says).
std::vector<SetArc> ballbar_transition(Plane p1, double a1_deg, Plane p2, double a2_deg);

// A ballbar test on a rotary table axis in simultaneous motion (docs/kinematics.md, "The
// ballbar on a rotary axis"): every block moves the three linear axes and the rotary axis
// together by linear interpolation (G01 / L / G1 with X Y Z and the axis's word), in steps the
// caller chooses small enough that the bar stays within its range between the points; the
// program stops (M00 / STOP / M0) for the bar to be fitted at the first point and removed at the
// end, and dwells at each point where the bar is read. The coordinates are those of the
// spindle ball's centre (the tool tip) in the caller's coordinates; the angle is written as
// given. No tool-centre-point mode is used, so no control's kinematics enters the program.
struct RotaryProgramPoint {
  double x_mm = 0.0, y_mm = 0.0, z_mm = 0.0, angle_deg = 0.0;
  bool measure = false;  // dwell here: the bar is read at this point
};
struct RotaryProgramSetup {
  std::string name = "BB5X";
  char rotary = 'C';  // A, B or C
  double feed_mm_per_min = 500.0;
  double dwell_s = 2.0;
  // The program's title comment: letters, digits, spaces and - . , : = + / only (InputError
  // otherwise: a parenthesis or a semicolon would end a comment early in some dialect).
  std::string what;
  FanucDwell fanuc_dwell = FanucDwell::p_ms;
};
std::string rotary_ballbar_program(std::span<const RotaryProgramPoint> points,
                                   const RotaryProgramSetup& s, Dialect d);

}  // namespace cal::daq
