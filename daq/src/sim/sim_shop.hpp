#pragma once
// The built-in SIMULATED machine shop for `daq demo` and the end-to-end tests: a machine with
// known injected errors, drifting air, and the instrument twins (IDS3010 on loopback TCP,
// PTU300 and a material thermometer and a ballbar gauge on pseudo-terminals), all on one
// simulated time line running `speed` times faster than the wall clock. The real drivers
// connect to the twins exactly as to hardware.
#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "cal/analysis/iso230_2.hpp"
#include "cal/analysis/iso230_2_targets.hpp"
#include "cal/daq/ballbar.hpp"
#include "cal/daq/config.hpp"
#include "cal/daq/gcode.hpp"
#include "cal/drivers/instrument.hpp"
#include "cal/drivers/sim/machine.hpp"

namespace boost::asio {
class io_context;
}

namespace daq {

struct LinearRunSetup;  // linear_run.hpp

// The rotary test of the simulated shop (`daq sim --test rotary`): axis C, 0 .. 360 deg every
// 45 deg with 3 deg of overrun, `runs` runs each way, 1200 deg/min, 3 s at each stop.
cal::daq::LinearTestConfig simulated_rotary_test(int runs = 5);

// How SimulatedShop::connect_linear connects a linear run's instruments to the shop's twins.
struct ShopInstruments {
  // Simulated seconds between laser polls: 100 Hz sees the 3 mm overrun excursions, without
  // which a stop's approach is unknown (and an automatic capture without one is refused).
  double laser_poll_s = 0.01;
  std::array<bool, 3> laser_axes{true, false, false};  // the interferometer axes read
  bool laser = true;     // false: no laser (a rotary test reads only its angular reference)
  bool material = true;  // a material thermometer besides the laser and the air station
  cal::drivers::WireRecorder* recorder = nullptr;  // records every instrument's bytes if set
};

// The injected errors: the truth the measured results are compared with.
struct ShopTruth {
  double scale_um_per_m = 8.0;       // E_XX linear term
  double cyclic_amplitude_um = 1.0;  // pitch error of the X drive
  double cyclic_period_mm = 40.0;
  double backlash_um = 4.0;
  double noise_um = 0.15;
  double machine_degc = 21.5;  // the scales expand: the material compensation removes it
  double expansion_ppm_per_k = 11.5;
  double air_start_degc = 20.6, air_drift_k_per_h = 0.6;
  double pressure_pa = 100650.0, humidity_pct = 42.0;
  // For the circular test in XY: squareness (E_C0Y) and the Y position loop slower than X's
  // (servo mismatch: Y lags X by 1/kv_y - 1/kv_x), the ballbar's table ball and length.
  double squareness_um_per_m = 20.0;
  double kv_x_per_s = 30.0, kv_y_per_s = 29.7;  // Y lags X by 0.337 ms
  std::array<double, 3> pivot_mm{150.0, 0.0, 0.0};
  double ballbar_mm = 100.0;
  // The bar's continuous output rate (simulated time) and [test.circle] sample_rate_hz: a
  // QC20-W streams 1 kHz; a faster gauge (daq sim --ballbar-rate-hz) makes the long 10 kHz
  // runs of issue 32's bounded-memory goal live.
  double ballbar_rate_hz = 1000.0;
  // The vertical planes (three_planes()): E_B0Z and E_A0Z (urad; the ballbar's alpha_ZX =
  // -E_B0Z, alpha_YZ = +E_A0Z), Z's position loop, backlash and cyclic error of Y and Z.
  double b0z_urad = 0.0, a0z_urad = 0.0;
  double kv_z_per_s = 30.0;
  double noise_yz_um = 0.0;  // Y's and Z's position noise (X's is noise_um)
  double backlash_y_um = 0.0, backlash_z_um = 0.0;
  double cyclic_y_amplitude_um = 0.0, cyclic_y_period_mm = 40.0;
  double cyclic_z_amplitude_um = 0.0, cyclic_z_period_mm = 40.0;
  // The truth of the three-plane set (`daq sim --test circle-set`): the above plus squareness
  // in ZX and YZ, a slower Z loop, backlash and cyclic error on every axis. The cyclic errors
  // share X's 40 mm period (screws of one pitch): the circle analysis fits one period per
  // plane (docs/circle.md).
  static ShopTruth three_planes();
  // Rotations of the X carriage, linear in X from 0 at X = 0 (urad per metre of X travel; ISO
  // 230-1's E_AX roll, E_BX pitch, E_CX yaw, the kinematic model's signs): what an angular
  // test (two laser beams) and a roll test (a level) read. They act on the tool through the
  // other axes' positions (FXYZ: Y and Z ride on X), so at Y = Z = 0 a positioning test of X
  // does not see them.
  double roll_x_urad_per_m = 0.0, pitch_x_urad_per_m = 0.0, yaw_x_urad_per_m = 0.0;
  // A vibration of the Y axis (cal::drivers::sim::ServoAxis::vibration_um): its amplitude
  // (peak, um) at a frequency, moving or standing. A ballbar in XY or YZ sees it; a laser or
  // indicator reading X does not.
  double vibration_y_um = 0.0, vibration_y_hz = 0.0;
  // The machine of `daq serve --simulate`: three_planes() with non-zero rotations of X and a
  // vibration of Y, so that the page's angular, roll and ballbar tests measure something
  // known (docs/web.md, "The simulated shop"):
  //   E_AX roll  +40 urad/m x X (+4 urad at X = 100 mm)
  //   E_BX pitch +40 urad/m x X (+4 urad at X = 100 mm)
  //   E_CX yaw   -20 urad/m x X (-2 urad at X = 100 mm)
  //   Y vibrates 0.6 um (peak) at 23.7 Hz: a ballbar circle in XY reads it as 0.3 um rms
  //   (docs/circle.md: an axial vibration of amplitude A is A/2 rms over a circle).
  static ShopTruth served();
  // All 21 geometric errors (sim_volumetric.hpp): when set, the machine's geometry is this
  // instead of the E_XX scale and E_C0Y above (the servo, thermal and air settings stay).
  std::optional<cal::kinematics::Machine> geometry;
  // Simulated seconds between a request to the indicator or the level and its answer (the
  // value is of the request's time): a loaded host or a slow adapter, injected by the tests.
  double probe_answer_delay_s = 0.0;
  // ... and the probe measures when it answers, not at the request (a device that queues
  // requests; what a starved twin process does): a late answer's value is of its answer time.
  bool probe_measures_on_answer = false;
  // The deviation at 20 degC of a stop at x approached from below (up) or above.
  double deviation_um(double x_mm, cal::iso230_2::Direction d) const;
  // A rotary test (measure = "rotary", `daq sim --test rotary`): the test's axis (A, B or C)
  // turns in degrees on the machine's first servo (its lengths read as angles: 1 um of it is
  // 1 millidegree = 3.6"), at 20 degC, with these errors in arcsec; a SIMULATED angular
  // reference (a rotary indexer's readout, through the gauge codec in arcsec) reads its angle
  // modulo a turn, 0 .. 360 deg.
  struct Rotary {
    double scale_arcsec_per_turn = 10.0;  // the axis's encoder scale error
    double cyclic_arcsec = 4.0;           // a cyclic error (a worm's) ...
    double cyclic_period_deg = 120.0;     // ... three times a turn
    double backlash_arcsec = 6.0;
    double noise_arcsec = 0.3;  // rms of the axis's position noise
    double zero_arcsec = -3.0;  // the reference reads this at the axis's 0 deg
    // The deviation (the reference's angle minus the target) of a stop at target_deg
    // approached from below (up) or above: the axis stops half the backlash short of its
    // target, the scale and cyclic errors at the angle it is driven to.
    double deviation_arcsec(double target_deg, cal::iso230_2::Direction d) const;
  } rotary;
};

// On an io_context with cal::drivers::VirtualTime installed (loop_time.hpp), the shop runs on
// that simulated time, which jumps from event to event: run_program and wait_until then take
// as long as the CPU needs, not the wall clock. Without it, simulated time follows the wall
// clock times `speed` (the live mode of `daq sim`).
class SimulatedShop {
 public:
  // `test`: the linear test the shop is set up for (kinds/kind.hpp): which axis the program
  // moves, where the other axes stand, and the simulated instruments it reads: the laser's
  // axis 0 on the test axis at the probe offset, angular runs' two beams at probe +- half the
  // separation, a simulated indicator (straightness) and a simulated electronic level (roll).
  SimulatedShop(boost::asio::io_context& io, ShopTruth truth, double speed,
                const cal::daq::LinearTestConfig& test = {});
  ~SimulatedShop();

