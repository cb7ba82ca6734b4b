// daq model kinematics: a model's rotary axes (their fitted average lines) written as a
// control's kinematic description: LinuxCNC's trunnion modules (xyzac-trt-kins,
// xyzbc-trt-kins: cal/analysis/trt_kins.hpp) or a SINUMERIK CYCLE800 swivel data record
// (kinematics type P: cal/analysis/swivel_data.hpp). HEIDENHAIN is refused with what the public
// text lacks. The semantics and the sources in docs/kinematics.md.
#include <fmt/format.h>

#include "cal/analysis/error.hpp"
#include "cal/analysis/swivel_data.hpp"
#include "cal/analysis/trt_kins.hpp"
#include "cli_checks.hpp"
#include "command.hpp"
#include "model_cli.hpp"
#include "output_file.hpp"

namespace daq {

namespace {

struct Options {
  std::string file, format = "linuxcnc-trt", output, db;
  int record = 1;
  bool reverse_angles = false;
};

// The control's file and what to say on stderr, for the chosen format.
struct Written {
  std::string text, what;
  std::vector<std::string> notes;
};

Written linuxcnc(const kin::FiveAxisMachine& m, const std::string& origin) {
  const kin::TrtPins pins = kin::linuxcnc_trt_pins(m);
  Written w{kin::linuxcnc_trt_hal(pins, origin), "HAL file", {}};
  for (const auto& n : pins.not_represented)
    w.notes.push_back(fmt::format("not represented by {} (left uncorrected): {}", pins.module, n));
  return w;
}

Written sinumerik(const kin::FiveAxisMachine& m, const std::string& origin, const Options& o) {
  const auto record =
      kin::sinumerik_swivel_record(m, {.number = o.record, .reverse_angles = o.reverse_angles});
  return {kin::sinumerik_swivel_program(record, origin), "swivel data", {}};
}

void run(const Options& given) {
  if (given.format == "heidenhain")
    throw cal::InputError(std::string(kin::heidenhain_not_written_reason()));
  if (given.format != "sinumerik-cycle800" && (given.record != 1 || given.reverse_angles))
    throw cal::InputError("--record and --reverse-angles are for -f sinumerik-cycle800");
  const auto in = read_model_input(given.file, given.db);
  Options o = given;
  o.file = in.label;  // the file, or the stored model: what the output names
  const mdl::Model& m = in.model;
  const std::string origin = model_origin(m);
  const std::string from = fmt::format(
      "from the model {}{}", o.file, origin.empty() ? "" : " (" + origin + ": not a real machine)");
  Written w;
  try {
    const kin::FiveAxisMachine machine = mdl::five_axis(m);
    w = o.format == "sinumerik-cycle800" ? sinumerik(machine, from, o) : linuxcnc(machine, from);
  } catch (const cal::InputError& e) {
    throw cal::InputError(fmt::format("{}: rotary: {}", o.file, e.what()));
  }
  for (const auto& n : w.notes) fmt::print(stderr, "{}\n", n);
  if (o.output.empty()) return fmt::print("{}", w.text);
  write_output_file(o.output, w.text, w.what);
  fmt::print(stderr, "written {}\n", o.output);
}

}  // namespace

void add_model_kinematics_command(CLI::App& model) {
  const auto [cmd, o] = add_command<Options>(
      model, "kinematics", run,
      "Write a model's rotary axes as a control's kinematics: LinuxCNC xyzac-trt-kins / "
      "xyzbc-trt-kins pivot pins (HAL setp lines) for a C table on an A or B cradle, or a "
      "SINUMERIK CYCLE800 swivel data record ($TC_CARR, kinematics type P) for one or two table "
      "axes; HEIDENHAIN is refused (the public text does not state the values' meaning)");
  cmd->add_option("file", o->file, "Model file with rotary axes (caldaq.model.v2)")->required();
  add_model_db_option(*cmd, o->db);
  cmd->add_option("-f,--format", o->format,
                  "linuxcnc-trt (the module follows the model's axes), sinumerik-cycle800, or "
                  "heidenhain (refused, says why)")
      ->check(CLI::IsMember({"linuxcnc-trt", "sinumerik-cycle800", "heidenhain"}))
      ->capture_default_str();
  cmd->add_option("--record", o->record,
                  "sinumerik-cycle800: the swivel data record n of $TC_CARRk[n]")
      ->check(whole_in(1, 9999))
      ->capture_default_str();
  cmd->add_flag("--reverse-angles", o->reverse_angles,
                "sinumerik-cycle800: the machine's positive angle turns the table the other way "
                "than the model's (its own right-handed rotation about +X, +Y, +Z): V1, V2 "
                "negated");
  cmd->add_option("-o,--output", o->output, "Write the file here (default: standard output)");
}

}  // namespace daq
