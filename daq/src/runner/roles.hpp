#pragma once
// The roles of a run's instruments and the device numbers they are stored under (readings.device
// and instruments.device in the run store, docs/storage.md). Runs look their instruments up by
// role here, never by arithmetic on the numbers: a new role is one line in kRoles.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace cal::drivers {
struct Reading;
}

namespace daq {

enum class Role : std::uint8_t { laser, air, material, position, probe, ballbar };

struct RoleEntry {
  Role role;
  std::string_view name;  // as stored (a probe is stored under its test kind's role instead)
  bool many;              // one device number per instrument (material thermometers), else one
  // A number of its own, outside the sequence (the ballbar of a circle run, which has no other
  // instrument: 3 since the first run files, kept so that stored runs read alike); else the
  // next number after the roles before it.
  std::optional<std::uint16_t> fixed;
};

// In the order of the device numbers: laser 0, air 1, the material thermometers from 2, then the
// position feed and the probe (a linear run's straightness indicator or level).
inline constexpr RoleEntry kRoles[] = {
    {Role::laser, "laser", false, std::nullopt},
    {Role::air, "air", false, std::nullopt},
    {Role::material, "material", true, std::nullopt},
    {Role::position, "position", false, std::nullopt},
    {Role::probe, "probe", false, std::nullopt},
    {Role::ballbar, "ballbar", false, std::uint16_t{3}},
};

// The role's name in kRoles ("laser", "material", ...).
std::string_view name(Role role);

// A driver's product as an engineer names it ("IDS3010", not the driver's key "ids3010"); ""
// for a generic driver (a line gauge reads whatever it is wired to: its configured name and
// role say what it is). The reports' legends and the operator page's instrument cards.
std::string product_name(std::string_view driver);

// The device numbers of one run's instruments, given how many a role with many has.
class RunDevices {
 public:
  explicit RunDevices(std::size_t materials = 0) : materials_(materials) {}
  // The number of the k-th instrument of `role` (k = 0 for a role of one instrument).
  std::uint16_t device(Role role, std::size_t k = 0) const;
  // Which instrument of `role` device number `device` is; nullopt: not one of that role.
  std::optional<std::size_t> index(Role role, std::uint16_t device) const;
  bool is(Role role, std::uint16_t device) const { return index(role, device).has_value(); }

 private:
  std::size_t count(const RoleEntry& e) const { return e.many ? materials_ : 1; }
  std::size_t materials_;
};

// Whether the laser (once it measures: its environment unit reads before that), the air and the
// first material thermometer of a run have each given a reading: what a simulated session
// waits for before the machine moves. Readings carry their device number (LinearRun sets it).
// A run without a laser (rotary: its angular reference sees the stops) waits for its probe instead.
class StartupReadings {
 public:
  explicit StartupReadings(std::size_t materials, bool laser = true)
      : devices_(materials), laser_(!laser), probe_(laser) {}
  void add(const cal::drivers::Reading& r);
  bool all() const { return laser_ && air_ && material_ && probe_; }

 private:
  RunDevices devices_;
  bool laser_, air_ = false, material_ = false, probe_;
};

}  // namespace daq
