#pragma once
// Machines and a rotation shared by the rotary-axis tests (trt_kins_test, swivel_data_test,
// rotary_head_test): written out here, not taken from the code under test.
#include <cmath>
#include <numbers>

#include "cal/analysis/rotary.hpp"

namespace cal::test {

using kinematics::FiveAxisMachine;
using kinematics::RotaryAxis;
using kinematics::RotaryLetter;
using kinematics::Vec3;

inline RotaryAxis table_axis(RotaryLetter l, const Vec3& pivot, const Vec3& pos_um,
                             const Vec3& orient_urad) {
  RotaryAxis r;
  r.letter = l;
  r.side = kinematics::Side::table;
  r.pivot_mm = pivot;
  r.location_position_um = pos_um;
  r.location_orientation_urad = orient_urad;
  return r;
}

// The small trunnion of the controller writers' tests: a C table on an A or B cradle (FXYZ, no
// tool offset), with position errors on both axes (mm and um):
//   C: pivot (10, 20, -300), E_X0C = 12, E_Y0C = -5 um, orientation `c_orient`
//   A: pivot (0, 25, -280),  E_Y0A = 7,  E_Z0A = -15 um, orientation `cradle_orient`
//   B: pivot (-4, 0, -280),  E_X0B = 9,  E_Z0B = -15 um, orientation `cradle_orient`
inline FiveAxisMachine small_trunnion(RotaryLetter cradle, const Vec3& c_orient,
                                      const Vec3& cradle_orient) {
  FiveAxisMachine m;
  m.linear.topology = kinematics::Topology::fxyz;
  m.rotary.push_back(table_axis(RotaryLetter::c, {10, 20, -300}, {12, -5, 0}, c_orient));
  if (cradle == RotaryLetter::a)
    m.rotary.push_back(table_axis(RotaryLetter::a, {0, 25, -280}, {0, 7, -15}, cradle_orient));
  else
    m.rotary.push_back(table_axis(RotaryLetter::b, {-4, 0, -280}, {9, 0, -15}, cradle_orient));
  return m;
}

// Rodrigues: v turned by `deg` right-handed about the line through q along u (any length).
inline Vec3 turn(const Vec3& v, const Vec3& q, const Vec3& u, double deg) {
  const double n = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  const Vec3 k{u[0] / n, u[1] / n, u[2] / n};
  const double t = deg * std::numbers::pi / 180.0, c = std::cos(t), s = std::sin(t);
  const Vec3 w{v[0] - q[0], v[1] - q[1], v[2] - q[2]};
  const double kw = k[0] * w[0] + k[1] * w[1] + k[2] * w[2];
  const Vec3 kxw{k[1] * w[2] - k[2] * w[1], k[2] * w[0] - k[0] * w[2], k[0] * w[1] - k[1] * w[0]};
  Vec3 out{};
  for (std::size_t i = 0; i < 3; ++i) out[i] = q[i] + w[i] * c + kxw[i] * s + k[i] * kw * (1 - c);
  return out;
}

}  // namespace cal::test
