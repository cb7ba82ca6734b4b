#pragma once
// The one way caldaq writes a number in fixed notation, on every output: the terminal and the
// reports (daq::number_text), the model commands' tables, the controllers' compensation tables
// (comptable::fixed), the part programs (gcode.cpp), the LinuxCNC pins and the SINUMERIK swivel
// data. Issue 30 asks for one presentation; a controller table or a part program must never
// hold "nan", "inf" or a "-0.0000" (a controller or a reader could take the sign for a
// direction).
#include <string>
#include <string_view>

namespace cal {

// `v` with `decimals` places (>= 0), rounded half away from zero at the last place (2.5 to
// 0 places is "3", -0.00125 to 4 is "-0.0013", 0.0045 to 3 "0.005" though printf's "%.3f"
// writes the binary value's "0.004"), and never a negative zero: a value that rounds
// to zero is written "0.000". For a display only: a value that is not finite is written as
// "nan", "inf" or "-inf", never as a number.
std::string fixed_text(double v, int decimals);

// The value fixed_text writes, as a number: `v` rounded half away from zero at `decimals`
// places (0.0045 to 3 is 0.005). What a verdict compares with its limit, so that a value is
// judged as the reader sees it printed (daq's verdicts and the central store's fleet trends).
double fixed_value(double v, int decimals);

// The same for a value that goes into a controller table or a part program: a value that is
// not finite is refused with cal::InputError naming `role` ("the X axis's value at 100 mm"),
// "ROLE is nan: nothing non-finite goes into a controller table or a part program".
std::string control_text(double v, int decimals, std::string_view role);

}  // namespace cal
