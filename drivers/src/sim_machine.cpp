// The simulated machine (see sim/machine.hpp). Units: mm, s; errors from the kinematic model
// in um. The interpolator is exact (closed-form trapezoid), the servo integration is exact for
// a command that is linear over each step, so the only discretisation is the caller's dt.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <random>
#include <utility>

#include "cal/analysis/error.hpp"
#include "cal/drivers/sim/machine.hpp"

namespace cal::drivers::sim {
namespace {

constexpr double pi = std::numbers::pi;

std::array<std::size_t, 2> plane_axes(Plane p) {
  switch (p) {
    case Plane::xy:
      return {0, 1};
    case Plane::yz:
      return {1, 2};
    case Plane::zx:
      return {2, 0};
  }
  return {0, 1};
}

// Distance along a move at time t for a trapezoidal speed profile (or a triangle when the
// move is too short to reach the feed): accelerate at a, cruise at v, decelerate at a.
struct Profile {
  double length = 0.0, accel = 1.0, v_peak = 0.0, t_acc = 0.0, t_const = 0.0;

  Profile() = default;
  Profile(double length_mm, double feed_mm_s, double a) : length(length_mm), accel(a) {
    if (length_mm <= 0.0) return;
    v_peak = std::min(feed_mm_s, std::sqrt(length_mm * a));
    t_acc = v_peak / a;
    t_const = (length_mm - v_peak * t_acc) / v_peak;
  }
  double duration() const { return length > 0.0 ? 2.0 * t_acc + t_const : 0.0; }
  double distance(double t) const {
    if (length <= 0.0) return 0.0;
    if (t <= 0.0) return 0.0;
    if (t < t_acc) return 0.5 * accel * t * t;
    if (t < t_acc + t_const) return 0.5 * accel * t_acc * t_acc + v_peak * (t - t_acc);
    const double left = duration() - t;
    return left <= 0.0 ? length : length - 0.5 * accel * left * left;
  }
};

struct Segment {
  Move move;
  Vec3 start{}, end{};
  double radius = 0.0, start_angle = 0.0, sweep = 0.0;  // arcs; sweep signed (ccw > 0)
  Profile profile;
  double duration = 0.0;
  double t0 = 0.0;  // start time in the program

