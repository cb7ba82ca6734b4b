#pragma once
// Test kinds of the one linear runner (linear_run.hpp). A kind says what is read at each stop
// of an ISO 230-2 plan and how the stops are evaluated: positioning (the laser's deviation from
// the target), straightness (an indicator or transducer across the axis), angular (pitch or yaw
// from two laser axes over their separation), roll (an electronic level against a reference
// level) and rotary (a rotary axis's angular positioning against an angular reference). The
// runner does everything else (instruments, stop recognition by the laser or the
// position feed, sequencing, storage) the same for every kind; a kind is one small file here.
// Conventions (ISO 230-1 names, signs of the tool relative to the workpiece): docs/kinematics.md;
// the set-up keys: docs/config.md; the whole procedure: docs/volumetric-walkthrough.md.
#include <cstdint>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cal/daq/config.hpp"
#include "cal/daq/sequencer.hpp"

namespace daq::kinds {

// Where a reading comes from, as the runner sees it.
enum class Source {
  laser,  // the laser's axes: value = the length compensated for air and material, m
  probe,  // the kind's own instrument (indicator: m; level: rad)
};

// Turns a run's readings into samples of the measured value (um or urad), one per reading
// or pair of readings; stateful (an angle pairs the two beams of one laser answer).
class SampleReader {
 public:
  virtual ~SampleReader() = default;
  virtual std::optional<double> add(Source source, std::uint8_t channel, std::int64_t time_ns,
                                    double value_si) = 0;
};

// One captured stop's value: the target, run, direction and the kind's value at it.
struct StopValue {
  double position_mm = 0.0;
  int target_index = 0;  // 0-based
  int run = 1;
  char direction = '+';
  double value = 0.0;  // in the kind's unit
};

// What a kind's evaluation gives: the result's title and JSON (schema caldaq.profile.v1).
struct Evaluation {
  std::string title;
  nlohmann::json json;
};

// What names a kind: the same four words for each, so they are data, not overrides.
struct KindNames {
  std::string_view name;        // the `measure` key: "straightness"
  std::string_view run_kind;    // the stored run's kind ("linear" positioning)
  std::string_view unit;        // of the values: "um" or "urad"
  std::string_view probe_role;  // the instrument read besides the laser ("indicator"; "" none)
};

class TestKind {
 public:
  explicit constexpr TestKind(KindNames names) : names_(names) {}
  virtual ~TestKind() = default;
  std::string_view name() const { return names_.name; }
  std::string_view run_kind() const { return names_.run_kind; }
  std::string_view unit() const { return names_.unit; }
  std::string_view probe_role() const { return names_.probe_role; }
  // The ISO 230-1 component it measures ("E_YX"), from the axis and direction.
  virtual std::string component(const cal::daq::LinearTestConfig& l) const = 0;
  // The set-up checks beyond the configuration's syntax; throws cal::InputError naming the key.
  virtual void validate(const cal::daq::LinearTestConfig& /*l*/) const {}
  // Every laser axis the kind reads (positioning: none beyond the position channel).
  virtual std::vector<int> laser_channels(const cal::daq::LinearTestConfig& /*l*/) const {
    return {};
  }
  // True when the stops are recognised from the kind's own instrument (its probe role) instead
  // of the laser or the position feed: rotary, whose angular reference is the only instrument
  // that sees the axis (its angle in degrees is the position the trigger and the sequencer
  // watch; the trigger's lengths then read as angles: tolerance_um in millidegrees, window_mm
  // in degrees). Such a kind needs no laser.
  virtual bool stops_from_probe() const { return false; }
  // How the run's events and live line name its positions and deviations (mm and µm; a rotary
  // axis's deg and arcsec).
  virtual cal::daq::AxisUnits axis_units() const { return cal::daq::linear_units; }
  // A captured stop's value as stored and evaluated, from its reader's window mean at the
  // target `position_mm`: the mean itself, but a rotary axis's continuous angle becomes its
  // deviation (arcsec, modulo a turn), so a stored stop reads as a deviation everywhere.
  virtual double stop_value(double /*position_mm*/, double window_mean) const {
    return window_mean;
  }
  // nullptr for positioning: its value is the sequencer's deviation of the laser position.
  virtual std::unique_ptr<SampleReader> reader(const cal::daq::LinearTestConfig& l) const = 0;
  // The stops evaluated (not called for positioning: ISO 230-2 evaluates those).
  virtual Evaluation evaluate(std::span<const StopValue> stops,
                              const cal::daq::LinearTestConfig& l) const;

 private:
  KindNames names_;
};

// A kind that reads its own instrument (its probe role) besides the laser: the value is the
// probe's SI value (m, rad) times `sign` in micro-units (um, urad). Straightness and roll.
class ProbeKind : public TestKind {
 public:
  using TestKind::TestKind;
  std::unique_ptr<SampleReader> reader(const cal::daq::LinearTestConfig& l) const override;
};

// The roles of the devices a linear run of kind `k` opens, and so lists as its instruments:
// the laser and the position feed (not for a kind whose stops come from its own instrument:
// they would measure linear axes that do not move), air, material, and the kind's probe role.
std::vector<std::string> linear_run_roles(const TestKind& k);

// The kind of a `measure` name; throws cal::InputError listing the kinds.
const TestKind& kind(std::string_view name);
std::span<const TestKind* const> all_kinds();

// The kinds' files register here (one function each, so the linker keeps them).
const TestKind& positioning();
const TestKind& straightness();
const TestKind& angular();
const TestKind& roll();
const TestKind& rotary();  // a rotary axis's angular positioning (ISO 230-2 in deg, arcsec)
// An angle in arcsec modulo one turn into [-180 deg, 180 deg), as a rotary stop's deviation is
// stored.
double wrapped_arcsec(double arcsec);

// The profile of a run: per target, the mean of all its stops, of the stops up and down, and
// the spread; for straightness also the least-squares line and the straightness about it.
// JSON schema caldaq.profile.v1 (docs/volumetric-walkthrough.md).
nlohmann::json profile_json(std::span<const StopValue> stops, std::string_view kind,
                            std::string_view component, std::string_view unit);

// The axis index (0, 1, 2) of "X", "Y", "Z".
int axis_index(std::string_view axis);

}  // namespace daq::kinds
