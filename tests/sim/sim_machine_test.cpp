// The simulated machine against closed forms: the trapezoid of a move, the following error
// v/Kv of a position loop on a ramp, the radius of a circle through a first-order lag, the
// play of backlash, and the kinematic and thermal errors at rest.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "cal/analysis/error.hpp"
#include "cal/drivers/sim/environment.hpp"
#include "cal/drivers/sim/machine.hpp"

namespace {

namespace sim = cal::drivers::sim;
using sim::Move;

sim::MachineConfig ideal() {
  sim::MachineConfig c;
  c.acceleration_mm_per_s2 = 1000.0;
  return c;
}

// Steps to time t with dt and returns the state.
const sim::MachineState& run_to(sim::Machine& m, double t, double dt = 1e-3) {
  while (m.state().time_s < t - 1e-12) m.step(std::min(dt, t - m.state().time_s));
  return m.state();
}

TEST(SimMachine, LinearMoveFollowsTheTrapezoid) {
  // 100 mm at 6000 mm/min = 100 mm/s with a = 1000 mm/s^2: t_acc = 0.1 s covering
  // 0.5 a t^2 = 5 mm, then (100 - 2 x 5) / 100 = 0.9 s at speed: 1.1 s in all.
  sim::Machine m(ideal());
  const Move program[] = {Move::linear({100, 0, 0}, 6000)};
  m.load(program);
  EXPECT_NEAR(m.program_duration_s(), 1.1, 1e-12);
  EXPECT_NEAR(run_to(m, 0.05).commanded_mm[0], 1.25, 1e-9);   // 0.5 x 1000 x 0.05^2
  EXPECT_NEAR(run_to(m, 0.6).commanded_mm[0], 55.0, 1e-9);    // 5 + 100 x 0.5
  EXPECT_NEAR(run_to(m, 1.05).commanded_mm[0], 98.75, 1e-9);  // 100 - 0.5 x 1000 x 0.05^2
  EXPECT_NEAR(run_to(m, 1.2).commanded_mm[0], 100.0, 1e-12);
}

TEST(SimMachine, FollowingErrorIsFeedOverKv) {
  // On a ramp a first-order position loop lags by v / Kv: 100 mm/s / 25 1/s = 4 mm. At
  // t = 0.8 s the transient of the acceleration phase has decayed by exp(-25 x 0.7) ~ 3e-8.
  auto c = ideal();
  c.servo[0].kv_per_s = 25.0;
  sim::Machine m(c);
  const Move program[] = {Move::linear({100, 0, 0}, 6000)};
  m.load(program);
  const auto& s = run_to(m, 0.8);
  EXPECT_NEAR(s.commanded_mm[0] - s.axes_mm[0], 4.0, 1e-6);
  run_to(m, 3.0);
  EXPECT_TRUE(m.finished());
  EXPECT_NEAR(m.state().tool_mm[0], 100.0, 1e-9);
}

TEST(SimMachine, CircleThroughEqualLagsShrinksByTheFirstOrderGain) {
  // A circle at angular speed w through a lag of gain Kv on both axes: the steady-state
  // amplitude ratio of 1/(1 + s/Kv) is 1/sqrt(1 + (w/Kv)^2). R = 50 mm at 3000 mm/min
  // (50 mm/s): w = 1 rad/s; Kv = 10: R' = 50 / sqrt(1.01) = 49.75186 mm.
  auto c = ideal();
  c.servo[0].kv_per_s = c.servo[1].kv_per_s = 10.0;
  c.start_mm = {50, 0, 0};
  sim::Machine m(c);
  const Move program[] = {Move::arc(false, {0, 0, 0}, sim::Plane::xy, 720.0, 3000)};
  m.load(program);
  // The circle takes 4 pi s (plus 0.05 s of ramps); at 6 s the lag transient decayed by e^-50.
  for (double t : {6.0, 7.3, 9.9}) {
    const auto& s = run_to(m, t);
    EXPECT_NEAR(std::hypot(s.commanded_mm[0], s.commanded_mm[1]), 50.0, 1e-9);
    EXPECT_NEAR(std::hypot(s.axes_mm[0], s.axes_mm[1]), 50.0 / std::sqrt(1.01), 1e-5) << t;
  }
}

TEST(SimMachine, BacklashIsAPlayOfItsWidth) {
  // Approaching 50 mm from above leaves the driven part b/2 above; from below b/2 below.
  auto c = ideal();
  c.servo[0].backlash_um = 8.0;
  sim::Machine m(c);
  const Move down[] = {Move::linear({100, 0, 0}, 6000), Move::linear({50, 0, 0}, 6000),
                       Move::dwell(1.0)};
  m.load(down);
  run_to(m, m.program_duration_s());
  EXPECT_NEAR(m.state().tool_mm[0], 50.004, 1e-9);
  const Move up[] = {Move::linear({0, 0, 0}, 6000), Move::linear({50, 0, 0}, 6000),
                     Move::dwell(1.0)};
  m.load(up);
  run_to(m, m.program_duration_s());
  EXPECT_NEAR(m.state().tool_mm[0], 49.996, 1e-9);
}

TEST(SimMachine, GeometricAndThermalErrorsAtRest) {
  // E_XX = 10 um/m (0.01 um per mm): at x = 200 mm, +2 um. Squareness E_C0Y = 50 urad: y
  // travel of 100 mm gives an x error of -50e-6 x 100 mm = -5 um. Scale at 21 degC with
  // 11.5 ppm/K: positions x 1.0000115. Tool at x = 200, y = 100 then:
  // x = 200 x 1.0000115 + (2 - 5) um (errors at the scaled axes; the change from scaling,
  // 0.01 um/mm x 2.3 um, is 2e-5 um), y = 100 x 1.0000115.
  auto c = ideal();
  c.geometry.axes[cal::kinematics::X].ex_um =
      cal::kinematics::ErrorFunction::polynomial({0.0, 0.01});
  c.geometry.squareness.c0y_urad = 50.0;
  c.thermal.start_degc = 21.0;
  sim::Machine m(c);
  const Move program[] = {Move::linear({200, 100, 0}, 6000), Move::dwell(1.0)};
  m.load(program);
  run_to(m, m.program_duration_s());
  EXPECT_NEAR(m.state().machine_temperature_degc, 21.0, 1e-12);
  EXPECT_NEAR(m.state().tool_mm[0], 200.0023 - 0.003, 1e-6);
  EXPECT_NEAR(m.state().tool_mm[1], 100.00115, 1e-6);
}

// A vibration of Y of 0.6 um at 25 Hz on a standing machine: Y is 0.6 sin(2 pi 25 t) um off,
// +0.6 um at t = 1/(4 x 25) = 10 ms, -0.6 um at 30 ms, 0 at 20 ms; X does not move.
TEST(SimMachine, VibrationIsASineInTime) {
  auto c = ideal();
  c.servo[1].vibration_um = 0.6;
  c.servo[1].vibration_hz = 25.0;
  sim::Machine m(c);
  EXPECT_NEAR(run_to(m, 0.010, 1e-4).axes_mm[1] * 1e3, 0.6, 1e-9);
  EXPECT_NEAR(run_to(m, 0.020, 1e-4).axes_mm[1] * 1e3, 0.0, 1e-9);
  EXPECT_NEAR(run_to(m, 0.030, 1e-4).axes_mm[1] * 1e3, -0.6, 1e-9);
  EXPECT_NEAR(m.state().tool_mm[1] * 1e3, -0.6, 1e-9);
  EXPECT_EQ(m.state().axes_mm[0], 0.0);
  auto no_frequency = ideal();
  no_frequency.servo[1].vibration_um = 0.6;
  EXPECT_THROW(sim::Machine{no_frequency}, cal::InputError);
  auto negative = ideal();
  negative.servo[2] = {.vibration_um = -1.0, .vibration_hz = 10.0};
  EXPECT_THROW(sim::Machine{negative}, cal::InputError);
}

// advance_to skips the geometric error of the intermediate steps (nothing reads them): the
// state it reaches must be the step-by-step one bit for bit, errors, noise and backlash
// included, and the tool's position must carry the geometric error of the last step.
TEST(SimMachine, AdvanceToIsStepByStepBitForBit) {
  auto c = ideal();
  c.servo[0] = {.kv_per_s = 30.0, .backlash_um = 4.0, .cyclic_amplitude_um = 1.0, .noise_um = 0.2};
  c.geometry.axes[0].ex_um = cal::kinematics::ErrorFunction::polynomial({0.0, 0.01});
  c.geometry.axes[0].ey_um = cal::kinematics::ErrorFunction::polynomial({0.0, 0.0, 1e-4});
  c.geometry.axes[0].ec_urad = cal::kinematics::ErrorFunction::polynomial({0.0, 0.05});
  c.geometry.tool_offset_mm = {0.0, 0.0, -100.0};
  sim::Machine a(c), b(c);
  const Move program[] = {Move::linear({100, 0, 0}, 6000), Move::dwell(1.0),
                          Move::linear({0, 20, 0}, 3000)};
  a.load(program);
  b.load(program);
  for (const double t : {0.0371, 0.5, 0.5, 1.234, 2.0, 3.5, 4.5}) {
    const auto& sa = run_to(a, t);
    const auto& sb = b.advance_to(t, 1e-3);
    EXPECT_EQ(sa.time_s, sb.time_s) << t;
    EXPECT_EQ(sa.block, sb.block) << t;
    for (std::size_t k = 0; k < 3; ++k) {
      EXPECT_EQ(sa.axes_mm[k], sb.axes_mm[k]) << t;
      EXPECT_EQ(sa.tool_mm[k], sb.tool_mm[k]) << t;
      EXPECT_EQ(sa.commanded_mm[k], sb.commanded_mm[k]) << t;
    }
  }
  // At 100 mm on X: E_XX = 1 um and E_YX = 1 um, and the 5 urad roll about Z does not move a
  // probe on the Z axis: the tool is 1 um off in X and Y from the axes' position.
  sim::Machine m(c);
  m.load(program);
  const auto& s = m.advance_to(2.0, 1e-3);  // the end of the dwell at x = 100: settled
  EXPECT_NEAR(s.axes_mm[0], 100.0, 0.01);
  EXPECT_NEAR((s.tool_mm[1] - s.axes_mm[1]) * 1e3, 1.0, 0.001);
  EXPECT_NEAR((s.tool_mm[0] - s.axes_mm[0]) * 1e3, 1.0, 0.001);
  EXPECT_THROW(b.advance_to(5.0, 0.0), cal::InputError);
}

TEST(SimMachine, ArcEndMustLieOnTheCircle) {
  auto c = ideal();
  c.start_mm = {50, 0, 0};
  sim::Machine m(c);
  Move bad = Move::arc(true, {0, 0, 0}, sim::Plane::xy, 0.0, 1000);
  bad.target_mm = {0, 49.9, 0};
  const Move program[] = {bad};
  try {
    m.load(program);
    FAIL() << "no error";
  } catch (const cal::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("move 0: arc end is 49.9000 mm from the centre"),
              std::string::npos)
        << e.what();
  }
  const Move no_feed[] = {Move::linear({1, 0, 0}, 0.0)};
  EXPECT_THROW(m.load(no_feed), cal::InputError);
  auto bad_kv = ideal();
  bad_kv.servo[2].kv_per_s = 0.0;
  EXPECT_THROW(sim::Machine{bad_kv}, cal::InputError);
  EXPECT_THROW(m.step(0.0), cal::InputError);
}

