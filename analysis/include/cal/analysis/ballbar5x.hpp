#pragma once
// The ballbar on a rotary TABLE axis in simultaneous motion: the axis turns, the linear axes
// follow so that the spindle ball keeps its place relative to the table ball (the bar is fixed
// in the workpiece frame), and the bar's length change at each angle is analysed into the
// axis's four location errors (E_X0C, E_Y0C, E_A0C, E_B0C for C) by least squares. Three
// set-ups of the bar relative to the axis: radial (along the line from the axis to the table
// ball), tangential (across it, perpendicular to the axis) and axial (along the axis).
//
// The method is that of M. Tsutsumi, A. Saito, IJMTM 43(8) (2003) 771-780 (a ballbar on a
// tilting rotary table, the table turning while the linear axes follow, several set-ups) and
// K.-I. Lee, S.-H. Yang, IJMTM 70 (2013) 45-52; only their abstracts were public to us: the
// set-ups, the sensitivities and the fit here are derived in docs/kinematics.md ("The ballbar
// on a rotary axis"), not copied. Units and conventions as in rotary.hpp.
#include <array>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cal/analysis/rotary.hpp"

namespace cal::kinematics {

enum class BarSetup { radial, tangential, axial };
std::string_view to_string(BarSetup s);              // "radial", "tangential", "axial"
BarSetup bar_setup_from_string(std::string_view s);  // throws InputError

// One ballbar test on one table axis; every other rotary axis stays at 0.
struct RotaryBallbarTest {
  std::string name;  // e.g. "C-radial"; names the test in messages and files
  RotaryLetter axis = RotaryLetter::c;
  BarSetup setup = BarSetup::radial;
  Vec3 table_ball_mm{};  // the table ball's centre on the workpiece, home coordinates
  double length_mm = 100.0;
  std::vector<double> angles_deg;  // the angles at which the bar is read
};

// The bar's direction, a unit vector fixed in the workpiece frame (from the table ball to the
// spindle ball): radial = the table ball's offset from the nominal axis line, normalised;
// tangential = d x radial (d the axis's direction); axial = d. Throws InputError for a radial or
// tangential set-up whose table ball is within 1 mm of the axis line, a spindle axis, an axis
// the machine has not, a non-finite ball or a length outside (0, 2000] mm.
Vec3 bar_direction(const FiveAxisMachine& m, const RotaryBallbarTest& t);

// The spindle ball's centre in the workpiece frame: table ball + length x direction.
Vec3 tool_ball_mm(const FiveAxisMachine& m, const RotaryBallbarTest& t);

// What the part program commands at an angle: the machine coordinates of the spindle ball (the
// linear axes' positions plus the tool offset, the tool tip being the ball) at which the
// CONTROL's model (`control`, with whatever location errors it holds) puts the ball on its
// place in the workpiece frame.
Vec3 rotary_ballbar_command_mm(const FiveAxisMachine& control, const RotaryBallbarTest& t,
                               double angle_deg);

// The bar's readings (actual length minus the nominal, um) at each angle of t when the machine
// `truth` runs the program the control computed: exact (HTM), no noise.
std::vector<double> rotary_ballbar_readings_um(const FiveAxisMachine& truth,
                                               const FiveAxisMachine& control,
                                               const RotaryBallbarTest& t);

// The first-order sensitivity of the reading at each angle of t to the four location errors of
// t's axis, in the order of location_error_names (um/um, then um/urad):
//   reading = u . [(I - R^T) o + ((I - R^T) e0) x v],
// u the bar's direction, R the turn about the nominal direction, o and e0 the position and
// orientation errors, v the spindle ball relative to the pivot (docs/kinematics.md).
std::vector<std::array<double, 4>> rotary_ballbar_sensitivity(const FiveAxisMachine& m,
                                                              const RotaryBallbarTest& t);

// A test with its readings (one per angle, um).
struct RotaryBallbarRun {
  RotaryBallbarTest test;
  std::vector<double> reading_um;
};

struct RotaryBallbarFit {
  RotaryLetter axis = RotaryLetter::c;
  // The axis's location errors in the order of location_error_names and their standard
  // uncertainties (um, urad).
  std::array<double, 4> value{}, uncertainty{};
  // Per run: the constant the bar read besides the location errors (its length calibration and
  // the balls' set-up), with its uncertainty; the residual at each angle.
  std::vector<double> offset_um, offset_u_um;
  std::vector<std::vector<double>> residual_um;
  double rms_um = 0.0;    // of all residuals
  double sigma_um = 0.0;  // the reading's standard deviation used for the uncertainties
  int dof = 0;            // readings less parameters (4 + one offset per run)
};

// Least squares: the four location errors of `axis` and one offset per run, the readings
// predicted by rotary_ballbar_readings_um for `control` with the axis's location errors
// replaced by the unknowns (Gauss-Newton on the first-order sensitivities, exact at the
// end). reading_u_um: the standard uncertainty of one reading; 0 estimates it from the
// residuals (then the readings must outnumber the parameters). Throws InputError for runs of
// another axis or none, a run whose readings do not match its angles, non-finite readings, or
// set-ups that cannot separate the four errors (e.g. radial tests at one height only).
RotaryBallbarFit fit_rotary_ballbar(const FiveAxisMachine& control, RotaryLetter axis,
                                    std::span<const RotaryBallbarRun> runs,
                                    double reading_u_um = 0.0);

// The machine `m` with the location errors of `axis` set to `value` (location_error_names'
// order): what a fit puts into the control's model.
FiveAxisMachine with_location_errors(const FiveAxisMachine& m, RotaryLetter axis,
                                     const std::array<double, 4>& value);

}  // namespace cal::kinematics
