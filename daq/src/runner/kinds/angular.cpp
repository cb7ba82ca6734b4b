// Pitch and yaw (E_BX, E_CX, E_AY, E_CY, E_AZ, E_BZ): two laser axes (beam a and beam b, e.g.
// two axes of an IDS3010) parallel to the travel, their reflectors on the moving part
// `separation_mm` apart (from b's to a's). The difference of their displacements is the
// rotation of the tool relative to the workpiece times the separation:
//   d_a - d_b = u . (eps x dr) = eps . (dr x u)      (u the travel direction, dr the separation)
// so with dr x u = s |dr| e_k (s = +-1), eps_k = s (d_a - d_b) / |dr|. The separation must be
// across the travel and turn it about the configured rotation axis; anything else is refused.
#include <fmt/format.h>

#include <array>
#include <cmath>

#include "cal/analysis/error.hpp"
#include "kind.hpp"

namespace daq::kinds {
namespace {

using Vec = std::array<double, 3>;

Vec cross(const Vec& a, const Vec& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

// s / |dr| for the rotation axis k, or InputError.
double factor_per_mm(const cal::daq::LinearTestConfig& l) {
  const auto& dr = l.measure.separation_mm;
  const int axis = axis_index(l.axis);
  const int k = l.measure.direction.empty() ? -1 : l.measure.direction[0] - 'A';
  Vec u{};
  u[static_cast<std::size_t>(axis)] = 1.0;
  const double length = std::hypot(dr[0], dr[1], dr[2]);
  const Vec n = cross(dr, u);
  if (k < 0 || k > 2 || k == axis)
    throw cal::InputError(fmt::format(
        "test.linear.direction '{}': an angular test of {} turns about one of the other axes "
        "(A, B, C)",
        l.measure.direction, l.axis));
  const auto kk = static_cast<std::size_t>(k);
  if (!(length > 0) || std::abs(std::abs(n[kk]) - length) > 1e-9 * length)
    throw cal::InputError(fmt::format(
        "test.linear.separation_mm [{}, {}, {}]: the two beams along {} must be apart across it "
        "so that they see the rotation about {} (for {} about {}: apart along {})",
        dr[0], dr[1], dr[2], l.axis, "XYZ"[kk], l.axis, l.measure.direction,
        "XYZ"[3 - static_cast<std::size_t>(axis) - kk]));
  return (n[kk] > 0 ? 1.0 : -1.0) / length;
}

class Reader final : public SampleReader {
 public:
  Reader(std::array<int, 2> beams, double factor_per_mm) : beams_(beams), factor_(factor_per_mm) {}
  // One laser answer carries every axis at one time: the pair is complete when both beams of
  // the same time are in.
  std::optional<double> add(Source source, std::uint8_t channel, std::int64_t time_ns,
                            double length_m) override {
    if (source != Source::laser) return std::nullopt;
    for (std::size_t b = 0; b < 2; ++b)
      if (channel == beams_[b]) {
        value_[b] = length_m;
        time_[b] = time_ns;
      }
    if (time_[0] != time_[1] || time_[0] < 0 || time_ns != time_[0]) return std::nullopt;
    time_ = {-1, -2};  // each pair once
    // um / mm = 1e-3 rad = 1e3 urad
    return factor_ * (value_[0] - value_[1]) * 1e6 * 1e3;
  }

 private:
  std::array<int, 2> beams_;
  double factor_;
  std::array<double, 2> value_{};
  std::array<std::int64_t, 2> time_{-1, -2};
};

class Angular final : public TestKind {
 public:
  Angular() : TestKind({.name = "angular", .run_kind = "angular", .unit = "urad"}) {}
  std::string component(const cal::daq::LinearTestConfig& l) const override {
    return "E_" + l.measure.direction + l.axis;
  }
  void validate(const cal::daq::LinearTestConfig& l) const override { factor_per_mm(l); }
  std::vector<int> laser_channels(const cal::daq::LinearTestConfig& l) const override {
    return {l.measure.beams[0], l.measure.beams[1]};
  }
  std::unique_ptr<SampleReader> reader(const cal::daq::LinearTestConfig& l) const override {
    return std::make_unique<Reader>(l.measure.beams, factor_per_mm(l));
  }
};

}  // namespace

const TestKind& angular() {
  static const Angular k;
  return k;
}

}  // namespace daq::kinds
