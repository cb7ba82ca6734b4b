// Positioning (E_XX, E_YY, E_ZZ): the laser's deviation from the target, evaluated by ISO 230-2
// (the runner's sequencer computes it; this kind only names it).
#include "kind.hpp"

namespace daq::kinds {
namespace {

class Positioning final : public TestKind {
 public:
  Positioning() : TestKind({.name = "positioning", .run_kind = "linear", .unit = "um"}) {}
  std::string component(const cal::daq::LinearTestConfig& l) const override {
    return "E_" + l.axis + l.axis;
  }
  std::unique_ptr<SampleReader> reader(const cal::daq::LinearTestConfig&) const override {
    return nullptr;
  }
};

}  // namespace

const TestKind& positioning() {
  static const Positioning k;
  return k;
}

}  // namespace daq::kinds
