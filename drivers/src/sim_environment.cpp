#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>

#include "cal/analysis/error.hpp"
#include "cal/drivers/sim/environment.hpp"

namespace cal::drivers::sim {

double Drift::mean(double t_s) const {
  return start + per_hour * t_s / 3600.0 +
         amplitude * std::sin(2.0 * std::numbers::pi * t_s / period_s);
}

Air::Air(AirConfig config) : config_(config) {
  for (const Drift* d : {&config_.temperature_degc, &config_.pressure_pa, &config_.humidity_pct})
    if (!(d->period_s > 0.0))
      throw InputError(fmt::format("simulated air: drift period {} s must be > 0", d->period_s));
}

air::Conditions Air::conditions(double t_s) const {
  air::Conditions c;
  c.temperature_degc = config_.temperature_degc.mean(t_s);
  c.pressure_pa = config_.pressure_pa.mean(t_s);
  c.humidity = air::Humidity::relative_pct(std::clamp(config_.humidity_pct.mean(t_s), 0.0, 100.0));
  c.co2_umol_per_mol = config_.co2_umol_per_mol;
  c.wavelength_vacuum_nm = config_.wavelength_vacuum_nm;
  return c;
}

namespace {

// SplitMix64's finaliser: a well-mixed 64-bit hash (Steele, Lea, Flood, "Fast splittable
// pseudorandom number generators", OOPSLA 2014).
std::uint64_t mix(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

// A standard normal deviate determined by (seed, quantity, t) alone (Box-Muller on two
// uniforms from the hash), so that the noise does not depend on the order of the samples.
double normal_at(std::uint64_t seed, std::uint64_t quantity, double t_s) {
  const std::uint64_t h1 =
      mix(seed ^ mix(std::bit_cast<std::uint64_t>(t_s) + 0x9e3779b97f4a7c15ULL * (quantity + 1)));
  const std::uint64_t h2 = mix(h1 + 0x9e3779b97f4a7c15ULL);
  const double u1 = (static_cast<double>(h1 >> 11) + 1.0) * 0x1.0p-53;  // (0, 1]
  const double u2 = static_cast<double>(h2 >> 11) * 0x1.0p-53;          // [0, 1)
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
}

}  // namespace

AirSample Air::sample(double t_s) {
  const air::Conditions c = conditions(t_s);
  const std::uint64_t seed = config_.seed;
  AirSample s;
  s.time_s = t_s;
  s.temperature_degc =
      c.temperature_degc + config_.temperature_degc.noise_rms * normal_at(seed, 0, t_s);
  s.pressure_pa = c.pressure_pa + config_.pressure_pa.noise_rms * normal_at(seed, 1, t_s);
  s.humidity_pct = std::clamp(
      c.humidity.value + config_.humidity_pct.noise_rms * normal_at(seed, 2, t_s), 0.0, 100.0);
  s.refractive_index = air::refractive_index(c, config_.equation).n;
  return s;
}

double laser_reading_m(const MachineState& state, kinematics::Axis axis, double datum_mm,
                       double refractive_index) {
  // Fringes counted with the vacuum wavelength: N = 2 n L / lambda0, reported as
  // N lambda0 / 2 = n L (optical path), hence the factor n.
  return refractive_index * (state.tool_mm[axis] - datum_mm) * 1e-3;
}

double ballbar_length_mm(const MachineState& state, const Vec3& pivot_mm) {
  double sum = 0.0;
  for (std::size_t k = 0; k < 3; ++k) sum += std::pow(state.tool_mm[k] - pivot_mm[k], 2);
  return std::sqrt(sum);
}

}  // namespace cal::drivers::sim
