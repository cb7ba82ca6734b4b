#pragma once
// The simulated 3-axis machine: a part program of linear moves, arcs and dwells is
// interpolated in simulated time (trapezoidal feed profile with an acceleration limit), each
// axis follows its command through a first-order position loop (following error v/Kv), with
// lost motion (backlash), a cyclic (pitch) error, thermal expansion of its scale and noise;
// the tool tip relative to the workpiece then carries the 21 geometric errors of the
// kinematic model. Every error is a known, configured number, so every analysis can be
// checked against this truth. Simulated, and named so: nothing here talks to a real machine.
#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <vector>

#include "cal/analysis/kinematics.hpp"

namespace cal::drivers::sim {

using Vec3 = kinematics::Vec3;

enum class Plane { xy, yz, zx };  // G17, G19, G18; arcs are counter-clockwise seen from +normal

struct Move {
  enum class Kind { linear, arc_cw, arc_ccw, dwell };
  Kind kind = Kind::linear;
  Vec3 target_mm{};         // end point (linear, arc)
  Vec3 centre_mm{};         // arc centre; must be equidistant from start and end in-plane
  Plane plane = Plane::xy;  // arc plane
  double sweep_deg = 0.0;   // arc: 0 = up to the target; > 0 = this sweep (full circles)
  double feed_mm_per_min = 1000.0;
  double dwell_s = 0.0;
  static Move linear(Vec3 target, double feed_mm_per_min);
  static Move dwell(double seconds);
  // A full or partial arc by sweep from the current position (the end point follows).
  static Move arc(bool clockwise, Vec3 centre, Plane plane, double sweep_deg,
                  double feed_mm_per_min);
};

struct ServoAxis {
  double kv_per_s = 33.3;            // position loop gain: lag 1/Kv s, following error v/Kv
  double backlash_um = 0.0;          // lost motion at a reversal (play of width backlash_um)
  double cyclic_amplitude_um = 0.0;  // pitch error A sin(2 pi q / period)
  double cyclic_period_mm = 5.0;
  double noise_um = 0.0;  // rms of white position noise, per sample
  // A vibration of the axis (a resonance kept up by a pump or the drive, moving or standing):
  // vibration_um x sin(2 pi vibration_hz t) added to its position, t the simulated time.
  double vibration_um = 0.0;  // amplitude (peak), >= 0
  double vibration_hz = 0.0;  // > 0 when vibration_um is
};

// Temperature of the machine's structure and scales; the scales expand by
// expansion_ppm_per_k * (T - 20 degC), so a reading normalised to 20 degC with the same
// coefficient recovers the geometric errors.
struct Thermal {
  double start_degc = 20.0;
  double drift_k_per_h = 0.0;
  double cycle_amplitude_k = 0.0;  // a sinusoid, e.g. the shop's heating cycle
  double cycle_period_s = 3600.0;
  double expansion_ppm_per_k = 11.5;  // steel
  double temperature_degc(double t_s) const;
};

struct MachineConfig {
  kinematics::Machine geometry;
  std::array<ServoAxis, 3> servo{};
  double acceleration_mm_per_s2 = 1000.0;
  Thermal thermal;
  Vec3 start_mm{};
  std::uint64_t seed = 1;
  // The controller's compensation (e.g. cross-axis tables written from a model): the correction
  // in um added to the interpolated command before the position loops, as a controller adds
  // its compensation to the set-point. Empty: none. The state's commanded_mm stays the
  // programmed position (what the control displays).
  std::function<Vec3(const Vec3& commanded_mm)> compensation_um;
};

struct MachineState {
  double time_s = 0.0;
  Vec3 commanded_mm{};  // interpolator output (what the controller's position display shows)
  Vec3 axes_mm{};       // axis positions after servo lag, backlash, cyclic error and thermal
  Vec3 tool_mm{};       // tool tip relative to the workpiece, with the geometric errors
  double machine_temperature_degc = 20.0;
  std::size_t block = 0;  // index of the move being executed (== size when finished)
  bool in_motion = false;
};

class Machine {
 public:
  // Throws cal::InputError for a non-positive Kv, acceleration or period, negative backlash,
  // noise or vibration, or a vibration without a positive finite frequency.
  explicit Machine(MachineConfig config);
  ~Machine();
  Machine(Machine&&) noexcept;
  Machine& operator=(Machine&&) noexcept;

  // Appends moves to the program. Throws cal::InputError (naming the move's index) for a
  // non-positive feed, a negative dwell, or an arc whose end is not on its circle.
  void load(std::span<const Move> program);
  // Replaces the controller's compensation (MachineConfig::compensation_um) from now on.
  void set_compensation(std::function<Vec3(const Vec3&)> compensation_um);
  // Advances simulated time by dt_s (> 0) and returns the new state.
  const MachineState& step(double dt_s);
  // Steps of at most max_step_s up to t_s (an earlier t_s is a no-op); the same state as
  // calling step() that often, bit for bit, but the geometric (HTM) error, which nothing can
  // read between the steps, is evaluated at the last step only.
  const MachineState& advance_to(double t_s, double max_step_s);
  const MachineState& state() const;
  // True when every move is done and the axes have settled (following error < 1 nm).
  bool finished() const;
  // Duration of the program as interpolated (without the settling of the servo).
  double program_duration_s() const;
  const MachineConfig& config() const;
  // The error (HTM, um and urad) of a point `offset_mm` from the tool reference point (the
  // geometry's tool offset replaced by it) at the current axis positions: what an instrument
  // whose probe, reflector or level sits there reads.
  kinematics::VolumetricError error_at(const Vec3& offset_mm) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace cal::drivers::sim