  const ShopTruth& truth() const;
  double now_s() const;  // simulated time
  cal::drivers::Clock clock_ns() const;
  bool simulated_time() const;  // on the loop's VirtualTime (see above)
  std::uint16_t laser_port() const;
  const std::string& air_device() const;
  const std::string& material_device() const;
  const std::string& ballbar_device() const;
  std::uint16_t position_port() const;  // MTConnect SHDR adapter: Xcom|Ycom|Zcom, commanded mm
  const std::string& indicator_device() const;  // SIMULATED straightness indicator (mm lines)
  const std::string& level_device() const;      // SIMULATED electronic level (urad lines)
  // SIMULATED angular reference of a rotary test: "?" answered with the angle in arcsec, 0 ..
  // 1296000 (ShopTruth::Rotary).
  const std::string& angle_device() const;
  // The controller's compensation (um added to the command), e.g. from a model: see
  // cal::drivers::sim::MachineConfig::compensation_um. Set before a program is loaded.
  void set_compensation(std::function<cal::kinematics::Vec3(const cal::kinematics::Vec3&)> f);
  // The shop set up for another linear test (the constructor's `test`): the laser's optics on
  // its axis and at its probe offset (an angular test's two beams), the indicator and the level
  // read at its probe, the other axes at its stationary positions. `daq serve --simulate` sets
  // it at each linear Start, as the operator sets up the instruments for that test.
  void set_test(const cal::daq::LinearTestConfig& test);
  // The [devices.*] tables (TOML, docs/config.md) of the shop's twins: laser, air, material,
  // ballbar and, with position_feed, the SHDR position feed. `daq sim` writes them; the demo
  // reads them, so the twins the shop starts are named here only.
  // every_probe: both probes (the indicator and the level) whatever the shop's test, for a
  // service that runs any test kind (`daq serve --simulate`).
  std::string devices_toml(double laser_poll_s, bool position_feed, bool serial_numbers = false,
                           bool every_probe = false) const;

