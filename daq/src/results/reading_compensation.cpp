// A stored run's laser readings compensated as the acquisition did (see reading_compensation.hpp).
#include "reading_compensation.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <map>
#include <set>

#include "cal/analysis/error.hpp"
#include "cal/drivers/instrument.hpp"
#include "provenance.hpp"

namespace daq {

namespace st = cal::storage;
using Q = cal::drivers::Quantity;
using nlohmann::json;

namespace {
bool is_material_quantity(std::uint8_t q) {
  // A line thermometer (a gauge codec) reports its temperature as a length.
  return q == static_cast<std::uint8_t>(Q::material_temperature_degc) ||
         q == static_cast<std::uint8_t>(Q::length_m);
}
}  // namespace

std::vector<std::uint8_t> ReadingCompensation::inputs() {
  return {static_cast<std::uint8_t>(Q::displacement_m),
          static_cast<std::uint8_t>(Q::air_temperature_degc),
          static_cast<std::uint8_t>(Q::air_pressure_pa),
          static_cast<std::uint8_t>(Q::air_humidity_pct),
          static_cast<std::uint8_t>(Q::material_temperature_degc),
          static_cast<std::uint8_t>(Q::length_m)};
}

ReadingCompensation::ReadingCompensation(const st::RunReader& store, const st::RunRecord& run,
                                         const json& settings) {
  if (run.kind == "circle" || !settings.is_object() || !settings.contains("environment") ||
      !settings["environment"].is_object())
    throw cal::InputError(fmt::format(
        "run {}: a {} run whose stored settings hold no environment: its readings were never "
        "compensated",
        run.id, run.kind));
  const json& env = settings["environment"];
  const auto used = compensation_used(settings, store.results(run.id));
  cal::daq::EnvironmentConfig cfg;  // the fallbacks are not stored: the configuration's defaults
  cfg.equation = used.coefficients.value("equation", cfg.equation);
  cfg.expansion_ppm_per_k = used.coefficients.value("expansion_ppm_per_k", cfg.expansion_ppm_per_k);
  cfg.co2_umol_per_mol = used.coefficients.value("co2_umol_per_mol", cfg.co2_umol_per_mol);
  cfg.wavelength_nm = used.coefficients.value("wavelength_nm", cfg.wavelength_nm);
  cfg.stale_after_s = env.value("stale_after_s", cfg.stale_after_s);
  cfg.on_stale = env.value("on_stale", "stop") == "fallback" ? cal::daq::StalePolicy::fallback
                                                             : cal::daq::StalePolicy::stop;
  offset_material_k_ = used.offsets.material_k;
  offset_air_k_ = used.offsets.air_temperature_k;
  offset_pressure_pa_ = used.offsets.pressure_pa;
  offset_humidity_ = used.offsets.humidity_pct;

  // The roles as stored (runner/roles.hpp names them): laser, air, material.
  std::vector<std::uint16_t> material_devices;
  for (const auto& i : store.instruments(run.id)) {
    const auto device = static_cast<std::uint16_t>(i.device);
    if (i.driver == "laser") laser_ = device;
    if (i.driver == "air") air_ = device;
    if (i.driver == "material") material_devices.push_back(device);
  }
  std::sort(material_devices.begin(), material_devices.end());
  // A thermometer's channels are the set-up's sensors: those it stored readings on.
  std::map<std::uint16_t, std::set<std::uint8_t>> channels;
  for (const auto& s : store.series(run.id))
    if (is_material_quantity(s.quantity)) channels[s.device].insert(s.channel);
  int sensors = 0;
  for (const auto device : material_devices) {
    const auto& c = channels[device];
    Material m{device, {}, sensors};
    if (c.size() > 1) m.channels.assign(c.begin(), c.end());
    sensors += m.channels.empty() ? 1 : static_cast<int>(m.channels.size());
    materials_.push_back(std::move(m));
  }
  stage_.emplace(cfg, sensors);
}

int ReadingCompensation::material_sensor(const st::RawReading& r) const {
  for (const auto& m : materials_) {
    if (m.device != r.device) continue;
    if (m.channels.empty()) return m.first_sensor;
    const auto it = std::find(m.channels.begin(), m.channels.end(), r.channel);
    return it == m.channels.end() ? -1 : m.first_sensor + static_cast<int>(it - m.channels.begin());
  }
  return -1;
}

std::optional<cal::daq::Compensated> ReadingCompensation::add(const st::RawReading& r) {
  using cal::daq::AirQuantity;
  auto& s = *stage_;
  // A sample the device flagged (out of range, no signal) is no air or material value, as in
  // the live run (linear_run.cpp).
  if (r.status != static_cast<std::uint8_t>(cal::drivers::ReadingStatus::ok) &&
      r.quantity != static_cast<std::uint8_t>(Q::displacement_m))
    return std::nullopt;
  switch (static_cast<Q>(r.quantity)) {
    case Q::air_temperature_degc:
      s.add_air(r.time_ns, AirQuantity::temperature_degc, r.value + offset_air_k_);
      return std::nullopt;
    case Q::air_pressure_pa:
      s.add_air(r.time_ns, AirQuantity::pressure_pa, r.value + offset_pressure_pa_);
      return std::nullopt;
    case Q::air_humidity_pct:  // a TEMPerX on the table measures there, not in the beam
      if (r.device == laser_ || r.device == air_)
        s.add_air(r.time_ns, AirQuantity::humidity_pct, r.value + offset_humidity_);
      return std::nullopt;
    case Q::material_temperature_degc:
    case Q::length_m:
      if (const int k = material_sensor(r); k >= 0)
        s.add_material(r.time_ns, k, r.value + offset_material_k_);
      return std::nullopt;
    case Q::displacement_m:
      if (r.device != laser_) return std::nullopt;
      try {
        return s.compensate(r.time_ns, r.value);
      } catch (const cal::InputError&) {
        return std::nullopt;  // the environment is out of the equation's range
      }
    default:
      return std::nullopt;
  }
}

}  // namespace daq
