// daq model kinematics: a model's rotary axes (their fitted average lines) written as a
// control's kinematic description. LinuxCNC's trunnion modules (xyzac-trt-kins,
// xyzbc-trt-kins: cal/analysis/trt_kins.hpp); the semantics and the source in
// docs/kinematics.md.
#include <fmt/format.h>

#include <fstream>

#include "cal/analysis/error.hpp"
#include "cal/analysis/trt_kins.hpp"
#include "command.hpp"
#include "model_cli.hpp"
#include "output_file.hpp"

namespace daq {

namespace {

struct Options {
  std::string file, format = "linuxcnc-trt", output;
};

void run(const Options& o) {
  const mdl::Model m = mdl::read(o.file);
  kin::TrtPins pins;
  try {
    pins = kin::linuxcnc_trt_pins(mdl::five_axis(m));
  } catch (const cal::InputError& e) {
    throw cal::InputError(fmt::format("{}: rotary: {}", o.file, e.what()));
  }
  const std::string origin = model_origin(m);
  const std::string hal = kin::linuxcnc_trt_hal(
      pins, fmt::format("from the model {}{}", o.file,
                        origin.empty() ? "" : " (" + origin + ": not a real machine)"));
  for (const auto& n : pins.not_represented)
    fmt::print(stderr, "not represented by {} (left uncorrected): {}\n", pins.module, n);
  if (o.output.empty()) return fmt::print("{}", hal);
  write_output_file(o.output, hal, "HAL file");
  fmt::print(stderr, "written {}\n", o.output);
}

}  // namespace

void add_model_kinematics_command(CLI::App& model) {
  const auto [cmd, o] = add_command<Options>(
      model, "kinematics", run,
      "Write a model's rotary axes as a control's kinematics: LinuxCNC xyzac-trt-kins / "
      "xyzbc-trt-kins pivot pins (HAL setp lines) for a C table on an A or B cradle");
  cmd->add_option("file", o->file, "Model file with rotary axes (caldaq.model.v2)")->required();
  cmd->add_option("-f,--format", o->format, "linuxcnc-trt (the module follows the model's axes)")
      ->check(CLI::IsMember({"linuxcnc-trt"}))
      ->capture_default_str();
  cmd->add_option("-o,--output", o->output, "Write the HAL lines here (default: standard output)");
}

}  // namespace daq