  // A linear run's laser, air station and (o.material) material thermometer on this shop's
  // twins, each under its role's device number, polled on the shop's clock (the air and the
  // material once a simulated second).
  void connect_linear(LinearRunSetup& setup, const ShopInstruments& o = {}) const;

  // The machine program for an ISO 230-2 plan on the test's axis (the other axes at their
  // stationary positions): every move at the feed, a dwell at each measure move.
  void run_linear(const cal::iso230_2::Plan& plan, double feed_mm_per_min, double dwell_s);
  // The ballbar program in XY about the pivot: start feed_in_mm outside the radius at 0 deg,
  // move in, dwell, ccw arc of 360 + 2 overshoot, dwell, cw arc back, move out.
  void run_circle(const cal::daq::BallbarProgram& p);
  // The ballbar set about the pivot (cal::daq::circle_set_program's moves: each test's feed-in,
  // dwell, ccw and cw arcs and feed-out, and between tests the arcs on the sphere of
  // R + feed-in). One radius only (a bar change needs an operator). Throws cal::InputError.
  void run_circle_set(std::span<const cal::daq::BallbarSetTest> tests);
  double program_end_s() const;  // simulated time at which the loaded program ends
  // Runs the event loop until `done()` or until simulated time passes the program's end plus
  // `margin_wall_s` seconds of wall time (times the speed). Bounded by simulated, not wall,
  // time: a starved process slows the shop's clock down, so a wall-clock limit would cut the
  // program short on a loaded machine. `each` runs after every slice (e.g. to flush a capture).
  // Returns done().
  bool run_program(const std::function<bool()>& done, double margin_wall_s,
                   const std::function<void()>& each = {});
  // Runs the event loop until `ready()` (e.g. every instrument has read once) or wall_s of
  // wall time pass; returns ready(). Start a program only then, as an operator would: the
  // first approach move of a program started while the laser still connects goes unseen,
  // and its first stop cannot be captured.
  bool wait_until(const std::function<bool()>& ready, double wall_s = 10.0);
  // The truth of a plan: the noise-free deviations at its stops, for the same evaluation.
  std::vector<cal::iso230_2::Measurement> true_measurements(const cal::iso230_2::Plan& p) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The configuration (TOML) of the shop's devices and tests, for an acquiring process:
// - in_process false (`daq sim`, another process): that process measures on its own wall
//   clock and sees the program `speed` times faster than the program's own times, so the
//   trigger's dwell and the laser's poll period are divided by the speed;
// - in_process true (`daq serve --simulate`): its instruments read the shop's clock, every
//   time in the file is simulated time (poll periods too: the service runs on a paced
//   VirtualTime, whose timers wait in simulated time), so the file reads as it would for a
//   real machine. The air is opened as 8N1: a
//   pseudo-terminal refuses to have 7E1 applied a second time (EINVAL), and the service opens
//   each device again for every run (a real PTU300 port is 4800 7E1).
// Both carry the machine specification of `daq demo` ([tolerances.X], [tolerances.XY]), so
// the results show verdicts.
struct ShopConfigOptions {
  double speed = 1.0;
  bool position_feed = false;  // the MTConnect SHDR feed of the commanded position
  bool in_process = false;
  // The linear program's size: a short one (e.g. 2 runs over 3 targets) tries the wiring in
  // seconds; the full ISO 230-2 program (5 runs over 11 targets, 50 mm apart) takes minutes.
  int runs = 5;
  int targets = 11;
  bool circle_set = false;  // [test.circle] is the standard set (daq sim --test circle-set)
  // [test.linear] is the rotary test of the shop's axis (daq sim --test rotary): 0 .. 360 deg
  // every 45 deg, `runs` runs, read by the angular reference (role "angle").
  bool rotary = false;
  // The single circle's feed: 1000 mm/min; a faster one is a shorter live run (fewer samples).
  double circle_feed_mm_per_min = 1000;
};
std::string simulated_shop_config(const SimulatedShop& shop, const ShopConfigOptions& o);

}  // namespace daq
