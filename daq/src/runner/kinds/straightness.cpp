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

class Reader final : public SampleReader {
 public:
  explicit Reader(double sign) : sign_(sign) {}
  std::optional<double> add(Source source, std::uint8_t, std::int64_t, double value_m) override {
    if (source != Source::probe) return std::nullopt;
    return sign_ * value_m * 1e6;  // um
  }

 private:
  double sign_;
};

class Straightness final : public TestKind {
 public:
  std::string_view name() const override { return "straightness"; }
  std::string_view run_kind() const override { return "straightness"; }
  std::string_view unit() const override { return "um"; }
  std::string component(const cal::daq::LinearTestConfig& l) const override {
    return "E_" + l.measure.direction + l.axis;
  }
  std::string_view probe_role() const override { return "indicator"; }
  void validate(const cal::daq::LinearTestConfig& l) const override {
    if (l.measure.direction.size() != 1 || l.measure.direction == l.axis ||
        std::string_view("XYZ").find(l.measure.direction) == std::string_view::npos)
      throw cal::InputError(fmt::format(
          "test.linear.direction '{}': a straightness of {} is read in one of the other axes' "
          "directions",
          l.measure.direction, l.axis));
  }
  std::unique_ptr<SampleReader> reader(const cal::daq::LinearTestConfig& l) const override {
    return std::make_unique<Reader>(l.measure.sign);
  }
};

}  // namespace

const TestKind& straightness() {
  static const Straightness k;
  return k;
}

}  // namespace daq::kinds
