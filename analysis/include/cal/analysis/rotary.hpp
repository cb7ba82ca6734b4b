#pragma once
// Rotary axes on top of the 3-axis model of kinematics.hpp: up to two rotary axes (A, B or C)
// on the table side, the spindle side, or one on each, each with its four ISO 230-1 location
// errors (position and orientation of its axis average line) and its six component errors as
// functions of the angle; the tool tip's position and orientation error relative to the
// workpiece by the exact HTM product or its first-order expansion; and the fit of an axis
// average line to sphere centres probed at several angles of one table axis (the method of
// HEIDENHAIN KinematicsOpt and SINUMERIK CYCLE996), and of a head axis's line to the sphere
// centres a control reports as the head turns. Conventions, derivations and sources:
// docs/kinematics.md, section "Rotary axes".
//
// Units as in kinematics.hpp: mm for positions, um for translational errors, urad for angular
// errors; angles of the rotary axes in degrees.
//
// Coordinates. Every nominal point (pivots, the tool offset) is given in HOME coordinates:
// machine coordinates of the tool reference point (spindle gauge point), with all linear and
// rotary axes at 0; the workpiece frame coincides with them at home. A sphere centre probed at
// a table angle is given in the same coordinates: the linear axes' positions plus the tool
// offset, as a control reports the probed centre.
//
// Chain. FiveAxisMachine::rotary lists the rotary axes from the workpiece to the tool: table
// axes first (the first one carries the workpiece: for an A/C trunnion, C then A), then
// spindle axes (the last one carries the spindle: for a C/B fork head, C then B). Table axes
// sit between the workpiece and the workpiece-side linear axes; spindle axes between the
// tool-side linear axes and the tool.
//
// Angle. The commanded angle is the rotation of the axis's moving member relative to its
// carrier, right-handed about the positive X (A), Y (B) or Z (C) direction. For a table axis
// that is the table's own rotation (ISO 841's primed direction, opposite to the tool's
// rotation relative to the workpiece).
//
// Errors of a rotary axis, all of its moving member relative to its carrier, in the carrier's
// axes:
// - Location errors (constant): the axis average line passes through pivot + position (the
//   component along the axis's own direction must be 0: E_X0C and E_Y0C for C) and has the
//   direction R(orientation) * nominal direction (the component about the axis itself must be
//   0: E_A0C and E_B0C for C). The rotation is about that actual line, so at angle 0 the
//   location errors move nothing: they show only when the axis turns (the workpiece and the
//   tool are set up at the rotary zero).
// - Component errors (functions of the angle in DEGREES; ErrorFunction's argument is the
//   angle): translations ex_um, ey_um, ez_um (for C: E_XC, E_YC radial, E_ZC axial) and
//   rotations ea_urad, eb_urad, ec_urad (E_AC, E_BC tilt, E_CC angular positioning) of the
//   moving member, at the actual pivot, in the carrier's axes.
#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cal/analysis/kinematics.hpp"