  Vec3 at(double t) const {
    if (move.kind == Move::Kind::dwell) return start;
    const double s = profile.distance(t);
    if (move.kind == Move::Kind::linear) {
      const double f = profile.length > 0.0 ? s / profile.length : 1.0;
      Vec3 p{};
      for (std::size_t k = 0; k < 3; ++k) p[k] = start[k] + f * (end[k] - start[k]);
      return p;
    }
    const auto [i, j] = plane_axes(move.plane);
    const double angle = start_angle + (sweep > 0 ? 1.0 : -1.0) * s / radius;
    Vec3 p = start;
    p[i] = move.centre_mm[i] + radius * std::cos(angle);
    p[j] = move.centre_mm[j] + radius * std::sin(angle);
    return p;
  }
};

void check_finite(const Vec3& v, std::string_view what, std::size_t index) {
  for (double x : v)
    if (!std::isfinite(x)) throw InputError(fmt::format("move {}: {} is not finite", index, what));
}

Segment make_segment(const Move& m, const Vec3& from, double accel_mm_s2, std::size_t index) {
  Segment seg{.move = m, .start = from, .end = from};
  if (m.kind == Move::Kind::dwell) {
    if (!(m.dwell_s >= 0.0) || !std::isfinite(m.dwell_s))
      throw InputError(fmt::format("move {}: dwell {} s must be >= 0", index, m.dwell_s));
    seg.duration = m.dwell_s;
    return seg;
  }
  if (!(m.feed_mm_per_min > 0.0) || !std::isfinite(m.feed_mm_per_min))
    throw InputError(fmt::format("move {}: feed {} mm/min must be > 0", index, m.feed_mm_per_min));
  const double feed_mm_s = m.feed_mm_per_min / 60.0;
  if (m.kind == Move::Kind::linear) {
    check_finite(m.target_mm, "target", index);
    seg.end = m.target_mm;
    double length = 0.0;
    for (std::size_t k = 0; k < 3; ++k) length += std::pow(seg.end[k] - from[k], 2);
    seg.profile = Profile(std::sqrt(length), feed_mm_s, accel_mm_s2);
    seg.duration = seg.profile.duration();
    return seg;
  }
  check_finite(m.centre_mm, "arc centre", index);
  const auto [i, j] = plane_axes(m.plane);
  const double di = from[i] - m.centre_mm[i], dj = from[j] - m.centre_mm[j];
  seg.radius = std::hypot(di, dj);
  if (seg.radius < 1e-6)
    throw InputError(fmt::format("move {}: the arc starts at its centre", index));
  seg.start_angle = std::atan2(dj, di);
  const double sign = m.kind == Move::Kind::arc_ccw ? 1.0 : -1.0;
  double sweep = m.sweep_deg * pi / 180.0;
  if (m.sweep_deg <= 0.0) {
    check_finite(m.target_mm, "target", index);
    const double ei = m.target_mm[i] - m.centre_mm[i], ej = m.target_mm[j] - m.centre_mm[j];
    // 1 um: a part program's coordinates are rounded to the control's resolution.
    if (std::abs(std::hypot(ei, ej) - seg.radius) > 1e-3)
      throw InputError(
          fmt::format("move {}: arc end is {:.4f} mm from the centre but the start is {:.4f} mm",
                      index, std::hypot(ei, ej), seg.radius));
    sweep = sign * (std::atan2(ej, ei) - seg.start_angle);
    while (sweep <= 1e-12) sweep += 2.0 * pi;  // equal start and end: a full circle
  }
  seg.sweep = sign * sweep;
  seg.profile = Profile(seg.radius * sweep, feed_mm_s, accel_mm_s2);
  seg.duration = seg.profile.duration();
  seg.end = seg.at(seg.duration);
  return seg;
}

void validate(const MachineConfig& c) {
  if (!(c.acceleration_mm_per_s2 > 0.0))
    throw InputError(fmt::format("acceleration {} mm/s^2 must be > 0", c.acceleration_mm_per_s2));
  const char* names = "XYZ";
  for (std::size_t k = 0; k < 3; ++k) {
    const ServoAxis& s = c.servo[k];
    if (!(s.kv_per_s > 0.0))
      throw InputError(fmt::format("axis {}: Kv {} 1/s must be > 0", names[k], s.kv_per_s));
    if (!(s.backlash_um >= 0.0) || !(s.noise_um >= 0.0))
      throw InputError(fmt::format("axis {}: backlash and noise must be >= 0", names[k]));
    if (!(s.vibration_um >= 0.0) || !std::isfinite(s.vibration_um))
      throw InputError(fmt::format("axis {}: vibration {} um must be finite and >= 0", names[k],
                                   s.vibration_um));
    if (s.vibration_um > 0.0 && !(s.vibration_hz > 0.0 && std::isfinite(s.vibration_hz)))
      throw InputError(fmt::format("axis {}: vibration frequency {} Hz must be finite and > 0",
                                   names[k], s.vibration_hz));
    if (!(s.cyclic_period_mm > 0.0))
      throw InputError(
          fmt::format("axis {}: cyclic period {} mm must be > 0", names[k], s.cyclic_period_mm));
  }
  if (!(c.thermal.cycle_period_s > 0.0))
    throw InputError(
        fmt::format("thermal cycle period {} s must be > 0", c.thermal.cycle_period_s));
}

}  // namespace

Move Move::linear(Vec3 target, double feed) {
  return Move{.kind = Kind::linear, .target_mm = target, .feed_mm_per_min = feed};
}
Move Move::dwell(double seconds) { return Move{.kind = Kind::dwell, .dwell_s = seconds}; }
Move Move::arc(bool clockwise, Vec3 centre, Plane plane, double sweep_deg, double feed) {
  return Move{.kind = clockwise ? Kind::arc_cw : Kind::arc_ccw,
              .centre_mm = centre,
              .plane = plane,
              .sweep_deg = sweep_deg,
              .feed_mm_per_min = feed};
}

double Thermal::temperature_degc(double t_s) const {
  return start_degc + drift_k_per_h * t_s / 3600.0 +
         cycle_amplitude_k * std::sin(2.0 * pi * t_s / cycle_period_s);
}

struct Machine::Impl {
  MachineConfig config;
  std::vector<Segment> program;
  std::size_t current = 0;
  Vec3 servo_mm{};   // position-loop output per axis
  Vec3 played_mm{};  // after the backlash play
  MachineState state;
  std::mt19937_64 rng;
  std::normal_distribution<double> normal{0.0, 1.0};
  // The last set-point computed: a step's start is the previous step's end, and a standing
  // machine's command does not change, so the compensation (a model's volumetric correction
  // can be costly) is evaluated once per new command, with the same result.
  std::optional<std::pair<Vec3, Vec3>> last_setpoint;
  std::optional<kinematics::Machine> probe_geometry;  // error_at's (see there)

