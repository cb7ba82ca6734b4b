#pragma once
// Machine and campaign configuration files (TOML): the machine, the instruments and how to
// reach them, the environment policy, and the tests. Documented with a full example in
// docs/config.md. Every error names the file, the line and column, and the key.
#include <array>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cal/drivers/options.hpp"

namespace cal::daq {

// What a device may be used for (its `role`): a linear run's laser, air station, material
// thermometers and position feed, a circle's ballbar, a straightness run's indicator, a roll
// run's electronic level, a rotary run's angular reference. The one list the loader accepts and
// the operator page's instrument form offers (a role missing from the form, as "angle" was,
// could not be chosen there).
inline constexpr std::string_view device_roles[] = {"laser",    "air",       "material", "ballbar",
                                                    "position", "indicator", "level",    "angle"};

// One [devices.ID] table: the keys every device has, and the device's own options, checked
// against its option table in the registry (drivers/include/cal/drivers/registry.hpp; listed
// by `daq devices --options` and docs/drivers.md).
struct DeviceConfig {
  std::string id;         // the table name, e.g. "laser" in [devices.laser]
  std::string driver;     // a registered driver: ids3010 | ptu300 | gauge | temper | ...
  std::string transport;  // "tcp HOST:PORT", "serial DEVICE BAUD FRAME [FLOW]", "hid VID:PID"
  std::string role;       // one of device_roles: what a run uses it for
  double poll_s = 0.0;    // 0: the driver's default
  // The instrument's identity and calibration, for the records and reports.
  std::string serial_number;
  std::string certificate;        // calibration certificate number
  std::string calibration_due;    // ISO 8601 date, YYYY-MM-DD (checked to be a real date)
  cal::drivers::Options options;  // the driver's own keys, every one with its value
  // "real", or "simulated" for a twin of the built-in simulated shop (`daq sim` and `daq serve
  // --simulate` write it): stored with each run so that nothing derived from it can pass for a
  // measurement of a real machine (docs/storage.md, "Origin").
  std::string origin = "real";
};

enum class StalePolicy { fallback, stop };

struct EnvironmentConfig {
  std::string equation = "ciddor";  // ciddor | edlen | shop-floor
  double stale_after_s = 10.0;
  StalePolicy on_stale = StalePolicy::stop;
  double fallback_temperature_degc = 20.0;
  double fallback_pressure_pa = 101325.0;
  double fallback_humidity_pct = 50.0;
  double fallback_material_degc = 20.0;
  double co2_umol_per_mol = 450.0;
  double wavelength_nm = 632.991;
  double expansion_ppm_per_k = 11.5;  // of the measured part of the machine (scale, spindle)
};

struct TriggerConfig {
  double tolerance_um = 1.0;  // readings within +/- this band ...
  double dwell_s = 1.5;       // ... for this long count as a stop
  double window_mm = 0.5;     // and within this of an expected target
};

// What a linear test reads at each stop (the measure keys of [test.linear], docs/config.md and
// docs/volumetric-walkthrough.md): the test kind and its set-up, stored with the run so that
// `daq model build` can use it. The kinds are daq/src/runner/kinds/.
struct MeasureConfig {
  std::string kind = "positioning";  // positioning | straightness | angular | roll
  // straightness: the direction read (X, Y or Z, not the axis); angular: the rotation axis
  // (A, B or C, not the axis's own: that is roll); positioning and roll: empty.
  std::string direction;
  std::array<double, 3> stationary_mm{};     // where the other axes stand (the axis's entry unused)
  std::array<double, 3> probe_offset_mm{};   // the measured point from the tool reference point
  std::array<int, 2> beams{1, 2};            // angular: the laser axes of beam a and beam b
  std::array<double, 3> separation_mm{};     // angular: from beam b's reflector to beam a's
  double sign = 1.0;  // straightness, roll: -1 when the instrument reads the other way round
  bool square = false;  // straightness read against a square's edge: one of a squareness pair
  // rotary: what the angular reference (the device with role "angle") is, for the report:
  // "laser" (a laser's angular optics over a rotary indexer), "autocollimator" (on a polygon),
  // "level" (an electronic level), "encoder" (a reference encoder or indexer's readout); "": not
  // stated.
  std::string reference;
};

struct LinearTestConfig {
  std::string axis = "X";
  double first_mm = 0.0, last_mm = 500.0;
  std::optional<double> interval_mm;
  std::optional<int> count;
  double random_fraction = 0.0;
  std::string cycle = "linear";  // linear | pendulum | pilgrim-step
  int runs = 5;
  bool bidirectional = true;
  double overrun_mm = 5.0;
  double feed_mm_per_min = 2000.0;
  double dwell_s = 4.0;
  double dead_path_mm = 0.0;
  std::string standard = "iso230-2:2014";
  MeasureConfig measure;
};

// One ballbar test ([test.circle] with `plane`), or a set of them (`planes`, and optionally
// several feeds and radii: docs/config.md, docs/circle.md "The standard set").
struct CircleTestConfig {
  std::string plane = "XY";
  double radius_mm = 100.0;
  double feed_mm_per_min = 1000.0;
  double sample_rate_hz = 1000.0;
  double overshoot_deg = 45.0;
  std::vector<double> centre_mm{0.0, 0.0, 0.0};
  double calibrated_radius_mm = 0.0;       // 0: from a stored calibration of `bar`, else none
  std::string standard = "iso230-4:2005";  // cal::circle::circular_standard_from_key
  // The set: planes in order (empty: the single test of `plane`), feeds and radii (empty: the
  // single feed_mm_per_min and radius_mm), the partial arc of ZX and YZ and its overshoot.
  std::vector<std::string> planes;
  std::vector<double> feeds_mm_per_min, radii_mm;
  double partial_arc_deg = 220.0;
  double partial_overshoot_deg = 10.0;
  double feed_in_mm = 1.5;
  double dwell_s = 1.0;
  std::string bar;  // the bar's identity, for its stored calibrations (daq ballbar calibrate)
};

// Who the test is for and where ([customer]).
struct CustomerConfig {
  std::string name, site, contact;
};

// The state the machine was tested in ([conditions]), stated in the report.
struct TestConditions {
  std::optional<bool> controller_compensation;  // the control's own compensation on or off
  std::string warm_up;                          // e.g. "20 min axes at 50 % rapid"
  std::string load;                             // e.g. "no workpiece"
  std::string state;                            // "as found" | "as left" | "" (not said)
  std::string notes;
};

// Limits of the positioning values of one axis, in um ([tolerances.X]): ISO 230-2's, applied to
// the bidirectional values (E, R, A, M, B) or the unidirectional ones of a one-way test, and
// VDI/DGQ 3441's (P, Pa, Ps max, U max), applied when a run is evaluated by that standard.
struct PositioningLimits {
  std::optional<double> E_um, R_um, B_um, A_um, M_um;
  std::optional<double> P_um, Pa_um, Ps_um, U_um;
  // The axis's other linear tests (ISO 230-1): its straightness about the least-squares line,
  // and its angular deviations (pitch, yaw, roll: the range of each).
  std::optional<double> straightness_um, angular_urad;
  // A rotary axis's (A, B, C: [tolerances.C]) angular positioning values in arcsec, ISO 230-2's
  // and VDI/DGQ 3441's as above; a rotary axis takes only these, a linear axis none of them.
  std::optional<double> E_arcsec, R_arcsec, B_arcsec, A_arcsec, M_arcsec;
  std::optional<double> P_arcsec, Pa_arcsec, Ps_arcsec, U_arcsec;
  // A rotary axis's location errors (ISO 230-1: E_X0C, E_Y0C in um, E_A0C, E_B0C in urad for a
  // C axis) as a five-axis ballbar run fits them: the magnitude of each position and each tilt
  // of its average line that the control's kinematics leave.
  std::optional<double> location_um, location_urad;
  bool empty() const;
};
// Each limit's key in the configuration and the run's stored context, in docs/config.md's order.
struct PositioningLimitKey {
  const char* key;
  std::optional<double> PositioningLimits::*member;
  bool rotary = false;  // a rotary axis's limit (arcsec), else a linear axis's (um, urad)
};
inline constexpr PositioningLimitKey positioning_limit_keys[] = {
    {"E_um", &PositioningLimits::E_um},  {"R_um", &PositioningLimits::R_um},
    {"B_um", &PositioningLimits::B_um},  {"A_um", &PositioningLimits::A_um},
    {"M_um", &PositioningLimits::M_um},  {"P_um", &PositioningLimits::P_um},
    {"Pa_um", &PositioningLimits::Pa_um}, {"Ps_um", &PositioningLimits::Ps_um},
    {"U_um", &PositioningLimits::U_um},  {"straightness_um", &PositioningLimits::straightness_um},
    {"angular_urad", &PositioningLimits::angular_urad},
    {"E_arcsec", &PositioningLimits::E_arcsec, true},
    {"R_arcsec", &PositioningLimits::R_arcsec, true},
    {"B_arcsec", &PositioningLimits::B_arcsec, true},
    {"A_arcsec", &PositioningLimits::A_arcsec, true},
    {"M_arcsec", &PositioningLimits::M_arcsec, true},
    {"P_arcsec", &PositioningLimits::P_arcsec, true},
    {"Pa_arcsec", &PositioningLimits::Pa_arcsec, true},
    {"Ps_arcsec", &PositioningLimits::Ps_arcsec, true},
    {"U_arcsec", &PositioningLimits::U_arcsec, true},
    {"location_um", &PositioningLimits::location_um, true},
    {"location_urad", &PositioningLimits::location_urad, true}};
inline bool PositioningLimits::empty() const {
  for (const auto& k : positioning_limit_keys)
    if (this->*k.member) return false;
  return true;
}
struct AxisTolerance {
  PositioningLimits limits;  // for any measured length
  // Limits for a measured travel up to a length ([[tolerances.X.by_length]]), ascending: the
  // first entry whose up_to_mm is at least the run's travel replaces the axis' limits it sets.
  std::vector<std::pair<double, PositioningLimits>> by_length;
};
// Limits of a circular test in a plane ([tolerances.XY]): G in um, and per diagnostic (its key,
// e.g. "squareness", "backlash_X") a limit on the magnitude of its value in its own unit.
struct CircleTolerance {
  std::optional<double> G_um;
  std::map<std::string, double> diagnostics;
};

struct Config {
  std::filesystem::path source;
  std::string machine_name = "machine";
  std::string machine_description;
  std::string machine_make, machine_model, machine_serial;
  // The kinematic chain and offsets ([machine] topology, tool_offset_mm, table_offset_mm),
  // stored with each run for `daq model build`; empty topology: not said.
  std::string machine_topology;
  std::array<double, 3> machine_tool_offset_mm{}, machine_table_offset_mm{};
  std::string campaign;
  std::string operator_name;  // the top-level key `operator`
  CustomerConfig customer;
  TestConditions conditions;
  std::map<std::string, AxisTolerance> axis_tolerances;     // by axis: X, Y, Z, A, B, C
  std::map<std::string, CircleTolerance> plane_tolerances;  // by plane: XY, YZ, ZX
  std::vector<DeviceConfig> devices;
  EnvironmentConfig environment;
  TriggerConfig trigger;
  std::optional<LinearTestConfig> linear;
  std::optional<CircleTestConfig> circle;
  // The device with a role, or nullptr.
  const DeviceConfig* device_for(std::string_view role) const;
};

// Throws cal::InputError: "FILE:LINE:COL: key 'devices.laser.driver': unknown driver 'foo'
// (expected one of ...)", or TOML syntax errors with their position.
Config load_config(const std::filesystem::path& file);
Config parse_config(std::string_view toml_text, const std::filesystem::path& source_name);

}  // namespace cal::daq
