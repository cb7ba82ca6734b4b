// Seeded machines for the kinematic tests: all 21 errors as cubics of realistic size
// (translations to ~10 um, angles to ~50 urad over 1 m, squareness to ~30 urad), and the same
// machine with every error scaled (the methods' agreement to second order).
#pragma once

#include <cstddef>
#include <cstdint>
#include <random>

#include "cal/analysis/kinematics.hpp"

namespace cal::test {

inline cal::kinematics::Machine random_machine(cal::kinematics::Topology t, std::uint64_t seed) {
  using namespace cal::kinematics;
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Machine m;
  m.topology = t;
  for (Component c : all_components()) {
    const bool angle = static_cast<std::size_t>(c) % 6 >= 3;
    const double size = angle ? 50.0 : 10.0;
    // size * (a0 + a1 s + a2 s^2 + a3 s^3) with s = q / 1000 mm
    component(m, c) = ErrorFunction::polynomial(
        {size * u(rng), size * u(rng) / 1e3, size * u(rng) / 1e6, size * u(rng) / 1e9});
  }
  m.squareness = {30.0 * u(rng), 30.0 * u(rng), 30.0 * u(rng)};
  m.tool_offset_mm = {10.0, -20.0, -150.0};
  m.table_offset_mm = {-250.0, 100.0, -30.0};
  return m;
}

inline cal::kinematics::Machine scaled(const cal::kinematics::Machine& m, double k) {
  using namespace cal::kinematics;
  Machine s = m;
  for (Component c : all_components()) component(s, c) = component(m, c).scaled(k);
  s.squareness = {k * m.squareness.c0y_urad, k * m.squareness.b0z_urad, k * m.squareness.a0z_urad};
  return s;
}

}  // namespace cal::test