TEST(SimMachine, QuarterArcEndsAtItsTarget) {
  // Clockwise from (50, 0) to (0, -50) about the origin is a quarter circle: pi/2 x 50 mm.
  auto c = ideal();
  c.start_mm = {50, 0, 0};
  c.acceleration_mm_per_s2 = 1e9;  // constant speed, so the duration is length / feed
  sim::Machine m(c);
  Move quarter = Move::arc(true, {0, 0, 0}, sim::Plane::xy, 0.0, 6000);
  quarter.target_mm = {0, -50, 0};
  const Move program[] = {quarter};
  m.load(program);
  EXPECT_NEAR(m.program_duration_s(), std::numbers::pi / 2 * 50 / 100, 1e-6);
  const auto& s = run_to(m, m.program_duration_s() / 2);
  EXPECT_NEAR(s.commanded_mm[0], 50 * std::cos(std::numbers::pi / 4), 1e-4);
  EXPECT_NEAR(s.commanded_mm[1], -50 * std::sin(std::numbers::pi / 4), 1e-4);
}

TEST(SimAir, LaserReadsTheOpticalPath) {
  // At 20 degC, 101325 Pa, 50 %RH, 633 nm the modified Edlen equation gives n = 1.000271374
  // (the reference value of tests/analysis/air_test.cpp); Ciddor agrees with Edlen within
  // 1e-8 there. The laser reads n x 100 mm.
  sim::Air air({});
  const auto s = air.sample(0.0);
  EXPECT_NEAR(s.refractive_index, 1.000271374, 1e-8);
  sim::MachineState state;
  state.tool_mm = {100.0, 0, 0};
  EXPECT_NEAR(sim::laser_reading_m(state, cal::kinematics::X, 0.0, s.refractive_index),
              0.1 * s.refractive_index, 1e-15);
  EXPECT_NEAR(sim::ballbar_length_mm(state, {0, 0, 0}), 100.0, 1e-12);
}

TEST(SimAir, DriftFollowsItsTrendAndCycle) {
  // 20 + 0.5 K/h x 0.5 h + 0.2 sin(2 pi 1800 / 7200) = 20.25 + 0.2 = 20.45 degC.
  sim::AirConfig c;
  c.temperature_degc = {.start = 20.0, .per_hour = 0.5, .amplitude = 0.2, .period_s = 7200.0};
  sim::Air air(c);
  EXPECT_NEAR(air.sample(1800.0).temperature_degc, 20.45, 1e-12);
  c.pressure_pa.period_s = 0.0;
  EXPECT_THROW(sim::Air{c}, cal::InputError);
}

}  // namespace
