#pragma once
// Simulated shop-floor air and the simulated instruments' physics: air temperature, pressure
// and humidity drift (linear trend + a cycle + seeded noise), the refractive index follows
// from them, and a laser interferometer that counts fringes of the vacuum wavelength reads
// n_air times the true displacement, so an uncompensated reading is wrong by (n - 1), about
// 270 ppm, as on a real shop floor. Simulated, and named so.
#include <cstdint>
#include <random>

#include "cal/analysis/air.hpp"
#include "cal/drivers/sim/machine.hpp"

namespace cal::drivers::sim {

// value(t) = start + per_hour * t / 3600 + amplitude * sin(2 pi t / period) + noise
struct Drift {
  double start = 0.0;
  double per_hour = 0.0;
  double amplitude = 0.0;
  double period_s = 3600.0;
  double noise_rms = 0.0;
  double mean(double t_s) const;  // without the noise
};

struct AirConfig {
  Drift temperature_degc{.start = 20.0};
  Drift pressure_pa{.start = 101325.0};
  Drift humidity_pct{.start = 50.0};
  double co2_umol_per_mol = 450.0;
  double wavelength_vacuum_nm = 632.991;
  air::Equation equation = air::Equation::ciddor;  // the "true" air of the simulation
  std::uint64_t seed = 2;
};

struct AirSample {
  double time_s = 0.0;
  double temperature_degc = 20.0;
  double pressure_pa = 101325.0;
  double humidity_pct = 50.0;
  double refractive_index = 1.0;  // of the true (noise-free) air along the beam
};

class Air {
 public:
  explicit Air(AirConfig config);  // throws cal::InputError for a period <= 0
  // The air at time t: the sensor values carry the configured noise, the refractive index is
  // that of the noise-free air (the beam sees the true air; sensors see it with noise). The
  // noise is a function of (seed, quantity, t) alone, not of how many samples were taken
  // before: two twins asking at the same simulated instant, in either order, get the same
  // values, so a simulated session is reproducible bit for bit (cal/drivers/loop_time.hpp).
  AirSample sample(double t_s);
  // The noise-free air at t.
  air::Conditions conditions(double t_s) const;
  const AirConfig& config() const { return config_; }

 private:
  AirConfig config_;
};

// What a fringe-counting laser aligned with `axis` reads, in metres of vacuum wavelength:
// n_air times the displacement of the tool (reflector) from the datum, along the axis.
double laser_reading_m(const MachineState& state, kinematics::Axis axis, double datum_mm,
                       double refractive_index);

// What a telescoping ballbar between the tool ball and a table ball at `pivot_mm` (workpiece
// coordinates) reads: the distance between the ball centres, in mm.
double ballbar_length_mm(const MachineState& state, const Vec3& pivot_mm);

}  // namespace cal::drivers::sim