  // The set-point the position loops follow: the command plus the control's compensation.
  Vec3 compensated(const Vec3& c) {
    if (!config.compensation_um) return c;
    if (last_setpoint && last_setpoint->first == c) return last_setpoint->second;
    const Vec3 d = config.compensation_um(c);
    Vec3 s = c;
    for (std::size_t k = 0; k < 3; ++k) s[k] += 1e-3 * d[k];
    last_setpoint.emplace(c, s);
    return s;
  }

  Vec3 commanded(double t) {
    while (current < program.size() && t >= program[current].t0 + program[current].duration)
      ++current;
    if (current == program.size()) return program.empty() ? config.start_mm : program.back().end;
    const Segment& s = program[current];
    return s.at(t - s.t0);
  }

  // `geometry` false: the axes only (state.tool_mm is left stale); for the intermediate steps
  // of advance_to, where nobody reads the tool's position.
  void advance(double dt, bool geometry = true) {
    const Vec3 c0 = state.commanded_mm;
    const double t = state.time_s + dt;
    const Vec3 c1 = commanded(t);
    const Vec3 s0 = compensated(c0), s1 = compensated(c1);
    const double temperature = config.thermal.temperature_degc(t);
    const double scale = 1.0 + config.thermal.expansion_ppm_per_k * 1e-6 * (temperature - 20.0);
    Vec3 axes{};
    for (std::size_t k = 0; k < 3; ++k) {
      const ServoAxis& s = config.servo[k];
      // dx/dt = Kv (c - x) with c linear over the step (rate r): exact solution
      // x(dt) = c1 - r/Kv + (x0 - c0 + r/Kv) exp(-Kv dt).
      const double r = (s1[k] - s0[k]) / dt;
      servo_mm[k] = s1[k] - r / s.kv_per_s +
                    (servo_mm[k] - s0[k] + r / s.kv_per_s) * std::exp(-s.kv_per_s * dt);
      // Lost motion: the driven part follows only once the play of width b is taken up.
      const double half = 0.5e-3 * s.backlash_um;
      played_mm[k] = std::clamp(played_mm[k], servo_mm[k] - half, servo_mm[k] + half);
      double q = played_mm[k] + 1e-3 * s.cyclic_amplitude_um *
                                    std::sin(2.0 * pi * played_mm[k] / s.cyclic_period_mm);
      if (s.noise_um > 0.0) q += 1e-3 * s.noise_um * normal(rng);
      if (s.vibration_um > 0.0)
        q += 1e-3 * s.vibration_um * std::sin(2.0 * pi * s.vibration_hz * t);
      axes[k] = q * scale;
    }
    state.time_s = t;
    state.commanded_mm = c1;
    state.axes_mm = axes;
    if (geometry) tool();
    state.machine_temperature_degc = temperature;
    state.block = current;
    state.in_motion = current < program.size() && program[current].move.kind != Move::Kind::dwell;
  }

