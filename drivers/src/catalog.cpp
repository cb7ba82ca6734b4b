#include "cal/drivers/catalog.hpp"

#include <array>

namespace cal::drivers {
namespace {

// PCsensor TEMPer family: the VID:PID pairs handled by the public reverse-engineering
// projects (e.g. urwen/temper, padelt/temper-python). Several models share a pair; the
// firmware string read at open tells them apart.
constexpr std::array kDevices{
    KnownDevice{0x0c45, 0x7401, "temper", "PCsensor TEMPer / TEMPer1 / TEMPer2 (RDing)", "hid"},
    KnownDevice{0x0c45, 0x7402, "temper", "PCsensor TEMPerHUM (RDing)", "hid"},
    KnownDevice{0x413d, 0x2107, "temper", "PCsensor TEMPerGold / TEMPer2 (v3.x firmware)", "hid"},
    KnownDevice{0x1a86, 0xe025, "temper", "PCsensor TEMPerGold (CH554-based)", "hid"},
    KnownDevice{0x3553, 0xa001, "temper", "PCsensor TEMPerX", "hid"},
};

}  // namespace

std::span<const KnownDevice> known_usb_devices() { return kDevices; }

const KnownDevice* find_known_device(std::uint16_t vid, std::uint16_t pid) {
  for (const auto& d : kDevices)
    if (d.vendor_id == vid && d.product_id == pid) return &d;
  return nullptr;
}

}  // namespace cal::drivers
