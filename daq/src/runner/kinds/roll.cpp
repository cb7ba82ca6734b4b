// Roll (E_AX, E_BY, E_CZ): an electronic level on the moving part read against a reference
// level on the workpiece side (the difference), through the line-gauge codec with an angle
// unit; positive for a rotation of the tool relative to the workpiece about +axis (`sign = -1`
// for a level mounted the other way round). A level senses tilt about horizontal axes only, so
// on a real vertical Z axis E_CZ needs angular optics instead; the simulated level reads any.
#include <fmt/format.h>

#include "kind.hpp"

namespace daq::kinds {
namespace {

class Reader final : public SampleReader {
 public:
  explicit Reader(double sign) : sign_(sign) {}
  std::optional<double> add(Source source, std::uint8_t, std::int64_t, double value_rad) override {
    if (source != Source::probe) return std::nullopt;
    return sign_ * value_rad * 1e6;  // urad
  }

 private:
  double sign_;
};

class Roll final : public TestKind {
 public:
  std::string_view name() const override { return "roll"; }
  std::string_view run_kind() const override { return "roll"; }
  std::string_view unit() const override { return "urad"; }
  std::string component(const cal::daq::LinearTestConfig& l) const override {
    return fmt::format("E_{}{}", static_cast<char>('A' + axis_index(l.axis)), l.axis);
  }
  std::string_view probe_role() const override { return "level"; }
  std::unique_ptr<SampleReader> reader(const cal::daq::LinearTestConfig& l) const override {
    return std::make_unique<Reader>(l.measure.sign);
  }
};

}  // namespace

const TestKind& roll() {
  static const Roll k;
  return k;
}

}  // namespace daq::kinds
