// The three-plane table against a machine with known errors: the bar lengths are computed here
// from the machine's geometry as docs/kinematics.md states it (not from the circle model), the
// three planes are analysed as tests (XY 360 deg, ZX and YZ 220 deg over the top, both
// directions), and the table must give back the injected squareness errors with the model's
// signs and the injected axis scales.
#include "cal/analysis/ballbar_planes.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "cal/analysis/error.hpp"

namespace ci = cal::circle;

namespace {

// Injected: axis scales (um/m) and the ISO 230-1 location errors (urad).
struct Truth {
  double sx = 12, sy = -6, sz = 4;
  double c0y = 15, b0z = 9, a0z = -7;
};

// Actual position of a commanded one (mm). docs/kinematics.md: X along +X; Y's direction
// (-sin c, cos c, 0), c = E_C0Y; Z's (cos a sin b, -sin a, cos a cos b), a = E_A0Z, b = E_B0Z;
// each axis scaled by (1 + s).
std::array<double, 3> actual(const Truth& t, double x, double y, double z) {
  const double c = t.c0y * 1e-6, a = t.a0z * 1e-6, b = t.b0z * 1e-6;
  const double xs = x * (1 + t.sx * 1e-6), ys = y * (1 + t.sy * 1e-6), zs = z * (1 + t.sz * 1e-6);
  return {xs - ys * std::sin(c) + zs * std::cos(a) * std::sin(b),
          ys * std::cos(c) - zs * std::sin(a), zs * std::cos(a) * std::cos(b)};
}

// One plane's test: the commanded point at caldaq's angle (from u towards v), the bar's
// deviation from R with the pivot at the origin, both directions over [from, from + arc].
ci::Result test_plane(const Truth& t, ci::Plane p, double from_deg, double arc_deg, double r_mm) {
  std::vector<ci::Trace> traces(2);
  traces[0].direction = ci::Direction::ccw;
  traces[1].direction = ci::Direction::cw;
  const int n = static_cast<int>(arc_deg / 0.25);
  for (int i = 0; i <= n; ++i) {
    if (arc_deg >= 360 && i == n) break;
    const double th = from_deg + arc_deg * i / n, rad = th * std::numbers::pi / 180;
    const double cu = r_mm * std::cos(rad), cv = r_mm * std::sin(rad);
    const auto q = p == ci::Plane::xy   ? actual(t, cu, cv, 0)
                   : p == ci::Plane::yz ? actual(t, 0, cu, cv)
                                        : actual(t, cv, 0, cu);  // ZX: u = Z, v = X
    const double dev = (std::hypot(q[0], q[1], q[2]) - r_mm) * 1e3;
    traces[0].angle_deg.push_back(th), traces[0].deviation_um.push_back(dev);
  }
  traces[1].angle_deg.assign(traces[0].angle_deg.rbegin(), traces[0].angle_deg.rend());
  traces[1].deviation_um.assign(traces[0].deviation_um.rbegin(), traces[0].deviation_um.rend());
  ci::Setup s{.plane = p, .radius_mm = r_mm, .cyclic_period_mm = 10.0};
  s.arc_deg = arc_deg;
  return ci::analyse(s, traces);
}

double value(const ci::Result& r, const std::string& key) {
  for (const auto& d : r.diagnostics)
    if (d.key == key) return d.value;
  ADD_FAILURE() << "no " << key;
  return NAN;
}

ci::PlaneValues values(const ci::Result& r, ci::Plane p, double r_mm, bool calibrated) {
  ci::PlaneValues v{.plane = p,
                    .squareness_um_per_m = value(r, "squareness"),
                    .scale_mismatch_um_per_m = value(r, "scale_mismatch")};
  if (calibrated) v.mean_scale_um_per_m = value(r, "radius_error") / r_mm * 1e3;
  return v;
}

}  // namespace

