// LinuxCNC trunnion kinematics pins from the fitted axis lines (trt_kins.hpp).
#include "cal/analysis/trt_kins.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

#include "cal/analysis/error.hpp"
#include "cal/analysis/fixed_text.hpp"
#include "cal/analysis/text.hpp"

namespace cal::kinematics {

namespace {

constexpr double kMmPerUm = 1e-3;

// The actual line's point at the pivot's plane: pivot + position error.
Vec3 actual_point_mm(const RotaryAxis& r) {
  return {r.pivot_mm[0] + kMmPerUm * r.location_position_um[0],
          r.pivot_mm[1] + kMmPerUm * r.location_position_um[1],
          r.pivot_mm[2] + kMmPerUm * r.location_position_um[2]};
}

void orientation_not_represented(const RotaryAxis& r, std::vector<std::string>& out) {
  const auto names = location_error_names(r.letter);
  const std::size_t own = direction_index(r.letter);
  std::size_t n = 2;  // names[2], names[3]: the orientation errors
  for (std::size_t i = 0; i < 3; ++i) {
    if (i == own) continue;
    out.push_back(fmt::format("{} {:g} urad", names[n++], r.location_orientation_urad[i]));
  }
}

}  // namespace

TrtPins linuxcnc_trt_pins(const FiveAxisMachine& m) {
  const auto& r = m.rotary;
  if (r.size() != 2 || r[0].letter != RotaryLetter::c || r[0].side != Side::table ||
      r[1].side != Side::table || r[1].letter == RotaryLetter::c)
    throw InputError(
        "LinuxCNC's trunnion kinematics (xyzac-trt-kins, xyzbc-trt-kins) describe a C table on "
        "an A or B cradle: the model's rotary axes must be [C table, A table] or [C table, B "
        "table]");
  TrtPins p;
  const bool a = r[1].letter == RotaryLetter::a;
  p.module = a ? "xyzac-trt-kins" : "xyzbc-trt-kins";
  const Vec3 c_line = actual_point_mm(r[0]);
  const Vec3 tilt_line = actual_point_mm(r[1]);
  p.x_rot_point_mm = c_line[0];
  p.y_rot_point_mm = c_line[1];
  p.z_rot_point_mm = c_line[2];
  // The cradle's line relative to the C line's point: A at (y, z), B at (x, z).
  if (a)
    p.y_offset_mm = tilt_line[1] - c_line[1];
  else
    p.x_offset_mm = tilt_line[0] - c_line[0];
  p.z_offset_mm = tilt_line[2] - c_line[2];
  orientation_not_represented(r[0], p.not_represented);
  orientation_not_represented(r[1], p.not_represented);
  return p;
}

std::string linuxcnc_trt_hal(const TrtPins& p, std::string_view origin_comment) {
  std::string s = fmt::format(
      "# {}: the rotary axes' fitted average lines (caldaq, docs/kinematics.md).\n"
      "# Per LinuxCNC src/emc/kinematics/trtfuncs.c: the C axis at (x-rot-point, y-rot-point);\n"
      "# {}\n"
      "# tool-offset is LinuxCNC's tool length (net to motion.tooloffset.z), not set here.\n"
      "# If the configuration nets a pin to a signal, set the signal instead (sets SIGNAL "
      "VALUE).\n",
      p.module,
      p.module == "xyzac-trt-kins"
          ? "the A axis at (y-rot-point + y-offset, z-rot-point + z-offset + tool-offset)."
          : "the B axis at (x-rot-point + x-offset, z-rot-point + z-offset + tool-offset).");
  if (!origin_comment.empty()) s += fmt::format("# {}\n", origin_comment);
  if (!p.not_represented.empty()) {
    s += "# Not represented by this module (its axes are exactly along Z and X or Y), left "
         "uncorrected:";
    for (const auto& n : p.not_represented) s += " " + n + ";";
    s.back() = '\n';
  }
  const auto pin = [&](std::string_view name, double v) {
    s += fmt::format("setp {}.{} {}\n", p.module, name,
                     control_text(v, 6, fmt::format("the pin {}.{}", p.module, name)));
  };
  pin("x-rot-point", p.x_rot_point_mm);
  pin("y-rot-point", p.y_rot_point_mm);
  pin("z-rot-point", p.z_rot_point_mm);
  if (p.module == "xyzac-trt-kins")
    pin("y-offset", p.y_offset_mm);
  else
    pin("x-offset", p.x_offset_mm);
  pin("z-offset", p.z_offset_mm);
  return s;
}

TrtPins parse_linuxcnc_trt_hal(std::string_view hal, std::string_view where) {
  TrtPins p;
  std::vector<std::string> seen;
  std::size_t line_no = 0;
  while (!hal.empty()) {
    const auto eol = hal.find('\n');
    const std::string_view line = hal.substr(0, eol);
    hal = eol == std::string_view::npos ? std::string_view{} : hal.substr(eol + 1);
    ++line_no;
    const auto fail = [&](std::string_view what) {
      throw InputError(fmt::format("{}:{}: {}", where, line_no, what));
    };
    std::istringstream in{std::string(line)};
    std::string cmd, name, value, extra;
    in >> cmd;
    if (cmd.empty() || cmd[0] == '#') continue;
    if (cmd != "setp")
      fail(fmt::format("'{}': expected setp MODULE.PIN VALUE", text::terminal_safe(cmd)));
    in >> name >> value;
    if (value.empty() || (in >> extra && extra[0] != '#')) fail("expected setp MODULE.PIN VALUE");
    const auto dot = name.find('.');
    const std::string module = name.substr(0, dot);
    if (module != "xyzac-trt-kins" && module != "xyzbc-trt-kins")
      fail(
          fmt::format("'{}' is not xyzac-trt-kins or xyzbc-trt-kins", text::terminal_safe(module)));
    if (!p.module.empty() && module != p.module)
      fail(fmt::format("{} after {}: one module per file", module, p.module));
    p.module = module;
    const std::string pin = dot == std::string::npos ? "" : name.substr(dot + 1);
    double* slot = pin == "x-rot-point"   ? &p.x_rot_point_mm
                   : pin == "y-rot-point" ? &p.y_rot_point_mm
                   : pin == "z-rot-point" ? &p.z_rot_point_mm
                   : pin == "x-offset"    ? &p.x_offset_mm
                   : pin == "y-offset"    ? &p.y_offset_mm
                   : pin == "z-offset"    ? &p.z_offset_mm
                                          : nullptr;
    if (!slot)
      fail(
          fmt::format("'{}' is not a pivot pin (x-rot-point, y-rot-point, z-rot-point, x-offset, "
                      "y-offset, z-offset)",
                      text::terminal_safe(pin)));
    if (std::find(seen.begin(), seen.end(), pin) != seen.end()) fail(pin + " given twice");
    seen.push_back(pin);
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (end != value.c_str() + value.size() || !std::isfinite(v) || std::abs(v) > 1e5)
      fail(fmt::format("'{}' is not a value in mm", text::terminal_safe(value)));
    *slot = v;
  }
  if (p.module.empty())
    throw InputError(fmt::format("{}: no setp line of a trunnion module", where));
  return p;
}

FiveAxisMachine trt_control_machine(const TrtPins& pins, const FiveAxisMachine& model) {
  const TrtPins shape = linuxcnc_trt_pins(model);  // checks the chain
  if (shape.module != pins.module)
    throw InputError(
        fmt::format("the pins are {}'s, the model's trunnion is {}", pins.module, shape.module));
  FiveAxisMachine m = model;
  for (RotaryAxis& r : m.rotary) {
    r.location_position_um = {};
    r.location_orientation_urad = {};
    r.motion = {};
  }
  m.rotary[0].pivot_mm = {pins.x_rot_point_mm, pins.y_rot_point_mm, pins.z_rot_point_mm};
  Vec3& tilt = m.rotary[1].pivot_mm;  // its coordinate along its own direction stays
  if (pins.module == "xyzac-trt-kins")
    tilt[1] = pins.y_rot_point_mm + pins.y_offset_mm;
  else
    tilt[0] = pins.x_rot_point_mm + pins.x_offset_mm;
  tilt[2] = pins.z_rot_point_mm + pins.z_offset_mm;
  return m;
}

}  // namespace cal::kinematics
