// Device numbers by role (see roles.hpp).
#include "roles.hpp"

#include <utility>

#include "cal/drivers/instrument.hpp"

namespace daq {

std::string_view name(Role role) {
  for (const auto& e : kRoles)
    if (e.role == role) return e.name;
  return "";
}

std::uint16_t RunDevices::device(Role role, std::size_t k) const {
  std::size_t next = 0;
  for (const auto& e : kRoles) {
    if (e.role == role) return static_cast<std::uint16_t>(e.fixed ? *e.fixed + k : next + k);
    if (!e.fixed) next += count(e);
  }
  return 0;  // every Role has its row
}

std::optional<std::size_t> RunDevices::index(Role role, std::uint16_t device) const {
  for (const auto& e : kRoles)
    if (e.role == role) {
      const std::size_t first = this->device(role);
      if (device < first || device - first >= count(e)) return std::nullopt;
      return device - first;
    }
  return std::nullopt;
}

void StartupReadings::add(const cal::drivers::Reading& r) {
  if (devices_.is(Role::laser, r.device))
    laser_ = laser_ || r.quantity == cal::drivers::Quantity::displacement_m;
  else if (devices_.is(Role::air, r.device))
    air_ = true;
  else if (devices_.index(Role::material, r.device) == 0)
    material_ = true;
  else if (devices_.is(Role::probe, r.device))
    probe_ = true;
}

std::string product_name(std::string_view driver) {
  static constexpr std::pair<std::string_view, std::string_view> products[] = {
      {"ids3010", "IDS3010"},
      {"ptu300", "PTU300"},
      {"temper", "TEMPer"},
      {"shdr", "MTConnect SHDR"},
      {"halsampler", "LinuxCNC halsampler"}};
  for (const auto& [key, product] : products)
    if (driver == key) return std::string(product);
  return driver == "gauge" ? "" : std::string(driver);
}

}  // namespace daq
