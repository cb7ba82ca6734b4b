// Environmental compensation stage (see env_stage.hpp).
#include "cal/daq/env_stage.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "cal/analysis/compensation.hpp"
#include "cal/analysis/error.hpp"

namespace cal::daq {
namespace {
// Samples older than this behind the newest are dropped: interpolation needs only the pair
// around "now" and readings arrive in order, with at most the laser's latency of skew.
constexpr std::int64_t kKeepNs = 120'000'000'000;  // 2 min
}  // namespace

EnvStage::EnvStage(const EnvironmentConfig& config, int material_sensors)
    : config_(config),
      equation_(air::equation_from_string(config.equation)),
      stale_ns_(static_cast<std::int64_t>(config.stale_after_s * 1e9)) {
  air_[0] = {"air temperature", config.fallback_temperature_degc, {}, false};
  air_[1] = {"air pressure", config.fallback_pressure_pa, {}, false};
  air_[2] = {"air humidity", config.fallback_humidity_pct, {}, false};
  for (int i = 0; i < material_sensors; ++i)
    material_.push_back(
        {fmt::format("material sensor {}", i + 1), config.fallback_material_degc, {}, false});
}

void EnvStage::add(Series& s, std::int64_t t, double v) {
  if (!std::isfinite(v)) return;
  // Out-of-order samples (two sensors on different links) are inserted in place.
  auto it = std::upper_bound(s.samples.begin(), s.samples.end(), t,
                             [](std::int64_t x, const auto& p) { return x < p.first; });
  s.samples.insert(it, {t, v});
  while (s.samples.size() > 2 && s.samples.back().first - s.samples.front().first > kKeepNs)
    s.samples.pop_front();
}

void EnvStage::add_air(std::int64_t t, AirQuantity q, double v) {
  add(air_[static_cast<int>(q)], t, v);
}

void EnvStage::add_material(std::int64_t t, int sensor, double v) {
  if (sensor < 0 || sensor >= static_cast<int>(material_.size()))
    throw InputError(fmt::format("material sensor {} does not exist (there are {})", sensor + 1,
                                 material_.size()));
  add(material_[static_cast<std::size_t>(sensor)], t, v);
}

std::optional<double> EnvStage::Series::at(std::int64_t t, std::int64_t stale_ns,
                                           bool& held) const {
  if (samples.empty() || t - samples.back().first > stale_ns) return std::nullopt;
  if (t >= samples.back().first) {
    held = held || t > samples.back().first;
    return samples.back().second;
  }
  if (t <= samples.front().first) return samples.front().second;
  auto hi = std::upper_bound(samples.begin(), samples.end(), t,
                             [](std::int64_t x, const auto& p) { return x < p.first; });
  auto lo = std::prev(hi);
  const double f = static_cast<double>(t - lo->first) / static_cast<double>(hi->first - lo->first);
  return lo->second + f * (hi->second - lo->second);
}

void EnvStage::check_series(Series& s, std::int64_t t, EnvHealth& h) {
  const bool stale = s.samples.empty() || t - s.samples.back().first > stale_ns_;
  if (stale && !s.stale_reported) {
    s.stale_reported = true;
    const std::string age =
        s.samples.empty() ? "no sample yet"
                          : fmt::format("last sample {:.1f} s ago",
                                        static_cast<double>(t - s.samples.back().first) * 1e-9);
    h.messages.push_back(
        config_.on_stale == StalePolicy::stop
            ? fmt::format("{} is stale ({}): stopping", s.name, age)
            : fmt::format("{} is stale ({}): using the fallback {}", s.name, age, s.fallback));
  } else if (!stale && s.stale_reported) {
    s.stale_reported = false;
    h.messages.push_back(fmt::format("{} is back", s.name));
  }
  if (stale && config_.on_stale == StalePolicy::stop) h.must_stop = true;
}

EnvHealth EnvStage::check(std::int64_t t) {
  EnvHealth h;
  for (auto& s : air_) check_series(s, t, h);
  for (auto& s : material_) check_series(s, t, h);
  return h;
}

Compensated EnvStage::compensate(std::int64_t t, double raw_m) const {
  Compensated c;
  c.time_ns = t;
  c.raw_m = raw_m;
  double value[3];
  for (int i = 0; i < 3; ++i) {
    const auto v = air_[i].at(t, stale_ns_, c.held);
    c.fallback_air = c.fallback_air || !v;
    value[i] = v.value_or(air_[i].fallback);
  }
  c.air_temperature_degc = value[0];
  c.pressure_pa = value[1];
  c.humidity_pct = std::clamp(value[2], 0.0, 100.0);
  // The mean of the material sensors that have a current value; all stale: the fallback.
  double sum = 0.0;
  int n = 0;
  for (const auto& s : material_) {
    if (const auto v = s.at(t, stale_ns_, c.held)) {
      sum += *v;
      ++n;
    }
  }
  c.fallback_material = !material_.empty() && n == 0;
  c.material_degc = n > 0 ? sum / n : config_.fallback_material_degc;

  air::Conditions air;
  air.temperature_degc = c.air_temperature_degc;
  air.pressure_pa = c.pressure_pa;
  air.humidity = air::Humidity::relative_pct(c.humidity_pct);
  air.co2_umol_per_mol = config_.co2_umol_per_mol;
  air.wavelength_vacuum_nm = config_.wavelength_nm;
  c.n = air::refractive_index(air, equation_).n;
  const double alpha = config_.expansion_ppm_per_k * 1e-6;
  c.length_m = comp::normalise_to_20c_m(comp::air_length_m(raw_m, c.n), alpha, c.material_degc);
  c.factor_ppm = comp::combined_factor(c.n, alpha, c.material_degc).total_ppm;
  return c;
}

}  // namespace cal::daq
