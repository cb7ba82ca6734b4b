// Straightness (E_YX, E_ZX, E_XY, E_ZY, E_XZ, E_YZ): an indicator or length transducer with its
// tip across the axis (against a straightedge, or a square's edge for a squareness pair), read
// in the configured direction; positive when the tool moves in +direction relative to the
// workpiece (`sign = -1` for an instrument mounted the other way round). The straightedge's own
// error is not separated (no reversal yet): it is taken as negligible, as it is in the
// simulation, where the straightedge is perfect and aligned with the nominal axis.
#include <fmt/format.h>

#include "cal/analysis/error.hpp"
#include "kind.hpp"

namespace daq::kinds {
namespace {

class Straightness final : public ProbeKind {
 public:
  Straightness()
      : ProbeKind({.name = "straightness",
                   .run_kind = "straightness",
                   .unit = "um",
                   .probe_role = "indicator"}) {}
  std::string component(const cal::daq::LinearTestConfig& l) const override {
    return "E_" + l.measure.direction + l.axis;
  }
  void validate(const cal::daq::LinearTestConfig& l) const override {
    if (l.measure.direction.size() != 1 || l.measure.direction == l.axis ||
        std::string_view("XYZ").find(l.measure.direction) == std::string_view::npos)
      throw cal::InputError(fmt::format(
          "test.linear.direction '{}': a straightness of {} is read in one of the other axes' "
          "directions",
          l.measure.direction, l.axis));
  }
};

}  // namespace

const TestKind& straightness() {
  static const Straightness k;
  return k;
}

}  // namespace daq::kinds
