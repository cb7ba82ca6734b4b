#pragma once
// What the `daq model` subcommands share (cmd_model*.cpp): reading the model and describing it.
#include <CLI/CLI.hpp>
#include <map>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "cal/analysis/fixed_text.hpp"
#include "cal/storage/store.hpp"
#include "model/model_file.hpp"
#include "model/model_map.hpp"
#include "report/model_report.hpp"

namespace daq {

// The names every model command uses, for the kinematics library and the model file (a private
// header of the model commands only).
namespace kin = cal::kinematics;
namespace mdl = cal::daq::model;
using nlohmann::json;

// "YFXZ: workpiece <- Y <- F -> X -> Z -> tool (Y carries the workpiece; ...)".
std::string describe_topology(cal::kinematics::Topology t);
// One line per component for show and the report: name, form, values, source.
std::vector<std::vector<std::string>> describe_components(const cal::daq::model::Model& m,
                                                          bool html);
// The page of a model over a grid (facts and components filled in).
cal::daq::report::ModelPage model_page_of(const cal::daq::model::Model& m, const std::string& path,
                                          const cal::kinematics::Grid& g,
                                          cal::kinematics::Method method);
// A point or a vector as JSON [x, y, z].
nlohmann::json vec_json(const cal::kinematics::Vec3& v);
// A map's grid as JSON: min_mm, max_mm, count (the maps' "grid").
nlohmann::json grid_json(const cal::kinematics::Grid& g);
// Numbers in fixed notation, never "-0.000" (fixed_text.hpp).
using cal::fixed_text;

// Every value finite, or InputError (model_map.hpp).
using cal::daq::model::require_finite;

// Where the model's measurements came from, from its provenance ("origin", written by `daq
// model build` and `daq sim --truth-out`): "SIMULATED", "REPLAYED", "IMPORTED", "MIXED", ...;
// "" for real instruments or when the file does not say. Only capitals, commas and spaces are
// kept (it is printed into controller files).
std::string model_origin(const cal::daq::model::Model& m);
// A model built from runs of several origins: each error that came from runs not measured on
// real instruments, with their origin ("E_XX" -> "SIMULATED"; the provenance's "origins"),
// the names and labels reduced to letters, digits, '_' and capitals.
std::map<std::string, std::string> model_origin_parts(const cal::daq::model::Model& m);

// --method htm|first-order
cal::kinematics::Method method_from_string(const std::string& s);
// The method as a map prints it: "htm" or "first-order".
std::string method_name(cal::kinematics::Method method);
// What every map's JSON starts with (daq model map, with or without rotary axes):
// {"schema": SCHEMA, "model": FILE, "method": method_name(METHOD)}.
nlohmann::json map_json_head(std::string_view schema, const std::string& file,
                             cal::kinematics::Method method);

// daq model map of a model with rotary axes (cmd_model_rotary.cpp): the grid (the linear
// volume) times angle_count angles over each rotary axis's range, or the poses of a CSV
// (x_mm, y_mm, z_mm and one column per rotary axis: c_deg, a_deg, ...).
struct FiveAxisMapRequest {
  std::string file;    // the model's path, for the output
  std::string points;  // a CSV of poses, or "" for the grid
  cal::kinematics::Grid grid;
  std::size_t angle_count = 5;
  cal::kinematics::Method method = cal::kinematics::Method::htm;
  bool json = false;
};
void run_five_axis_map(const cal::daq::model::Model& m, const FiveAxisMapRequest& q);
// The CSV columns of a pose's angles, one per rotary axis in chain order: "c_deg", "a_deg", ...
std::vector<std::string> rotary_angle_columns(const cal::daq::model::Model& m);

// The model a command reads (cmd_model_store.cpp): a file, or with `db` given (--db) a model
// kept in that store, local or central, named by its UUID or its number there. `label` names it
// in the output: the file, or "model UUID" (the same from every store).
struct ModelInput {
  cal::daq::model::Model model;
  std::string label;
};
ModelInput read_model_input(const std::string& arg, const std::string& db);
// --db for a command that reads a model (the model argument then names a stored one). A command
// whose --db is where it writes a run (daq sim, daq model ballbar5x-run) reads stored models
// with --model-db (`writes_runs`), by default from its --db (model_db_of).
void add_model_db_option(CLI::App& cmd, std::string& db, bool writes_runs = false);
// The store such a command reads stored models from: --model-db, else its --db.
inline const std::string& model_db_of(const std::string& model_db, const std::string& db) {
  return model_db.empty() ? db : model_db;
}

// A simulated machine and its control (probe-sim, probe-poses-sim, ballbar5x-sim,
// ballbar5x-run): the truth's model, the control's (either a file or a stored model) and the
// store they may be kept in.
struct TruthControlOptions {
  std::string truth, control, model_db;
};
struct TruthControlHelp {
  std::string control;            // what --control holds
  bool control_required = false;  // else a missing --control has a meaning the help says
  bool writes_runs = false;       // the command's --db is where it writes (--model-db here)
};
void add_truth_control_options(CLI::App& cmd, TruthControlOptions& o, const TruthControlHelp& help);
// The two models read: `control` empty without --control. `db` is the command's --db when it
// writes runs (model_db_of).
struct TruthControl {
  ModelInput truth;
  std::optional<ModelInput> control;
};
TruthControl read_truth_control(const TruthControlOptions& o, const std::string& db = "");
// daq model build --store: keeps the model built in the local store at `db` for `machine`, with
// the runs it was built from (`used`: error -> run ids in `read_from`), their UUIDs and versions.
cal::storage::ModelRecord store_built_model(
    const std::string& db, const cal::storage::RunReader& read_from, const std::string& machine,
    const cal::daq::model::Model& m,
    std::span<const std::pair<std::string, std::vector<std::int64_t>>> used);
// daq model store | list (cmd_model_store.cpp).
void add_model_store_commands(CLI::App& model);

// daq model compensate / daq model testpiece (their own files).
void add_model_compensate_command(CLI::App& model);
void add_model_testpiece_command(CLI::App& model);
void add_model_build_command(CLI::App& model);
void add_model_compare_command(CLI::App& model);
// daq model probe | probe-sim (cmd_model_probe.cpp), daq model kinematics
// (cmd_model_kinematics.cpp): sphere probing of rotary axes and the controls' kinematics.
void add_model_probe_commands(CLI::App& model);
// A fitted axis line's four location errors into the model's axis, with their uncertainty and
// `source` (what was probed) in each.
void put_location_fit(cal::daq::model::RotaryEntry& r, const cal::kinematics::AxisLineFit& f,
                      const nlohmann::json& source);
// daq model probe-poses (cmd_model_probe_poses.cpp): several rotary axes fitted together to
// centres probed at poses that turn them at once.
void add_model_probe_poses_command(CLI::App& model);
void add_model_kinematics_command(CLI::App& model);
// daq model ballbar5x | ballbar5x-sim | ballbar5x-program (cmd_model_ballbar5x.cpp): the
// ballbar on a rotary table axis.
void add_model_ballbar5x_commands(CLI::App& model);

}  // namespace daq
