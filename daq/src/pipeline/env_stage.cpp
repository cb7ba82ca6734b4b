// Environmental compensation stage (see env_stage.hpp).
#include "cal/daq/env_stage.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "cal/analysis/compensation.hpp"
#include "cal/analysis/error.hpp"

namespace cal::daq {
namespace {
// Samples older than this behind the newest are dropped: interpolation needs only the pair
// around "now" and readings arrive in order, with at most the laser's latency of skew.
constexpr std::int64_t kKeepNs = 120'000'000'000;  // 2 min
}  // namespace

EnvStage::EnvStage(const EnvironmentConfig& config, int material_sensors)
    : EnvStage(config,
               EnvSensors{
                   std::vector<bool>(static_cast<std::size_t>(std::max(material_sensors, 0)), true),
                   false}) {
  if (material_sensors < 0)
    throw InputError(fmt::format("material sensors: {} (expected >= 0)", material_sensors));
}

EnvStage::EnvStage(const EnvironmentConfig& config, const EnvSensors& sensors)
    : config_(config),
      equation_(air::equation_from_string(config.equation)),
      keep_all_(sensors.keep_all_samples),
      stale_ns_(static_cast<std::int64_t>(std::min(config.stale_after_s, 1e9) * 1e9)) {
  if (!(config.stale_after_s > 0))
    throw InputError(
        fmt::format("environment: stale_after_s {} (expected > 0 s)", config.stale_after_s));
  if (!std::isfinite(config.expansion_ppm_per_k))
    throw InputError(fmt::format("environment: expansion_ppm_per_k {} (expected a finite value)",
                                 config.expansion_ppm_per_k));
  air_[0] = {"air temperature", config.fallback_temperature_degc, {}, false, true, true};
  air_[1] = {"air pressure", config.fallback_pressure_pa, {}, false, true, true};
  air_[2] = {"air humidity", config.fallback_humidity_pct, {}, false, true, true};
  air_[3] = {"air CO2", config.co2_umol_per_mol, {}, false, sensors.co2, true};
  for (std::size_t i = 0; i < sensors.material_enabled.size(); ++i)
    material_.push_back({fmt::format("material sensor {}", i + 1),
                         config.fallback_material_degc,
                         {},
                         false,
                         true,
                         sensors.material_enabled[i]});
  if (!material_.empty() &&
      std::none_of(material_.begin(), material_.end(), [](const auto& m) { return m.enabled; }))
    throw InputError(fmt::format("material sensors: all {} are disabled (at least one must be on)",
                                 material_.size()));
}

void EnvStage::set_material_enabled(int sensor, bool enabled) {
  if (sensor < 0 || sensor >= static_cast<int>(material_.size()))
    throw InputError(fmt::format("material sensor {} does not exist (there are {})", sensor + 1,
                                 material_.size()));
  auto& s = material_[static_cast<std::size_t>(sensor)];
  if (!enabled && s.enabled && std::count_if(material_.begin(), material_.end(), [](const auto& m) {
                                 return m.enabled;
                               }) == 1)
    throw InputError(
        fmt::format("material sensor {}: the last enabled one cannot be disabled", sensor + 1));
  s.enabled = enabled;
  held_cache_.valid = false;
  s.stale_reported = false;  // a new episode if it is stale when enabled again
}

void EnvStage::add(Series& s, std::int64_t t, double v) {
  if (!std::isfinite(v)) return;
  held_cache_.valid = false;
  // Out-of-order samples (two sensors on different links) are inserted in place.
  auto it = std::upper_bound(s.samples.begin(), s.samples.end(), t,
                             [](std::int64_t x, const auto& p) { return x < p.first; });
  s.samples.insert(it, {t, v});
  while (!keep_all_ && s.samples.size() > 2 &&
         s.samples.back().first - s.samples.front().first > kKeepNs)
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

bool EnvStage::Series::at(std::int64_t t, std::int64_t stale_ns, bool& held, double& value) const {
  if (samples.empty()) return false;
  const auto& newest = samples.back();
  if (t - newest.first > stale_ns) return false;
  if (t >= newest.first) {
    held = held || t > newest.first;
    value = newest.second;
    return true;
  }
  if (t <= samples.front().first) {
    value = samples.front().second;
    return true;
  }
  auto hi = std::upper_bound(samples.begin(), samples.end(), t,
                             [](std::int64_t x, const auto& p) { return x < p.first; });
  auto lo = std::prev(hi);
  const double f = static_cast<double>(t - lo->first) / static_cast<double>(hi->first - lo->first);
  value = lo->second + f * (hi->second - lo->second);
  return true;
}

void EnvStage::check_series(Series& s, std::int64_t t, EnvHealth& h) {
  if (!s.required || !s.enabled) return;
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
  for (auto& s : air_) check_series(s, t, h);  // the CO2 only with a sensor (required)
  for (auto& s : material_) check_series(s, t, h);
  return h;
}

double EnvStage::refractive_index(const double (&in)[4]) const {
  // Compared bit for bit (memcmp), so -0.0 and 0.0 are different states; a state the
  // equation refuses (it throws) is never cached, so it is refused again every time.
  if (index_cache_.valid && std::memcmp(index_cache_.key, in, sizeof in) == 0)
    return index_cache_.n;
  air::Conditions air;
  air.temperature_degc = in[0];
  air.pressure_pa = in[1];
  air.humidity = air::Humidity::relative_pct(in[2]);
  air.co2_umol_per_mol = in[3];
  air.wavelength_vacuum_nm = config_.wavelength_nm;
  const double n = air::refractive_index(air, equation_).n;  // throws: nothing cached
  std::memcpy(index_cache_.key, in, sizeof in);
  index_cache_.n = n;
  index_cache_.valid = true;
  return n;
}

double EnvStage::factor_ppm(double n, double material_degc) const {
  const double key[2] = {n, material_degc};
  if (factor_cache_.valid && std::memcmp(&factor_cache_.n, &key[0], sizeof(double)) == 0 &&
      std::memcmp(&factor_cache_.material_degc, &key[1], sizeof(double)) == 0)
    return factor_cache_.total_ppm;
  const double ppm =
      comp::combined_factor(n, config_.expansion_ppm_per_k * 1e-6, material_degc).total_ppm;
  factor_cache_ = {true, n, material_degc, ppm};
  return ppm;
}

Compensated EnvStage::environment_at(std::int64_t t) const {
  Compensated c;
  double value[4];
  // The interval over which this environment stays held (see HeldCache): after the newest
  // sample of every sensor consulted, until the first of the current ones goes stale.
  std::int64_t after = std::numeric_limits<std::int64_t>::min();
  std::int64_t until = std::numeric_limits<std::int64_t>::max();
  const auto bound = [&](const Series& s, bool current) {
    if (s.samples.empty()) return;
    const std::int64_t newest = s.samples.back().first;
    after = std::max(after, newest);
    if (current)
      until = std::min(until, newest > std::numeric_limits<std::int64_t>::max() - stale_ns_
                                  ? std::numeric_limits<std::int64_t>::max()
                                  : newest + stale_ns_);
  };
  for (int i = 0; i < 4; ++i) {
    const bool current = air_[i].at(t, stale_ns_, c.held, value[i]);
    // Without a CO2 sensor the configured constant is the value, not a fallback.
    c.fallback_air = c.fallback_air || (!current && air_[i].required);
    if (!current) value[i] = air_[i].fallback;
    bound(air_[i], current);
  }
  c.co2_umol_per_mol = value[3];
  c.air_temperature_degc = value[0];
  c.pressure_pa = value[1];
  c.humidity_pct = std::clamp(value[2], 0.0, 100.0);
  // The mean of the material sensors that have a current value; all stale: the fallback.
  double sum = 0.0;
  int n = 0;
  for (const auto& s : material_) {
    if (!s.enabled) continue;
    double v = 0.0;
    const bool current = s.at(t, stale_ns_, c.held, v);
    if (current) {
      sum += v;
      ++n;
    }
    bound(s, current);
  }
  c.fallback_material = !material_.empty() && n == 0;
  c.material_degc = n > 0 ? sum / n : config_.fallback_material_degc;
  c.n =
      refractive_index({c.air_temperature_degc, c.pressure_pa, c.humidity_pct, c.co2_umol_per_mol});
  c.factor_ppm = factor_ppm(c.n, c.material_degc);
  if (t > after && t <= until) held_cache_ = {true, after, until, c};
  return c;
}

namespace {
// L20 = raw / (n (1 + alpha (T - 20))): cal::comp (ISO 1 reference temperature). The one
// formula of both compensate() and compensated_length_m().
double length_at_20c_m(double raw_m, double n, double expansion_ppm_per_k, double material_degc) {
  return comp::normalise_to_20c_m(comp::air_length_m(raw_m, n), expansion_ppm_per_k * 1e-6,
                                  material_degc);
}
}  // namespace

Compensated EnvStage::compensate(std::int64_t t, double raw_m) const {
  const Compensated* held = held_at(t);
  Compensated c = held ? *held : environment_at(t);
  c.time_ns = t;
  c.raw_m = raw_m;
  c.length_m = length_at_20c_m(raw_m, c.n, config_.expansion_ppm_per_k, c.material_degc);
  return c;
}

double EnvStage::compensated_length_m(std::int64_t t, double raw_m) const {
  if (const Compensated* held = held_at(t))
    return length_at_20c_m(raw_m, held->n, config_.expansion_ppm_per_k, held->material_degc);
  return compensate(t, raw_m).length_m;
}

}  // namespace cal::daq
