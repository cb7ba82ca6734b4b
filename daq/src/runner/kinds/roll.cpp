// Roll (E_AX, E_BY, E_CZ): an electronic level on the moving part read against a reference
// level on the workpiece side (the difference), through the line-gauge codec with an angle
// unit; positive for a rotation of the tool relative to the workpiece about +axis (`sign = -1`
// for a level mounted the other way round). A level senses tilt about horizontal axes only, so
// on a real vertical Z axis E_CZ needs angular optics instead; the simulated level reads any.
#include <fmt/format.h>

#include "kind.hpp"

namespace daq::kinds {
namespace {

class Roll final : public ProbeKind {
 public:
  Roll() : ProbeKind({.name = "roll", .run_kind = "roll", .unit = "urad", .probe_role = "level"}) {}
  std::string component(const cal::daq::LinearTestConfig& l) const override {
    return fmt::format("E_{}{}", static_cast<char>('A' + axis_index(l.axis)), l.axis);
  }
};

}  // namespace

const TestKind& roll() {
  static const Roll k;
  return k;
}

}  // namespace daq::kinds
