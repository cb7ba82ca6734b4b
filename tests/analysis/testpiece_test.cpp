// The test piece: predictions against hand-derived values for machines with one known error,
// and the CMM evaluation against points written out here with known faces and circles.
#include "cal/analysis/testpiece.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <numbers>

#include "cal/analysis/error.hpp"

namespace {

using namespace cal::testpiece;
namespace kin = cal::kinematics;
using cal::InputError;

// Default layout: side 100 mm (faces at +-50), bore0 R = 15 at the centre, corner bores R = 8 at
// (+-30, +-30); tool radius 5 mm; the part's origin at (0, 0, -50) unless stated.
Result predict(const kin::Machine& m, const kin::Vec3& origin = {0.0, 0.0, -50.0}) {
  const Layout l;
  Cutting s;
  s.origin_mm = origin;
  s.tool_radius_mm = 5.0;
  return evaluate(l, predict_profiles(m, l, s));
}

std::map<std::string, BoreResult> by_name(const Result& r) {
  std::map<std::string, BoreResult> m;
  for (const auto& b : r.bores) m[b.feature] = b;
  return m;
}

// Only squareness, E_C0Y = 30 urad (x error -30e-3 y um). The Y faces lean: deviation in +X
// -30e-3 y, slope k = -30 um/m; the X faces stay straight along X (m = 0): every corner's
// squareness -(m + k) = +30 um/m, the squareness of the machine itself. Parallel faces stay
// parallel, faces straight. Bores: the tool centre runs on radius R - r, its x error
// -c (R - r) sin t gives the radial deviation -(c (R - r) / 2) sin 2t: circularity
// c (R - r) = 30e-3 * 10 = 0.3 um for bore0; bore1 at (30, 30) shifts by -c * 30 = -0.9 um in x.
TEST(TestPiece, OnlySquarenessGivesTheFacesSquareness) {
  kin::Machine m;
  m.squareness.c0y_urad = 30.0;
  const Result r = predict(m);
  ASSERT_EQ(r.squareness_um_per_m.size(), 4u);
  for (const auto& [corner, v] : r.squareness_um_per_m) EXPECT_NEAR(v, 30.0, 1e-6) << corner;
  for (const auto& [pair, v] : r.parallelism_um_per_m) EXPECT_NEAR(v, 0.0, 1e-6) << pair;
  for (const auto& f : r.faces) EXPECT_NEAR(f.straightness_um, 0.0, 1e-6) << f.feature;
  const auto b = by_name(r);
  EXPECT_NEAR(b.at("bore0").circularity_um, 0.3, 1e-4);
  EXPECT_NEAR(b.at("bore1").position_x_um, -0.9, 1e-6);
  EXPECT_NEAR(b.at("bore3").position_x_um, 0.9, 1e-6);
  EXPECT_NEAR(b.at("bore1").position_y_um, 0.0, 1e-4);  // exact model: y (cos - 1) ~ 1e-5 um
  EXPECT_TRUE(r.aligned);
}

// Only yaw of X, E_CX = 20 urad, FXYZ (X carries Y and Z): the x error is -E_CX (y + ty), the
// Abbe term of the yaw with the arm from X's reference point to the cutting edge. Bores one
// above the other are offset in x by -E_CX times their distance in y: bore1 (y = 30) against
// bore0 (y = 0): -20e-6 * 30 mm = -0.6 um, wherever the part sits (origin at y = 150 here: both
// move by -3 um, the relative -0.6 stays). The Y faces lean by the yaw (k = -20 um/m), so the
// part is out of square by +20 um/m. Circularity: the edge's arm differs from the centre's by
// r u, so the sin 2t term is E_CX (R - r): 0.2 um for bore0.
TEST(TestPiece, OnlyYawGivesTheAbbeTerm) {
  kin::Machine m;
  m.axes[kin::X].ec_urad = kin::ErrorFunction::polynomial({20.0});
  m.tool_offset_mm = {0.0, 0.0, -100.0};
  const Result r = predict(m, {200.0, 150.0, -50.0});
  const auto b = by_name(r);
  EXPECT_NEAR(b.at("bore1").position_x_um, -0.6, 1e-6);
  EXPECT_NEAR(b.at("bore2").position_x_um, -0.6, 1e-6);  // also at y = +30
  EXPECT_NEAR(b.at("bore3").position_x_um, 0.6, 1e-6);   // at y = -30
  EXPECT_NEAR(b.at("bore1").position_y_um, 0.0, 1e-4);  // exact model: y (cos - 1) ~ 1e-5 um
  EXPECT_NEAR(b.at("bore0").circularity_um, 0.2, 1e-4);
  for (const auto& [corner, v] : r.squareness_um_per_m) EXPECT_NEAR(v, 20.0, 1e-6) << corner;
}

// CMM points written out: face-Y straight at y = -50; face+Y at y = 50 + 20e-6 x (20 um/m);
// face+X at x = 50 - 10e-6 y (-10 um/m); face-X at x = -50.001 but 3 um out at y = 0 (a bump:
// minimum-zone straightness 3 um). Corners -(m + k): (+Y, +X) -(20 - 10) = -10, (+Y, -X) -20,
// (-Y, +X) +10, (-Y, -X) 0 um/m; parallelism +Y/-Y 20, +X/-X -10 um/m. bore0: radius 15.002
// about (0.001, -0.002) mm: diameter error +4 um, the alignment's origin. bore1: radius 8 about
// (30.003, 30): raw centre (+3, 0) um, aligned (3 - 1, 0 + 2) = (2, 2) um. Tolerance 0.01 um:
// the linear circle fit errs by ~ offset^2 / R ~ 1e-3 um.
TEST(TestPiece, CmmPointsWithTheSameReferenceFits) {
  std::vector<Point> pts;
  for (int i = -4; i <= 4; ++i) {
    const double t = 10.0 * i;
    pts.push_back({"face-Y", t, -50.0});
    pts.push_back({"face+Y", t, 50.0 + 20e-6 * t});
    pts.push_back({"face+X", 50.0 - 10e-6 * t, t});
    pts.push_back({"face-X", -50.001 + (i == 0 ? 0.003 : 0.0), t});
  }
  for (int k = 0; k < 36; ++k) {
    const double a = 2 * std::numbers::pi * k / 36;
    pts.push_back({"bore0", 0.001 + 15.002 * std::cos(a), -0.002 + 15.002 * std::sin(a)});
    pts.push_back({"bore1", 30.003 + 8.0 * std::cos(a), 30.0 + 8.0 * std::sin(a)});
  }
  const Layout l;
  const Result r = evaluate(l, measured_profiles(l, pts));
  std::map<std::string, double> sq(r.squareness_um_per_m.begin(), r.squareness_um_per_m.end());
  EXPECT_NEAR(sq.at("face+Y / face+X"), -10.0, 1e-6);
  EXPECT_NEAR(sq.at("face+Y / face-X"), -20.0, 1e-6);
  EXPECT_NEAR(sq.at("face-Y / face+X"), 10.0, 1e-6);
  EXPECT_NEAR(sq.at("face-Y / face-X"), 0.0, 1e-6);
  std::map<std::string, double> par(r.parallelism_um_per_m.begin(), r.parallelism_um_per_m.end());
  EXPECT_NEAR(par.at("face+Y / face-Y"), 20.0, 1e-6);
  EXPECT_NEAR(par.at("face+X / face-X"), -10.0, 1e-6);
  for (const auto& f : r.faces)
    EXPECT_NEAR(f.straightness_um, f.feature == "face-X" ? 3.0 : 0.0, 1e-6) << f.feature;
  const auto b = by_name(r);
  EXPECT_NEAR(b.at("bore0").diameter_error_um, 4.0, 0.01);
  EXPECT_NEAR(b.at("bore0").position_x_um, 0.0, 1e-9);
  EXPECT_NEAR(b.at("bore1").position_x_um, 2.0, 0.01);
  EXPECT_NEAR(b.at("bore1").position_y_um, 2.0, 0.01);
  EXPECT_NEAR(b.at("bore1").circularity_um, 0.0, 0.01);
}

TEST(TestPiece, BadInputIsRefused) {
  const Layout l;
  EXPECT_THROW(measured_profiles(l, std::vector<Point>{{"face+Z", 0, 0}, {"face+Z", 1, 0}}),
               InputError);
  EXPECT_THROW(measured_profiles(l, std::vector<Point>{{"bore1", 38, 30}, {"bore1", 30, 38}}),
               InputError);
  EXPECT_THROW(measured_profiles(l, std::vector<Point>{{"face+X", NAN, 0}, {"face+X", 50, 1}}),
               InputError);
  Layout bad;
  bad.corner_bore_offset_mm = 48.0;  // outside the square
  EXPECT_THROW(validate(bad), InputError);
  Cutting s;
  s.tool_radius_mm = 9.0;  // does not fit the corner bores (radius 8)
  EXPECT_THROW(predict_profiles(kin::Machine{}, l, s), InputError);
}

// Issue 27: points on a straight line beside bore1 (centre (30, 30)) were fitted as a circle.
TEST(TestPiece, BorePointsOnOneSideAreRefused) {
  const Layout l;
  const std::vector<Point> line{{"bore1", 38, 26}, {"bore1", 38, 30}, {"bore1", 38, 34}};
  const auto profiles = measured_profiles(l, line);
  try {
    evaluate(l, profiles);
    FAIL() << "a line of points was fitted as a bore";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bore1: the points lie within half of the bore"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