TEST(ThreePlanes, InjectedSquarenessAndScalesComeBackWithTheModelsSigns) {
  const Truth t;
  const double r = 150;
  const auto xy = test_plane(t, ci::Plane::xy, 0, 360, r);
  const auto zx = test_plane(t, ci::Plane::zx, -110, 220, r);  // symmetric about +Z (0 deg)
  const auto yz = test_plane(t, ci::Plane::yz, -20, 220, r);   // symmetric about +Z (90 deg)
  // Each plane by hand: alpha = angle - 90 deg; mismatch s_u - s_v in the plane's order.
  EXPECT_NEAR(value(xy, "squareness"), +15, 0.05);  // +E_C0Y
  EXPECT_NEAR(value(zx, "squareness"), -9, 0.05);   // -E_B0Z
  EXPECT_NEAR(value(yz, "squareness"), -7, 0.05);   // +E_A0Z
  EXPECT_NEAR(value(xy, "scale_mismatch"), 12 - -6, 0.05);
  EXPECT_NEAR(value(zx, "scale_mismatch"), 4 - 12, 0.05);
  EXPECT_NEAR(value(yz, "scale_mismatch"), -6 - 4, 0.05);

  // Uncalibrated: relative scales, mean 0: (12, -6, 4) - 10/3.
  const std::vector<ci::PlaneValues> rel{values(xy, ci::Plane::xy, r, false),
                                         values(zx, ci::Plane::zx, r, false),
                                         values(yz, ci::Plane::yz, r, false)};
  const auto a = ci::combine_planes(rel);
  EXPECT_NEAR(ci::location_error_urad(*a.planes[0]), 15, 0.05);  // E_C0Y
  EXPECT_NEAR(ci::location_error_urad(*a.planes[2]), 9, 0.05);   // E_B0Z (from ZX)
  EXPECT_NEAR(ci::location_error_urad(*a.planes[1]), -7, 0.05);  // E_A0Z
  ASSERT_TRUE(a.scale_um_per_m);
  EXPECT_FALSE(a.scale_absolute);
  EXPECT_NEAR((*a.scale_um_per_m)[0], 12 - 10.0 / 3, 0.05);
  EXPECT_NEAR((*a.scale_um_per_m)[1], -6 - 10.0 / 3, 0.05);
  EXPECT_NEAR((*a.scale_um_per_m)[2], 4 - 10.0 / 3, 0.05);
  ASSERT_TRUE(a.closure_um_per_m);
  EXPECT_NEAR(*a.closure_um_per_m, 0, 0.05);

  // Calibrated bars: the radius error carries R (s_u + s_v) / 2, so the scales are absolute.
  const std::vector<ci::PlaneValues> abs{values(xy, ci::Plane::xy, r, true),
                                         values(zx, ci::Plane::zx, r, true),
                                         values(yz, ci::Plane::yz, r, true)};
  const auto b = ci::combine_planes(abs);
  ASSERT_TRUE(b.scale_um_per_m);
  EXPECT_TRUE(b.scale_absolute);
  EXPECT_NEAR((*b.scale_um_per_m)[0], 12, 0.05);
  EXPECT_NEAR((*b.scale_um_per_m)[1], -6, 0.05);
  EXPECT_NEAR((*b.scale_um_per_m)[2], 4, 0.05);
  ASSERT_TRUE(b.scale_residual_um_per_m);
  EXPECT_LT(*b.scale_residual_um_per_m, 0.05);
}

TEST(ThreePlanes, ScalesByHandFromOneTwoAndThreePlanes) {
  // s = (10, -5, 3): mismatches XY 15, YZ -8, ZX -7.
  const ci::PlaneValues xy{.plane = ci::Plane::xy, .scale_mismatch_um_per_m = 15};
  const ci::PlaneValues yz{.plane = ci::Plane::yz, .scale_mismatch_um_per_m = -8};
  ci::PlaneValues zx{.plane = ci::Plane::zx, .scale_mismatch_um_per_m = -7};
  // One plane: X - Y only, no scale of Z: nothing solved.
  EXPECT_FALSE(ci::combine_planes(std::vector{xy}).scale_um_per_m);
  // Two planes: relative, mean 0 (x - y = 15, y - z = -8, x + y + z = 0: x = 22/3 ... by hand).
  const auto two = ci::combine_planes(std::vector{xy, yz});
  ASSERT_TRUE(two.scale_um_per_m);
  EXPECT_NEAR((*two.scale_um_per_m)[0], 22.0 / 3, 1e-9);
  EXPECT_NEAR((*two.scale_um_per_m)[1], -23.0 / 3, 1e-9);
  EXPECT_NEAR((*two.scale_um_per_m)[2], 1.0 / 3, 1e-9);
  EXPECT_FALSE(two.closure_um_per_m);
  // A closure that does not vanish: ZX read 3 um/m too high. Least squares spreads it: each
  // equation keeps 1 um/m of it (the residual's rms), the closure says 3.
  zx.scale_mismatch_um_per_m = -4;
  const auto three = ci::combine_planes(std::vector{xy, yz, zx});
  EXPECT_NEAR(*three.closure_um_per_m, 3, 1e-9);
  EXPECT_NEAR(*three.scale_residual_um_per_m, 1, 1e-9);
  // One calibrated plane (XY mean (10 - 5)/2 = 2.5) and two mismatches: absolute.
  ci::PlaneValues xy_cal = xy;
  xy_cal.mean_scale_um_per_m = 2.5;
  zx.scale_mismatch_um_per_m = -7;
  const auto abs = ci::combine_planes(std::vector{xy_cal, zx});
  ASSERT_TRUE(abs.scale_absolute);
  EXPECT_NEAR((*abs.scale_um_per_m)[0], 10, 1e-9);
  EXPECT_NEAR((*abs.scale_um_per_m)[1], -5, 1e-9);
  EXPECT_NEAR((*abs.scale_um_per_m)[2], 3, 1e-9);
  // Refused: a plane twice, a value that is not finite.
  EXPECT_THROW(ci::combine_planes(std::vector{xy, xy}), cal::InputError);
  ci::PlaneValues bad = yz;
  bad.squareness_um_per_m = NAN;
  EXPECT_THROW(ci::combine_planes(std::vector{bad}), cal::InputError);
}