namespace cal::kinematics {

enum class RotaryLetter { a, b, c };                         // about X, Y, Z
std::string_view to_string(RotaryLetter l);                  // "A", "B", "C"
RotaryLetter rotary_letter_from_string(std::string_view s);  // case-insensitive; throws InputError
// The index (0, 1, 2 = X, Y, Z) of the axis's nominal direction.
std::size_t direction_index(RotaryLetter l);
// The four location errors' ISO 230-1 names in the order position (two), orientation (two), by
// increasing direction index: C -> E_X0C, E_Y0C, E_A0C, E_B0C; A -> E_Y0A, E_Z0A, E_B0A,
// E_C0A; B -> E_X0B, E_Z0B, E_A0B, E_C0B.
std::array<std::string, 4> location_error_names(RotaryLetter l);

enum class Side { table, spindle };
std::string_view to_string(Side s);  // "table", "spindle"

struct RotaryAxis {
  RotaryLetter letter = RotaryLetter::c;
  Side side = Side::table;
  Vec3 pivot_mm{};                   // a point of the nominal axis line, home coordinates
  Vec3 location_position_um{};       // e.g. C: {E_X0C, E_Y0C, 0}
  Vec3 location_orientation_urad{};  // e.g. C: {E_A0C, E_B0C, 0}
  AxisErrors motion;                 // component errors; argument: the angle in degrees
};

struct FiveAxisMachine {
  // The linear axes, their 21 errors, topology and offsets as in the 3-axis model. Its
  // tool_offset_mm is the tool tip relative to the tool reference point with all rotary axes
  // at 0 (a spindle axis turns it).
  Machine linear;
  std::vector<RotaryAxis> rotary;  // 0, 1 or 2; chain order, table axes first
};

// The error of the tool tip relative to the workpiece, in the workpiece frame (which turns with
// the table axes): translation = actual minus nominal tip; rotation = rotation vector of
// R_actual * R_nominal^T (the tool's orientation error). angles_deg has one angle per rotary
// axis, in the order of machine.rotary. Throws InputError for a machine that breaks the rules
// above, a wrong number of angles, a non-finite input, or an angle outside an error table.
VolumetricError five_axis_error(const FiveAxisMachine& machine, const Vec3& linear_mm,
                                std::span<const double> angles_deg, Method method);

// The nominal tool tip in the workpiece frame, home coordinates (what the control believes).
Vec3 five_axis_nominal_tip_mm(const FiveAxisMachine& machine, const Vec3& linear_mm,
                              std::span<const double> angles_deg);

// The machine as a control's kinematics holds it: the same chain, pivots, location errors (the
// lines as the control believes them) and tool offset; no component error of a rotary axis and
// no linear-axis error (those are the machine's, not the control's kinematics).
FiveAxisMachine control_kinematics(const FiveAxisMachine& m);
// The control's nominal kinematics: control_kinematics with the location errors cleared too.
FiveAxisMachine nominal_kinematics(const FiveAxisMachine& m);

// The tool tip the control's kinematics (control_kinematics(control)) computes at the linear
// position linear_mm and these angles, in MACHINE coordinates: the table axes taken at 0
// (machine coordinates do not turn with the table), the spindle axes at their angles (the
// control turns the tool offset about its head axes). What a control reports as a probed point.
Vec3 control_tip_mm(const FiveAxisMachine& control, const Vec3& linear_mm,
                    std::span<const double> angles_deg);

// A simulated touch probe: the centre of a sphere fixed at sphere_mm on the workpiece (home
// coordinates) as `control` reports it when the ACTUAL `machine` probes it at these angles: the
// linear position p at which the actual tool tip is on the centre (the nominal tip is affine in
// p, so Newton's steps on it converge to 1e-12 mm in a few), and control_tip_mm(control, p). With
// the spindle axes at 0 this is p plus the tool offset, whatever the control (the location errors
// move nothing at 0); with a spindle axis turned it is where the control's kinematics puts the
// turned probe tip: the sphere less the actual tip's error relative to the control's belief.
// The two machines must have the same chain (letters and sides). Throws InputError as
// five_axis_error, and for chains that differ.
Vec3 probed_centre_mm(const FiveAxisMachine& machine, const FiveAxisMachine& control,
                      const Vec3& sphere_mm, std::span<const double> angles_deg);
// The same reported by a control holding the machine's nominal kinematics
// (nominal_kinematics(machine)).
Vec3 probed_centre_mm(const FiveAxisMachine& machine, const Vec3& sphere_mm,
                      std::span<const double> angles_deg);

// ---------------------------------------------------------------------------------------------
// Sphere probing: the axis average line of one TABLE axis from sphere centres probed at
// several of its angles (the other rotary axis at 0), fitted by least squares as a circle in
// 3-D about a line (its position at the nominal pivot's plane, its orientation), the radius
// and the height of the circle's plane.

struct ProbedCentre {
  double angle_deg = 0.0;
  Vec3 centre_mm{};  // home (machine) coordinates
};

struct AxisLineFit {
  RotaryLetter letter = RotaryLetter::c;
  // The location errors in the layout of RotaryAxis (the entries along / about the axis are 0)
  // and their standard uncertainties (NaN when they cannot be estimated: three angles and no
  // probing uncertainty given).
  Vec3 position_um{}, position_u_um{};
  Vec3 orientation_urad{}, orientation_u_urad{};
  double radius_mm = 0.0;        // of the circle the sphere centre described
  double plane_offset_mm = 0.0;  // of the circle's plane along the axis, from the pivot
  // Residuals per probed centre, in the input order: radial (outward from the line), axial
  // (along the fitted direction) and tangential (arc length, after removing the mean angular
  // offset between the fitted and the commanded angles): the axis's error motion as probed.
  std::vector<double> radial_um, axial_um, tangential_um;
  double rms_um = 0.0;    // RMS of the radial and axial residuals
  double sigma_um = 0.0;  // the point standard deviation used for the uncertainties
  int dof = 0;            // 2 N - 6: radial and axial residuals less the 6 parameters
};

// The linear axes' errors taken out of probed centres, before the fit: each centre plus the
// error of the tool tip relative to the workpiece that `linear` (the machine's measured linear
// axes: their 21 errors, topology and tool offset; no rotary axis) has at the linear position
// the centre was probed at (the centre minus the tool offset). Why plus: the probe touches the
// sphere where the ACTUAL tip is, nominal + error, and the control reports the nominal; so the
// sphere is at the reported centre + error. The table axes sit on the workpiece-side linear
// axes, so to first order in the errors the corrected centres are the ones a machine with
// perfect linear axes reports, and the fit sees the rotary axis alone. correction_um[k] is what
// was added to centre k. Throws InputError as volumetric_error (a position outside a table).
struct LinearCorrection {
  std::vector<ProbedCentre> centres;
  std::vector<Vec3> correction_um;
};
LinearCorrection remove_linear_errors(const Machine& linear, std::span<const ProbedCentre> centres);

// probe_u_um: the standard uncertainty of one probed centre per coordinate; 0 estimates it from
// the residuals (needs 4 or more centres). Throws InputError for fewer than 3 distinct angles,
// non-finite input, centres that are (nearly) collinear or coincident, a circle whose plane is
// not (nearly) perpendicular to the nominal direction, or a negative probe_u_um.
AxisLineFit fit_axis_line(RotaryLetter letter, const Vec3& nominal_pivot_mm,
                          std::span<const ProbedCentre> centres, double probe_u_um = 0.0);

// ---------------------------------------------------------------------------------------------
// Sphere probing of one SPINDLE (head) axis: the sphere fixed on the table, the probe carried
// by the head, probed at several angles of the head axis (every other rotary axis at 0). Each
// centre is what the control reports (control_tip_mm: the probe tip where the control's
// kinematics puts it, machine coordinates), so on a machine that matches the control every
// centre is the sphere's; the spread of the centres is the head's error as the tool turns:
// reported = S - (actual tip - control's tip). docs/kinematics.md, "Sphere probing of a head
// axis".
//
// Fitted by Gauss-Newton on the exact model (probed_centre_mm with the candidate machine): the
// sphere S (3 parameters) and the axis's four location errors, relative to its NOMINAL pivot
// (not to the control's belief: the control's own location errors only say how it computed the
// centres). 3 N residuals; u from sigma^2 (J^T J)^-1, sigma the probe's if given, else the
// residuals' sqrt(sum r^2 / (3 N - 7)).
//
// The tool offset must be right: an error of the probe tip across the axis moves the tip exactly
// as a position error of the line does (a tip that stands off by delta turns about the line like
// one whose line stands off by -delta), so the probe's length and offset must be calibrated, as
// for any head probing cycle. with_linear_errors: the machine's linear-axis errors (control's
// `linear`, e.g. a volumetric campaign's) are part of the fitted machine, so they are not read
// as the head's; false fits the centres as if the linear axes were perfect.
struct HeadAxisFit {
  // Location errors and uncertainties as for a table axis; radius_mm: the probe tip's distance
  // from the fitted line, plane_offset_mm: along the line from the pivot's plane; residuals: the
  // error motion at the probe tip (predicted minus reported: the actual tip's displacement),
  // radial (outward from the line), axial (along it), tangential (in the sense of rotation);
  // rms_um over the 3 N coordinates; dof = 3 N - 7.
  AxisLineFit line;
  Vec3 sphere_mm{}, sphere_u_um{};  // the sphere's centre on the workpiece, home coordinates
};
// Throws InputError for an index that is not a spindle axis, fewer than 3 distinct angles,
// non-finite input, centres spread more than 2 mm (not a control's computed tip: the linear
// axes' raw positions?), centres that cannot separate the line's position from its orientation
// (the probe tip on the axis line), a negative probe_u_um.
HeadAxisFit fit_head_axis_line(const FiveAxisMachine& control, std::size_t index,
                               std::span<const ProbedCentre> centres, double probe_u_um = 0.0,
                               bool with_linear_errors = true);

}  // namespace cal::kinematics
