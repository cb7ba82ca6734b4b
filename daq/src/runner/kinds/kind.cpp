// The registry of test kinds and the profile evaluation they share (see kind.hpp).
#include "kind.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>

#include "cal/analysis/error.hpp"
#include "cal/analysis/straightness.hpp"

namespace daq::kinds {

using nlohmann::json;

int axis_index(std::string_view axis) { return axis == "Y" ? 1 : axis == "Z" ? 2 : 0; }

namespace {

class ProbeReader final : public SampleReader {
 public:
  explicit ProbeReader(double sign) : sign_(sign) {}
  std::optional<double> add(Source source, std::uint8_t, std::int64_t, double value_si) override {
    if (source != Source::probe) return std::nullopt;
    return sign_ * value_si * 1e6;  // m -> um, rad -> urad
  }

 private:
  double sign_;
};

}  // namespace

std::unique_ptr<SampleReader> ProbeKind::reader(const cal::daq::LinearTestConfig& l) const {
  return std::make_unique<ProbeReader>(l.measure.sign);
}

std::span<const TestKind* const> all_kinds() {
  static const std::array<const TestKind*, 5> k{&positioning(), &straightness(), &angular(),
                                                &roll(), &rotary()};
  return k;
}

std::vector<std::string> linear_run_roles(const TestKind& k) {
  std::vector<std::string> roles;
  if (!k.stops_from_probe()) roles = {"laser", "position"};
  roles.insert(roles.end(), {"air", "material"});
  if (!k.probe_role().empty()) roles.emplace_back(k.probe_role());
  return roles;
}

const TestKind& kind(std::string_view name) {
  for (const auto* k : all_kinds())
    if (k->name() == name) return *k;
  throw cal::InputError(fmt::format(
      "test kind '{}' (expected positioning, straightness, angular, roll or rotary)", name));
}

Evaluation TestKind::evaluate(std::span<const StopValue> stops,
                              const cal::daq::LinearTestConfig& l) const {
  const std::string c = component(l);
  return {fmt::format("{} {} (profile)", name(), c), profile_json(stops, name(), c, unit())};
}

json profile_json(std::span<const StopValue> stops, std::string_view kind,
                  std::string_view component, std::string_view unit) {
  if (stops.empty()) throw cal::InputError("no stop was captured: nothing to evaluate");
  struct Sums {
    double position_mm = 0, all = 0, up = 0, down = 0, lo = INFINITY, hi = -INFINITY;
    int n = 0, n_up = 0, n_down = 0;
  };
  std::map<int, Sums> by_target;
  for (const auto& s : stops) {
    auto& t = by_target[s.target_index];
    t.position_mm = s.position_mm;
    t.all += s.value, ++t.n;
    (s.direction == '+' ? t.up : t.down) += s.value;
    ++(s.direction == '+' ? t.n_up : t.n_down);
    t.lo = std::min(t.lo, s.value), t.hi = std::max(t.hi, s.value);
  }
  json targets = json::array();
  std::vector<double> q, v;
  for (const auto& [index, t] : by_target) {
    json row{{"index", index},
             {"position_mm", t.position_mm},
             {"mean", t.all / t.n},
             {"count", t.n},
             {"spread", t.hi - t.lo}};
    row["mean_up"] = t.n_up ? json(t.up / t.n_up) : json(nullptr);
    row["mean_down"] = t.n_down ? json(t.down / t.n_down) : json(nullptr);
    targets.push_back(row);
    q.push_back(t.position_mm), v.push_back(t.all / t.n);
  }
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  json j{{"schema", "caldaq.profile.v1"},
         {"kind", kind},
         {"component", component},
         {"unit", unit},
         {"targets", targets},
         {"range", *hi - *lo}};
  if (kind == "straightness" && q.size() >= 2) {
    const auto r = cal::straightness::evaluate(q, v, cal::straightness::Reference::least_squares);
    j["straightness_um"] = r.straightness_um;
    j["slope_um_per_m"] = r.slope_um_per_m;
    j["reference"] = "least squares";
  }
  return j;
}

}  // namespace daq::kinds
