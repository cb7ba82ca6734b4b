// Angular positioning of a rotary axis (E_AA, E_BB, E_CC), evaluated by ISO 230-2 as a linear
// axis is: the targets in degrees (the keys first_mm, last_mm, interval_mm and overrun_mm of
// [test.linear] hold degrees for an axis A, B or C), the deviations in arcseconds. The
// reference is an angular instrument whose readings arrive as a stream through the gauge codec
// with an angle unit (probe role "angle": a laser's angular optics over a rotary indexer, an
// autocollimator on a polygon, an electronic level): it reads the axis's angle, zeroed with
// the axis at 0 deg, modulo one turn as an indexer or encoder gives it (0 .. 360 deg or
// -180 .. 180 deg: any representative). Its stream alone recognises the stops
// (stops_from_probe): the runner watches its continuous angle in degrees as a linear run
// watches the laser's length in mm; no laser is read. Assumed: between two successive readings the
// axis turns less than half a turn, so the reader follows the turns (a stop at 360 deg averages
// readings on both sides of 0 without a jump); a stop's deviation is taken modulo one turn into
// [-180, 180) deg, so targets 0 and 360 deg are told apart only by the plan, as on the machine.
#include <fmt/format.h>

#include <cmath>

#include "cal/analysis/error.hpp"
#include "cal/analysis/iso230_2.hpp"
#include "kind.hpp"

namespace daq::kinds {
namespace {

constexpr double kArcsecPerDeg = 3600.0;
constexpr double kTurnArcsec = 360.0 * kArcsecPerDeg;
constexpr double kPi = 3.14159265358979323846;

// The reference's angle (rad, modulo a turn) as a continuous angle in arcsec: each reading
// taken within half a turn of the previous one.
class Reader final : public SampleReader {
 public:
  explicit Reader(double sign) : sign_(sign) {}
  std::optional<double> add(Source source, std::uint8_t, std::int64_t, double angle_rad) override {
    if (source != Source::probe) return std::nullopt;
    const double reading = sign_ * angle_rad * 180.0 / kPi * kArcsecPerDeg;
    // The first reading in [-180, 180) deg: the run starts near its first target, 0 deg read
    // as 359.999 deg is -0.001 deg (the runner's stops are recognised on this angle).
    angle_ =
        previous_ ? *previous_ + wrapped_arcsec(reading - *previous_) : wrapped_arcsec(reading);
    previous_ = angle_;
    return angle_;
  }

 private:
  double sign_;
  double angle_ = 0.0;
  std::optional<double> previous_;
};

class Rotary final : public TestKind {
 public:
  Rotary()
      : TestKind(
            {.name = "rotary", .run_kind = "rotary", .unit = "arcsec", .probe_role = "angle"}) {}
  std::string component(const cal::daq::LinearTestConfig& l) const override {
    return "E_" + l.axis + l.axis;
  }
  void validate(const cal::daq::LinearTestConfig& l) const override {
    if (l.axis != "A" && l.axis != "B" && l.axis != "C")
      throw cal::InputError(fmt::format(
          "test.linear.axis '{}': a rotary test measures a rotary axis (A, B, C)", l.axis));
  }
  bool stops_from_probe() const override { return true; }
  cal::daq::AxisUnits axis_units() const override { return cal::daq::rotary_units; }
  // The reference's angle at the stop minus its target, modulo a turn into [-180, 180) deg.
  double stop_value(double position_deg, double angle_arcsec) const override {
    return wrapped_arcsec(angle_arcsec - position_deg * kArcsecPerDeg);
  }
  std::unique_ptr<SampleReader> reader(const cal::daq::LinearTestConfig& l) const override {
    return std::make_unique<Reader>(l.measure.sign);
  }
  // Each stop's deviation (stop_value: its reference angle minus its target, modulo a turn)
  // evaluated by the configured standard, in degrees and arcseconds.
  Evaluation evaluate(std::span<const StopValue> stops,
                      const cal::daq::LinearTestConfig& l) const override {
    if (stops.empty()) throw cal::InputError("no stop was captured: nothing to evaluate");
    namespace iso = cal::iso230_2;
    std::vector<iso::Measurement> m;
    for (const auto& s : stops)
      m.push_back({.target_mm = s.position_mm,  // deg
                   .run = s.run,
                   .direction = s.direction == '+' ? iso::Direction::up : iso::Direction::down,
                   .deviation_um = wrapped_arcsec(s.value)});  // any turn's representative
    const auto e = iso::evaluate(m, iso::standard_from_string(l.standard));
    return {fmt::format("{} rotary {} ({})", e.standard.title, l.axis, component(l)),
            rotary_json(e, component(l))};
  }

 private:
  // caldaq.rotary.v1: the ISO 230-2 evaluation with its units named (deg, arcsec).
  static nlohmann::json rotary_json(const cal::iso230_2::Evaluation& e,
                                    const std::string& component) {
    using nlohmann::json;
    json targets = json::array();
    for (const auto& t : e.targets)
      targets.push_back({{"position_deg", t.target_mm},
                         {"mean_up", t.mean_up_um},
                         {"mean_down", t.runs_down ? json(t.mean_down_um) : json(nullptr)},
                         {"s_up", t.s_up_um},
                         {"s_down", t.runs_down ? json(t.s_down_um) : json(nullptr)},
                         {"mean", t.mean_bi_um},
                         {"reversal", t.runs_down ? json(t.reversal_um) : json(nullptr)}});
    json axis = json::object(), values = json::array();  // values: in the evaluation's order
    for (const auto& a : e.axis) {
      axis[a.key] = {{"symbol", a.symbol}, {"description", a.description}, {"value", a.value_um}};
      values.push_back({{"key", a.key},
                        {"symbol", a.symbol},
                        {"description", a.description},
                        {"value", a.value_um},
                        {"unit", "arcsec"}});
    }
    return {{"schema", "caldaq.rotary.v1"},
            {"kind", "rotary"},
            {"component", component},
            {"standard", e.standard.key},
            {"title", e.standard.title},
            {"target_unit", "deg"},
            {"unit", "arcsec"},
            {"runs", e.runs},
            {"bidirectional", e.bidirectional},
            {"targets", targets},
            {"axis", axis},
            {"values", values},
            {"warnings", e.warnings}};
  }
};

}  // namespace

double wrapped_arcsec(double x) {
  return x - kTurnArcsec * std::floor((x + kTurnArcsec / 2) / kTurnArcsec);
}

const TestKind& rotary() {
  static const Rotary k;
  return k;
}

}  // namespace daq::kinds