  // The tool's position from the axes' through the geometric errors (the HTM chain: about
  // half of a step's cost with all 21 errors).
  void tool() {
    const Vec3 e_um =
        kinematics::volumetric_error_um(config.geometry, state.axes_mm, kinematics::Method::htm);
    for (std::size_t k = 0; k < 3; ++k) state.tool_mm[k] = state.axes_mm[k] + 1e-3 * e_um[k];
  }
};

Machine::Machine(MachineConfig config) : impl_(std::make_unique<Impl>()) {
  validate(config);
  impl_->config = std::move(config);
  impl_->rng.seed(impl_->config.seed);
  impl_->servo_mm = impl_->played_mm = impl_->config.start_mm;
  impl_->state.commanded_mm = impl_->config.start_mm;
  impl_->advance(1e-9);  // fill axes/tool for t = 0 (no motion yet)
  impl_->state.time_s = 0.0;
}
Machine::~Machine() = default;
Machine::Machine(Machine&&) noexcept = default;
Machine& Machine::operator=(Machine&&) noexcept = default;

void Machine::load(std::span<const Move> moves) {
  Impl& m = *impl_;
  Vec3 from = m.program.empty() ? m.config.start_mm : m.program.back().end;
  double t0 = m.program.empty() ? m.state.time_s : m.program.back().t0 + m.program.back().duration;
  t0 = std::max(t0, m.state.time_s);
  for (std::size_t n = 0; n < moves.size(); ++n) {
    Segment seg = make_segment(moves[n], from, m.config.acceleration_mm_per_s2, m.program.size());
    seg.t0 = t0;
    t0 += seg.duration;
    from = seg.end;
    m.program.push_back(std::move(seg));
  }
}

const MachineState& Machine::step(double dt_s) {
  if (!(dt_s > 0.0) || !std::isfinite(dt_s))
    throw InputError(fmt::format("simulation step {} s must be > 0", dt_s));
  impl_->advance(dt_s);
  return impl_->state;
}

const MachineState& Machine::advance_to(double t_s, double max_step_s) {
  if (!(max_step_s > 0.0) || !std::isfinite(max_step_s))
    throw InputError(fmt::format("simulation step {} s must be > 0", max_step_s));
  Impl& m = *impl_;
  bool stepped = false;
  while (m.state.time_s < t_s - 1e-12) {
    m.advance(std::min(max_step_s, t_s - m.state.time_s), false);
    stepped = true;
  }
  if (stepped) m.tool();
  return m.state;
}

const MachineState& Machine::state() const { return impl_->state; }

bool Machine::finished() const {
  const Impl& m = *impl_;
  if (m.current < m.program.size()) return false;
  for (std::size_t k = 0; k < 3; ++k)
    if (std::abs(m.servo_mm[k] - m.state.commanded_mm[k]) > 1e-6) return false;
  return true;
}

double Machine::program_duration_s() const {
  const Impl& m = *impl_;
  return m.program.empty() ? 0.0 : m.program.back().t0 + m.program.back().duration;
}

const MachineConfig& Machine::config() const { return impl_->config; }

void Machine::set_compensation(std::function<Vec3(const Vec3&)> compensation_um) {
  impl_->config.compensation_um = std::move(compensation_um);
  impl_->last_setpoint.reset();
}

kinematics::VolumetricError Machine::error_at(const Vec3& offset_mm) const {
  // The geometry with the probe's offset, copied once per offset (the geometry itself never
  // changes): an instrument asks at every reading, and a copy of the 18 error functions costs
  // more than the HTM chain.
  auto& g = impl_->probe_geometry;
  if (!g || g->tool_offset_mm != offset_mm) {
    g = impl_->config.geometry;
    g->tool_offset_mm = offset_mm;
  }
  return kinematics::volumetric_error(*g, impl_->state.axes_mm, kinematics::Method::htm);
}

}  // namespace cal::drivers::sim
