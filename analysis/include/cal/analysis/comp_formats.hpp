#pragma once
// Controller formats for cross-axis and volumetric compensation, and positioning tables for
// FANUC and HEIDENHAIN (comp_table.hpp has the per-axis formats from runs). Each writer follows
// the public document named in its comment and in docs/compensation-tables.md, which also says
// what that document leaves open. Every writer validates what it writes: nothing non-finite,
// nothing outside the format's syntax or range; values in fixed notation (no exponents).
// Analysis does no I/O: writers return the text.
#include <map>
#include <span>
#include <string>
#include <vector>

#include "cal/analysis/comp_table.hpp"
#include "cal/analysis/kinematics.hpp"
#include "cal/analysis/volumetric_comp.hpp"

namespace cal::comptable {

// The correction of one axis (output) as a function of the position of another (input) on a
// regular grid; input == output is the axis's own (pitch) table. Correction = what the control
// adds to the output axis's position, in mm.
struct CrossAxisTable {
  std::string input = "X";
  std::string output = "Y";
  double start_mm = 0.0;
  double interval_mm = 10.0;
  std::vector<double> correction_mm;
  double position_mm(std::size_t i) const {
    return start_mm + interval_mm * static_cast<double>(i);
  }
  double end_mm() const { return position_mm(correction_mm.size() - 1); }
};

// Largest correction any writer accepts: a geometric error beyond it means wrong units.
inline constexpr double kMaxCorrectionMm = 5.0;

// Throws InputError naming the table for: an axis name that is not one letter A-Z, fewer than 2
// points, a non-finite or non-positive interval, a non-finite start, a non-finite value, or a
// value beyond kMaxCorrectionMm.
void validate(const CrossAxisTable& t);

// From the model's cross tables (um) to mm tables named X, Y, Z; tables whose values all round
// to zero at `resolution_mm` are left out when skip_zero.
std::vector<CrossAxisTable> from_model(const volcomp::CrossTables& t, double resolution_mm,
                                       bool skip_zero);
// The model's own-axis table of `axis` as a positioning Table (correction sign, mm, absolute,
// one table without backlash) for the per-axis formats.
Table own_axis_table(const volcomp::CrossTables& t, kinematics::Axis axis, double resolution_mm,
                     Sign sign = Sign::correction);
// A straightness run (deviation of `output` in um along `input`) as the correction table of
// `output` over the grid (interpolated; the slope kept unless remove_slope): the fix of
// `daq compensate --straightness`, which belongs in a cross-axis table, not in the input axis's
// own pitch table.
CrossAxisTable from_straightness(const std::string& input, const std::string& output,
                                 const Spec& grid, std::span<const double> position_mm,
                                 std::span<const double> deviation_um, bool remove_slope);

// caldaq's own CSV: "input,output,point,position_mm,correction_mm".
std::string write_cross_csv(std::span<const CrossAxisTable> tables);

// SINUMERIK 840D sl / 828D "sag compensation" (CEC, Siemens function manual Extended Functions,
// K3, interpolatory compensation): a part program %_N_NC_CEC_INI setting, per table t,
// $AN_CEC[t,N] (mm), $AN_CEC_INPUT_AXIS[t], $AN_CEC_OUTPUT_AXIS[t] (AXn), $AN_CEC_STEP[t],
// $AN_CEC_MIN[t], $AN_CEC_MAX[t], $AN_CEC_DIRECTION[t] = 0, $AN_CEC_MULT_BY_TABLE[t] = 0,
// $AN_CEC_IS_MODULO[t] = 0, ending in M17. axis_numbers maps axis names to the n of AXn.
std::string write_sinumerik_cec(std::span<const CrossAxisTable> tables,
                                const std::map<std::string, int>& axis_numbers,
                                int first_table = 0);

// Beckhoff TwinCAT CNC / ISG cross compensation list of the slave (output) axis: kopf.achs_nr,
// kopf.log_achs_name, kw.crosscomp.last_index, .master_ax_nr, .unit 1 (0.1 um), and per point
// kw.crosscomp.table[i].setpoint (master position) and .correction, both in 0.1 um
// (P-COMP-00001..00007, TF5200 axis compensation).
std::string write_isg_cross(const CrossAxisTable& t, int slave_axis_number, int master_axis_number);

// ISG volumetric compensation (TF5280, Volumetric Compensation): the configuration list
// (logical axis numbers of X, Y, Z, chain, workpiece_axes, file[0], file_format[0] ISG_CSV)
// and the ISG CSV parameter file: the location errors C0Y B0Z A0Z, then per axis the six
// component errors (EXX ... ECX) over its grid, in mm and rad with arguments in mm.
std::string write_isg_volumetric_list(kinematics::Topology t,
                                      const std::map<std::string, int>& axis_numbers,
                                      const std::string& csv_path);
std::string write_isg_volumetric_csv(const kinematics::Machine& m,
                                     const std::array<volcomp::AxisGrid, 3>& grid);

// HEIDENHAIN nonlinear axis error compensation: one *.COM table per input axis, the column
// AXISPOS (compensation points, mm) and one column per output axis that depends on it (the
// value for that axis at the point, mm). For a positioning table, the column of the axis and,
// with separate directions, BACKLASH (the values of the negative direction). What the public
// technical manual pages do not show (the file's header and end lines, an NR column) is not
// written: the text holds the header line of the columns and the rows.
std::string write_heidenhain_com(std::span<const CrossAxisTable> same_input);
std::string write_heidenhain_com(const Table& positioning);
// The *.CMA assignment of *.COM tables to their input axes (MANUALplus 620 technical manual p.
// 718: "[Axis in column from *.com] = F(Axis in column from *.cma, in which *.com is
// entered)"): the header line ACTIVE and a column per input axis, and one row, active (*),
// with each table's name in its input axis's column. The file's frame is not confirmed, as for
// the *.COM. Throws cal::InputError for an empty list or an axis name that is not one letter.
std::string write_heidenhain_cma(
    const std::vector<std::pair<std::string, std::string>>& input_and_com);

// FANUC stored pitch error compensation (parameters 3620-3624 of the Series 0i/16i/18i
// parameter manuals): the compensation points numbered from `first_point`, the reference
// position's point, the magnification, and per point the incremental value in detection units
// (what the point adds over the section ending at it, moving in the positive direction; zero at
// the farthest negative point). A listing of parameters and values for the pitch error
// compensation screen: the data file (tape) syntax was not found in public documentation.
struct FanucOptions {
  double reference_mm = 0.0;     // the reference position; must be a grid point
  int first_point = 0;           // number of the farthest point in the negative direction
  double detection_unit_um = 1;  // the axis's detection unit
  int magnification = 1;         // parameter 3623
  int max_step = 127;            // largest |value| per point accepted
};
std::string write_fanuc_pitch(const Table& t, const FanucOptions& o);
// What the FANUC table holds: the point of the reference position and, per point, the step in
// units of detection unit x magnification (what write_fanuc_pitch lists). The absolute
// correction is the steps summed from the reference position, so it is zero there: a constant
// in the correction at the reference position is not in the table (it stays in the residual).
struct FanucSteps {
  std::size_t reference_index = 0;
  double unit_um = 1.0;          // detection unit x magnification
  std::vector<long long> steps;  // steps[0] = 0 (the farthest negative point)
};
FanucSteps fanuc_steps(const Table& t, const FanucOptions& o);
// The correction the control applies at each grid point from those steps (um, both directions
// alike: the bidirectional option is not written). Between points linear: how FANUC spreads a
// step over its section is not in the pages read (at most one step per section).
Applied fanuc_applied(const Table& t, const FanucOptions& o);

// LinuxCNC matrixkins (HAL component, LinuxCNC 2.9+: X_joint = C_xx X + C_xy Y + C_xz Z, ...):
// setp lines for the squareness corrections on their carriers (E_C0Y by Y: C_xy = +E_C0Y;
// by X: C_yx = +E_C0Y; E_B0Z by Z: C_xz = -E_B0Z; by X: C_zx = -E_B0Z; E_A0Z by Z:
// C_yz = +E_A0Z; by Y: C_zy = +E_A0Z; radians), the diagonal 1.
std::string write_linuxcnc_matrixkins(const kinematics::Squareness& s,
                                      const volcomp::Carriers& carriers);

}  // namespace cal::comptable
