// The standard ballbar set in one part program, checked move by move in every dialect by an
// interpreter written here from the dialects' public rules (docs/circle.md, "Part programs"),
// not from the generator's code:
// - ISO / Fanuc and SINUMERIK: G17 XY, G18 ZX, G19 YZ; G02/G2 clockwise, G03/G3
//   counter-clockwise, seen from the positive end of the axis normal to the plane (Z, Y, X),
//   i.e. G03 is a positive (right-hand) rotation about +Z, +Y, +X; I, J, K the centre relative
//   to the arc's start point.
// - HEIDENHAIN: CC names the centre in two axes, which give the plane in the order X/Y, Y/Z,
//   Z/X; C to the end point with DR+ (mathematically positive, the same right-hand rotation
//   about the normal of that ordered pair) or DR-.
// Every arc's start and end must lie on its circle; every point of every move is checked against
// the ball (on the test's circle, on the feed-in line, or on the sphere of R + feed-in between
// tests) and never more than 30 degrees below the ball.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <numbers>
#include <regex>
#include <sstream>

#include "cal/analysis/error.hpp"
#include "cal/daq/gcode.hpp"

namespace {

using namespace cal::daq;
using V = std::array<double, 3>;
constexpr double pi = std::numbers::pi;

V add(V a, V b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
V sub(V a, V b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
double dot(V a, V b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V cross(V a, V b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double norm(V a) { return std::sqrt(dot(a, a)); }
// Rotation of v about the unit axis n by phi (right-hand rule, Rodrigues).
V rotate(V v, V n, double phi) {
  const V c = cross(n, v);
  const double k = dot(n, v) * (1 - std::cos(phi));
  V out;
  for (int i = 0; i < 3; ++i)
    out[static_cast<std::size_t>(i)] = v[static_cast<std::size_t>(i)] * std::cos(phi) +
                                       c[static_cast<std::size_t>(i)] * std::sin(phi) +
                                       n[static_cast<std::size_t>(i)] * k;
  return out;
}

struct Move {
  bool arc = false;
  V from{}, to{};
  V centre{}, normal{};  // arcs: the rotation axis (the plane's normal, + = G03 / DR+)
  double sweep = 0.0;    // arcs: signed angle about `normal`, radians
  std::string block;
  // A point along the move, f in [0, 1].
  V at(double f) const {
    if (!arc)
      return add(from, {f * (to[0] - from[0]), f * (to[1] - from[1]), f * (to[2] - from[2])});
    return add(centre, rotate(sub(from, centre), normal, f * sweep));
  }
};

// The signed angle from a to b about n, in (0, 2 pi] for positive, [-2 pi, 0) for negative.
double sweep_about(V a, V b, V n, bool positive) {
  double phi = std::atan2(dot(n, cross(a, b)), dot(a, b));
  if (positive && phi <= 1e-12) phi += 2 * pi;
  if (!positive && phi >= -1e-12) phi -= 2 * pi;
  return phi;
}

std::map<char, double> words(const std::string& line) {
  std::map<char, double> w;
  static const std::regex word(R"(([A-Z])=?([+-]?[0-9]+(\.[0-9]+)?))");
  for (std::sregex_iterator it(line.begin(), line.end(), word), end; it != end; ++it)
    w[(*it)[1].str()[0]] = std::stod((*it)[2].str());
  return w;
}

// Interprets a program in a dialect into moves (feeds and dwells are not needed here).
std::vector<Move> interpret(const std::string& text, Dialect d, V start) {
  std::vector<Move> moves;
  V pos = start, cc{};
  V normal{0, 0, 1};
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (d == Dialect::heidenhain) line = line.substr(line.find(' ') + 1);  // the block number
    if (line.empty() || line[0] == ';' || line[0] == '(' || line[0] == '%') continue;
    if (d != Dialect::heidenhain) {
      if (line.find("G17") != std::string::npos) normal = {0, 0, 1};
      if (line.find("G18") != std::string::npos) normal = {0, 1, 0};
      if (line.find("G19") != std::string::npos) normal = {1, 0, 0};
    }
    const auto w = words(line);
    V target = pos;
    for (int k = 0; k < 3; ++k)
      if (w.count(static_cast<char>('X' + k)))
        target[static_cast<std::size_t>(k)] = w.at(static_cast<char>('X' + k));
    const bool linear =
        line.starts_with("G01 ") || line.starts_with("G1 ") || line.starts_with("L ");
    if (d == Dialect::heidenhain && line.starts_with("CC ")) {
      cc = pos;
      for (int k = 0; k < 3; ++k)
        if (w.count(static_cast<char>('X' + k)))
          cc[static_cast<std::size_t>(k)] = w.at(static_cast<char>('X' + k));
      // The plane of the two axes named, ordered X/Y, Y/Z, Z/X.
      const bool x = w.count('X'), y = w.count('Y'), z = w.count('Z');
      normal = x && y ? V{0, 0, 1} : y && z ? V{1, 0, 0} : V{0, 1, 0};
      continue;
    }
    if (linear) {
      moves.push_back({false, pos, target, {}, {}, 0.0, line});
    } else if (line.starts_with("G02 ") || line.starts_with("G03 ") || line.starts_with("G2 ") ||
               line.starts_with("G3 ") || line.starts_with("C ")) {
      bool ccw = false;
      V centre = cc;
      if (d == Dialect::heidenhain) {
        ccw = line.find("DR+") != std::string::npos;
      } else {
        ccw = line.starts_with("G03 ") || line.starts_with("G3 ");
        centre = add(pos, {w.count('I') ? w.at('I') : 0.0, w.count('J') ? w.at('J') : 0.0,
                           w.count('K') ? w.at('K') : 0.0});
      }
      const V a = sub(pos, centre), b = sub(target, centre);
      EXPECT_NEAR(norm(a), norm(b), 2e-4) << line;  // both ends on the circle (4 decimals)
      EXPECT_NEAR(dot(a, normal), 0.0, 1e-9) << line;
      moves.push_back({true, pos, target, centre, normal, sweep_about(a, b, normal, ccw), line});
    } else {
      continue;  // dwell, stop, program start and end
    }
    pos = target;
  }
  return moves;
}

constexpr V kBall{10.0, 20.0, -300.0};
constexpr double kR = 100.0, kFeedIn = 1.5;

std::vector<BallbarSetTest> standard_set() {
  return ballbar_set({.feeds_mm_per_min = {500.0, 2000.0}, .radii_mm = {kR}});
}

CircleProgramSetup ball() {
  return {.centre_x_mm = kBall[0], .centre_y_mm = kBall[1], .centre_z_mm = kBall[2]};
}

TEST(BallbarSet, TheStandardSetIsThreePlanesAtEachFeed) {
  // XY 360 measured from 0 (the ccw move starts there, 45 deg overshoot); ZX 220 measured
  // -110..110 (symmetric about +Z at 0 deg, Z first), the move from -120; YZ 220 measured
  // -20..200 (+Z at 90 deg), the move from -30; 10 deg overshoot on the partial arcs.
  const auto set = standard_set();
  ASSERT_EQ(set.size(), 6u);
  const struct {
    Plane plane;
    double feed, arc, start, overshoot;
  } expected[] = {{Plane::xy, 500, 360, 0, 45},    {Plane::xy, 2000, 360, 0, 45},
                  {Plane::zx, 500, 220, -120, 10}, {Plane::zx, 2000, 220, -120, 10},
                  {Plane::yz, 500, 220, -30, 10},  {Plane::yz, 2000, 220, -30, 10}};
  for (std::size_t i = 0; i < set.size(); ++i) {
    EXPECT_EQ(set[i].plane, expected[i].plane) << i;
    EXPECT_EQ(set[i].program.feed_mm_per_min, expected[i].feed) << i;
    EXPECT_EQ(set[i].program.arc_deg, expected[i].arc) << i;
    EXPECT_EQ(set[i].program.start_deg, expected[i].start) << i;
    EXPECT_EQ(set[i].program.overshoot_deg, expected[i].overshoot) << i;
    EXPECT_EQ(set[i].program.radius_mm, kR) << i;
  }
}

// The expected unit direction of the tool from the ball at an angle of a plane (u, v as G17,
// G18, G19 order them: X/Y, Z/X, Y/Z), written out per plane.
V dir(Plane p, double deg) {
  const double c = std::cos(deg * pi / 180), s = std::sin(deg * pi / 180);
  if (p == Plane::zx) return {s, 0, c};  // u = Z, v = X
  if (p == Plane::yz) return {0, c, s};  // u = Y, v = Z
  return {c, s, 0};
}
V point(Plane p, double deg, double r) {
  const V d = dir(p, deg);
  return add(kBall, {r * d[0], r * d[1], r * d[2]});
}

void check_program(Dialect d) {
  const auto set = standard_set();
  const std::string text = circle_set_program(set, ball(), d);
  SCOPED_TRACE(text);
  const auto moves = interpret(text, d, kBall);
  // Every point of every move: at most 30 degrees below the ball (the partial arcs' ends with
  // their overshoot: sin 30 deg = 0.5), and at the radius its move is for.
  for (const auto& m : moves)
    for (double f = 0; f <= 1.0; f += 0.05) {
      const V p = m.at(f);
      EXPECT_GE(p[2] - kBall[2], -0.5 * (kR + kFeedIn) - 1e-3) << m.block << " at " << f;
    }
  // Walk the tests: feed-in, ccw arcs, cw arcs, feed-out; transitions between them on the
  // sphere of R + feed-in.
  std::size_t i = 1;  // moves[0] is the first approach to the first start point
  EXPECT_NEAR(norm(sub(moves[0].to, point(Plane::xy, 0, kR + kFeedIn))), 0.0, 1e-4);
  for (std::size_t t = 0; t < set.size(); ++t) {
    const auto& [plane, b] = set[t];
    SCOPED_TRACE(::testing::Message() << "test " << t + 1 << " " << plane_name(plane));
    // Transition arcs: radius R + feed-in about the ball, ending at this test's start point.
    while (i < moves.size() && moves[i].arc) {
      EXPECT_NEAR(norm(sub(moves[i].from, kBall)), kR + kFeedIn, 1e-3) << moves[i].block;
      EXPECT_NEAR(norm(sub(moves[i].centre, kBall)), 0.0, 1e-4) << moves[i].block;
      ++i;
    }
    ASSERT_LT(i, moves.size());
    EXPECT_NEAR(norm(sub(moves[i - 1].to, point(plane, b.start_deg, kR + kFeedIn))), 0.0, 2e-4);
    // The feed-in: a straight move along the radius to the circle.
    ASSERT_FALSE(moves[i].arc) << moves[i].block;
    EXPECT_NEAR(norm(sub(moves[i].to, point(plane, b.start_deg, kR))), 0.0, 2e-4) << moves[i].block;
    ++i;
    // The ccw arcs: in the test's plane about the ball, positive about its normal, together the
    // arc and both overshoots; their middle is over the ball (+Z) for the vertical planes.
    const double sweep = (b.arc_deg + 2 * b.overshoot_deg) * pi / 180;
    const V normal = cross(dir(plane, 0), dir(plane, 90));
    double ccw = 0.0;
    const V ccw_start = moves[i].from;
    while (i < moves.size() && moves[i].arc && moves[i].sweep > 0) {
      EXPECT_NEAR(norm(sub(moves[i].normal, normal)), 0.0, 1e-12) << moves[i].block;
      EXPECT_NEAR(norm(sub(moves[i].centre, kBall)), 0.0, 1e-4) << moves[i].block;
      ccw += moves[i++].sweep;
    }
    EXPECT_NEAR(ccw, sweep, 1e-6);
    if (plane != Plane::xy) {
      const V middle = add(kBall, rotate(sub(ccw_start, kBall), normal, sweep / 2));
      EXPECT_NEAR(middle[2] - kBall[2], kR, 1e-3) << "the arc runs over the top";
    }
    // The cw arcs back, the same sweep negative, ending where the ccw ones started.
    double cw = 0.0;
    while (i < moves.size() && moves[i].arc && moves[i].sweep < 0) cw += moves[i++].sweep;
    EXPECT_NEAR(cw, -sweep, 1e-6);
    EXPECT_NEAR(norm(sub(moves[i - 1].to, point(plane, b.start_deg, kR))), 0.0, 2e-4);
    // The feed-out, back to R + feed-in.
    ASSERT_FALSE(moves[i].arc) << moves[i].block;
    EXPECT_NEAR(norm(sub(moves[i].to, point(plane, b.start_deg, kR + kFeedIn))), 0.0, 2e-4);
    ++i;
  }
  EXPECT_EQ(i, moves.size());
}

TEST(BallbarSet, FanucProgramMoveByMove) { check_program(Dialect::fanuc); }
TEST(BallbarSet, SiemensProgramMoveByMove) { check_program(Dialect::siemens); }
TEST(BallbarSet, HeidenhainProgramMoveByMove) { check_program(Dialect::heidenhain); }

TEST(BallbarSet, G18ArcsAreWrittenInTheZxOrder) {
  // The ZX test's feed-in and first ccw arc, by hand: the feed-in ends at
  // Z = -300 + 100 cos(-120) = -350, X = 10 + 100 sin(-120) = -76.6025; G03 (positive about +Y:
  // from -Z/-X up over the top) by 120 deg (the ccw move's 240 deg in two pieces) to angle 0:
  // Z = -200, X = 10; I and K the centre from the start: +86.6025, +50.
  const auto set = standard_set();
  const std::string f = circle_set_program(set, ball(), Dialect::fanuc);
  EXPECT_NE(f.find("G01 X-76.6025 Z-350.0000 F500\nG04 P1000\n"
                   "G03 X10.0000 Z-200.0000 I86.6025 K50.0000 F500\n"),
            std::string::npos)
      << f;
  EXPECT_NE(f.find("(TEST 3 OF 6: ZX 220 DEG R100.0000 F500)"), std::string::npos) << f;
  const std::string h = circle_set_program(set, ball(), Dialect::heidenhain);
  EXPECT_NE(h.find("CC X+10.0000 Z-300.0000\n"), std::string::npos) << h;
  EXPECT_NE(h.find("C X+10.0000 Z-200.0000 DR+ F500\n"), std::string::npos) << h;
  const std::string s = circle_set_program(set, ball(), Dialect::siemens);
  EXPECT_NE(s.find("G3 X10.0000 Z-200.0000 I=86.6025 K=50.0000 F500\n"), std::string::npos) << s;
}

TEST(BallbarSet, SeveralRadiiStopForTheBarChange) {
  // Two radii: after the last test of R 100 the program stops, moves out along the radius to
  // R 150 + 1.5, and stops again for the new bar; the second radius' tests follow.
  const auto set = ballbar_set({.planes = {Plane::xy}, .radii_mm = {100.0, 150.0}});
  ASSERT_EQ(set.size(), 2u);
  const std::string f = circle_set_program(set, ball(), Dialect::fanuc);
  EXPECT_NE(f.find("(REMOVE THE R100.0000 BAR)\nM00\nG01 X161.5000 Y20.0000 F1000\n"
                   "(FIT THE R150.0000 BAR)\nM00\n"),
            std::string::npos)
      << f;
  EXPECT_NE(circle_set_program(set, ball(), Dialect::siemens).find("\nM0\n"), std::string::npos);
  EXPECT_NE(circle_set_program(set, ball(), Dialect::heidenhain).find(" STOP\n"),
            std::string::npos);
}

TEST(BallbarSet, RefusesAnEmptyOrBadSet) {
  EXPECT_THROW(ballbar_set({.planes = {}}), cal::InputError);
  EXPECT_THROW(ballbar_set({.feeds_mm_per_min = {}}), cal::InputError);
  EXPECT_THROW(ballbar_set({.partial_arc_deg = 170}), cal::InputError);
  EXPECT_THROW(ballbar_set({.feeds_mm_per_min = {-5}}), cal::InputError);
  EXPECT_THROW(ballbar_set({.radii_mm = {std::nan("")}}), cal::InputError);
  EXPECT_THROW(circle_set_program({}, ball(), Dialect::fanuc), cal::InputError);
}

}  // namespace
