#pragma once
// Reading a positioning table back from a controller file, as the control reads it: what the
// simulated shop's control loads (daq demo --control-table) so that the compensation loop is
// tested against a known truth, and an independent check that what a writer printed is what
// its Applied says. Parsed from the text alone (not from the writer's data).
#include <array>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cal/analysis/comp_table.hpp"
#include "cal/analysis/kinematics.hpp"

namespace cal::comptable {

// The correction (um, what the control adds to the position) at each point of a table file of
// `format` (siemens, linuxcnc, isg, heidenhain, fanuc, csv), with the vendor's meaning of the
// values (comp_meaning.hpp) unless `inverted` (a control that reads them with the other sign).
// Throws cal::InputError naming the line for text that is not such a table.
Applied read_applied(std::string_view format, std::string_view text, bool inverted = false);

// One table of a cross-axis file as its control applies it: what the control adds to the
// `output` axis (um) as a function of the `input` axis's position (linear between points, the
// end values held beyond them).
struct CrossTableApplied {
  std::string input, output;
  std::vector<double> position_mm, correction_um;
};
// What a cross-axis or volumetric compensation (its files) does on the control.
struct CrossApplied {
  std::vector<CrossTableApplied> tables;
  // isg-volumetric: the ISO 230-1 errors the control evaluates (tables over the file's grids),
  // their grids' ranges (positions are held within them), and the factor on the correction the
  // control derives (-1 for a control that reads the errors with the other sign).
  std::optional<kinematics::Machine> volumetric;
  std::array<std::array<double, 2>, 3> volumetric_range_mm{};
  double volumetric_factor = 1.0;
};
// The formats whose files read_cross_applied reads (docs/compensation-tables.md): csv (caldaq's
// cross CSV), siemens-cec, isg-cross (kw.crosscomp lists), linuxcnc-matrixkins (matrixkins.hal),
// isg-volumetric (the configuration list and the ISG CSV parameter file), heidenhain (the *.COM
// tables with the *.CMA assignment that names each one's input axis).
bool is_cross_format(std::string_view format);
// A file of a compensation: its name as the control knows it ("" for a one-file format; a
// HEIDENHAIN *.CMA names its *.COM tables, matched by the name without its directory, in any
// case) and its text.
struct CompFile {
  std::string name, text;
};
// The files of a compensation in `format`, read as its control reads them: with the vendor's
// meaning of the values (comp_meaning.hpp) unless `inverted`. `axis_numbers` maps the control's
// axis numbers (AXn, logical axis numbers) back to X, Y, Z. Files of the set that are not of the
// cross-axis function (an ISG leadscrew list beside the cross lists, LinuxCNC COMP_FILEs beside
// matrixkins.hal) are left out: they are positioning tables (read_applied). Throws
// cal::InputError naming the file and line for text that is not such a file.
CrossApplied read_cross_applied(std::string_view format, std::span<const std::string> files,
                                const std::map<std::string, int>& axis_numbers,
                                bool inverted = false);
// The same with the files' names (needed for heidenhain: its *.CMA assigns the *.COM by name).
CrossApplied read_cross_applied(std::string_view format, std::span<const CompFile> files,
                                const std::map<std::string, int>& axis_numbers,
                                bool inverted = false);
// The correction the control adds at the commanded position p (um, X Y Z).
kinematics::Vec3 cross_correction_um(const CrossApplied& a, const kinematics::Vec3& p_mm);
// The file with every compensation value multiplied by `factor` (-1: the other sign; 1/1000: a
// unit error undone), everything else as it was, in the format's own notation (no -0; a value
// made smaller gets the decimals the factor takes away, where the notation has decimals). For a
// file that is not of the cross-axis function (see above) the text is returned unchanged.
std::string scale_cross_values(std::string_view format, std::string_view text, double factor);
// The file with `add_um` more added by the control to `output` everywhere (a reference-point
// error undone): the values of the first table of that output axis moved by it, in the format's
// units and sign (siemens-cec, isg-cross, csv). Throws cal::InputError for a format that cannot
// hold a constant (matrixkins, volumetric: the error parameters) or a set with no table of
// `output` (say so; `with_table` tells whether this file had one).
std::string shift_cross_values(std::string_view format, std::string_view text,
                               const std::string& output, double add_um,
                               const std::map<std::string, int>& axis_numbers, bool& with_table);
// The files with the table of `output` over `input` acting at positions shifted by -shift_mm (a
// position shift undone: the control applied the table at the input axis's position minus
// shift_mm, so its positions move by -shift_mm): SINUMERIK CEC $AN_CEC_MIN/_MAX of that table,
// the ISG cross list's setpoints, the cross CSV's positions, HEIDENHAIN the AXISPOS of the *.COM
// of that input (its other columns share them and move too). Throws cal::InputError for a
// format without positions of one table (matrixkins: a line, where a shift is a constant;
// volumetric: the error parameters of the whole axis) or a set with no such table.
std::vector<CompFile> shift_cross_positions(std::string_view format,
                                            std::span<const CompFile> files,
                                            const std::string& input, const std::string& output,
                                            double shift_mm,
                                            const std::map<std::string, int>& axis_numbers);

}  // namespace cal::comptable
