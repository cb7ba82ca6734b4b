#pragma once
// The fitted axis average lines of a tilting rotary table written as LinuxCNC's trunnion
// kinematics modules expect them: xyzac-trt-kins (C on an A cradle) and xyzbc-trt-kins (C on a
// B cradle), whose HAL pins place the C axis at (x-rot-point, y-rot-point) and the cradle axis at
// (y-rot-point + y-offset, z-rot-point + z-offset + tool-offset) for A, (x-rot-point + x-offset,
// z-rot-point + z-offset + tool-offset) for B (LinuxCNC src/emc/kinematics/trtfuncs.c; quoted
// and discussed in docs/kinematics.md, "LinuxCNC trunnion kinematics"). Pure: no I/O.
#include <string>
#include <string_view>
#include <vector>

#include "cal/analysis/rotary.hpp"

namespace cal::kinematics {

struct TrtPins {
  std::string module;  // "xyzac-trt-kins" or "xyzbc-trt-kins"
  double x_rot_point_mm = 0.0, y_rot_point_mm = 0.0, z_rot_point_mm = 0.0;
  double x_offset_mm = 0.0, y_offset_mm = 0.0, z_offset_mm = 0.0;
  // The location errors the module has no pin for (the orientation errors: its axes are exactly
  // along Z and X or Y), with their values: "E_A0C 20 urad". They stay uncorrected.
  std::vector<std::string> not_represented;
};

// The pins from a machine whose rotary axes are {C table, A table} (xyzac) or {C table, B
// table} (xyzbc), in home coordinates (machine coordinates of the tool reference point with a
// zero-length tool: LinuxCNC adds the tool length from its tool-offset pin). z-rot-point is the
// C pivot's height (any point of the C line would do; the module uses it only as the origin of
// z-offset). Throws InputError for any other machine.
TrtPins linuxcnc_trt_pins(const FiveAxisMachine& machine);

// The HAL lines: a comment block with the source and what is not represented, then one
// `setp MODULE.PIN VALUE` per pin (values in mm, 6 decimals).
std::string linuxcnc_trt_hal(const TrtPins& pins, std::string_view origin_comment);

// The pins of such HAL lines read back (what a simulated control applies): `setp MODULE.PIN
// VALUE` lines of one module, '#' comments and blank lines; a pin not given is 0 (LinuxCNC's
// default). Throws InputError naming `where` and the line for anything else (another command,
// module or pin, a value that is not a finite number, a pin given twice).
TrtPins parse_linuxcnc_trt_hal(std::string_view text, std::string_view where);

// The control's machine with these pins: the model's chain and linear part, its rotary axes'
// nominal pivots moved onto the pins' lines, and no location or component errors (what the
// control believes). Throws InputError as linuxcnc_trt_pins, or when the pins' module is not
// the model's trunnion.
FiveAxisMachine trt_control_machine(const TrtPins& pins, const FiveAxisMachine& model);

}  // namespace cal::kinematics
