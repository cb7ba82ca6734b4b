// daq model build --machine NAME: the machine's model (caldaq.model.v1) from its stored runs,
// the latest complete run of each component (docs/volumetric-walkthrough.md).
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "cal/analysis/error.hpp"
#include "command.hpp"
#include "database.hpp"
#include "model/model_build.hpp"
#include "model/model_file.hpp"
#include "model_cli.hpp"
#include "provenance.hpp"
#include "run_quality.hpp"
#include "stored_model.hpp"

namespace daq {

namespace kin = cal::kinematics;
namespace mdl = cal::daq::model;
using nlohmann::json;

namespace {

// Where the runs of a model came from (provenance.hpp): "" when every run was measured on real
// instruments, the label when all share one ("SIMULATED"), else "MIXED"; and each error whose
// run was not real, with its run's label. Stored in the model's provenance, so that the model,
// its map and its compensation say it whatever the machine is called.
struct ModelOrigin {
  std::string label;
  std::map<std::string, std::string> errors;  // E_XX -> "SIMULATED"
  std::size_t real = 0, other = 0;
};

ModelOrigin model_origin(const cal::storage::RunReader& store,
                         const std::vector<std::pair<std::string, std::vector<std::int64_t>>>& used,
                         const std::string& machine) {
  ModelOrigin o;
  std::map<std::int64_t, std::string> of_run;
  std::set<std::string> labels;
  for (const auto& [name, ids] : used) {
    std::string error_label;
    for (const auto id : ids) {
      if (!of_run.count(id)) {
        const auto run = store.run(id);
        of_run[id] = run ? run_origin(*run, store.instruments(id), machine).label() : "";
      }
      if (!of_run[id].empty()) error_label = of_run[id];
    }
    labels.insert(error_label);
    if (error_label.empty())
      ++o.real;
    else
      ++o.other, o.errors[name] = error_label;
  }
  if (o.other > 0) o.label = labels.size() == 1 ? *labels.begin() : "MIXED";
  return o;
}

struct BuildCliOptions {
  std::string machine, db, output;
  std::string topology;
  std::vector<double> tool_offset_mm;
  std::vector<std::int64_t> accept_suspect;  // suspect runs used knowingly (run_quality.hpp)
  bool allow_missing = false, json = false;
};

void run_build(const BuildCliOptions& o) {
  const auto reader = open_run_reader(o.db);  // either store (--db postgresql://...)
  const auto& store = *reader;
  const auto stored = stored_profiles(store, o.machine);
  std::vector<std::int64_t> used_runs;
  for (const auto& p : stored.profiles) used_runs.push_back(p.run_id);
  const auto accepted = refuse_suspect_runs(store, used_runs, o.accept_suspect, "daq model build");
  mdl::BuildOptions b{.machine = o.machine, .allow_missing = o.allow_missing};
  if (!o.topology.empty())
    b.topology = kin::topology_from_string(o.topology);
  else if (stored.topology)
    b.topology = *stored.topology;
  else
    throw cal::InputError(fmt::format(
        "machine '{}': its runs do not say the kinematic chain ([machine] topology in the "
        "configuration): give --topology",
        o.machine));
  b.tool_offset_mm = stored.tool_offset_mm;
  b.table_offset_mm = stored.table_offset_mm;
  if (!o.tool_offset_mm.empty())
    b.tool_offset_mm = {o.tool_offset_mm[0], o.tool_offset_mm[1], o.tool_offset_mm[2]};
  auto r = mdl::build(stored.profiles, b);
  const auto origin = model_origin(store, r.used, o.machine);
  {
    auto prov = json::parse(r.model.provenance.json);
    // the model says it was built from suspect runs, knowingly
    if (!accepted.empty()) prov["accepted_suspect_runs"] = accepted;
    if (!origin.label.empty()) prov["origin"] = origin.label, prov["origins"] = origin.errors;
    r.model.provenance.json = prov.dump();
  }
  mdl::write(r.model, o.output);
  if (o.json) {
    json used = json::object();
    for (const auto& [name, ids] : r.used) used[name] = ids;
    fmt::print("{}\n", json{{"schema", "caldaq.model-build.v1"},
                            {"machine", o.machine},
                            {"topology", kin::to_string(b.topology)},
                            {"file", o.output},
                            {"used", used},
                            {"missing", r.missing},
                            {"skipped", stored.skipped},
                            {"accepted_suspect_runs", accepted},
                            {"origin", origin.label},
                            {"origins", origin.errors},
                            {"notes", r.notes}}
                           .dump(2));
    return;
  }
  fmt::print("Model of '{}' ({}) written to {}\n", o.machine, describe_topology(b.topology),
             o.output);
  fmt::print("From the latest complete run of each component:\n");
  for (const auto& [name, ids] : r.used)
    fmt::print("  {:6} run{} {}\n", name, ids.size() > 1 ? "s" : "", fmt::join(ids, ", "));
  if (!r.missing.empty())
    fmt::print("Missing, taken as zero (--allow-missing): {}\n", fmt::join(r.missing, ", "));
  for (const auto& s : stored.skipped) fmt::print("  not used: {}\n", s);
  for (const auto id : accepted)
    fmt::print(
        "  SUSPECT run {} used as told (--accept-suspect; recorded in the model's "
        "provenance): {}\n",
        id, run_quality(store, id).summary);
  for (const auto& n : r.notes) fmt::print("  note: {}\n", n);
  if (origin.label == "MIXED") {
    std::vector<std::string> parts;
    for (const auto& [name, label] : origin.errors) parts.push_back(name + " " + label);
    fmt::print("MIXED: {} of the 21 errors come from runs not measured on real instruments: {}\n",
               origin.other, fmt::join(parts, ", "));
  } else if (!origin.label.empty()) {
    fmt::print(
        "{}: every run of this model was {} (stored with it): not a model of a real "
        "machine\n",
        origin.label,
        origin.label == "SIMULATED" ? "measured on simulated instruments" : "of that origin");
  }
}

}  // namespace

void add_model_build_command(CLI::App& model) {
  const auto [cmd, o] = add_command<BuildCliOptions>(
      model, "build", run_build,
      "Assemble the model from a machine's stored runs (the latest complete run of each of the "
      "21 errors); missing errors are refused unless --allow-missing");
  cmd->add_option("--machine", o->machine, "The machine's name ([machine] name)")->required();
  cmd->add_option("-o,--output", o->output, "The model file to write")->required();
  cmd->add_option("--topology", o->topology,
                  "The kinematic chain (e.g. YFXZ), when the runs do not say it");
  cmd->add_option("--tool-offset-mm", o->tool_offset_mm, "Tool tip from the tool reference point")
      ->expected(3);
  cmd->add_flag("--allow-missing", o->allow_missing,
                "Write a partial model: errors without a run are zero, and listed");
  cmd->add_option("--accept-suspect", o->accept_suspect,
                  "Use this suspect run anyway (repeatable; recorded in the model's provenance): "
                  "runs with a stop far outside their repeatability are refused otherwise")
      ->take_all();
  cmd->add_flag("--json", o->json, "Print caldaq.model-build.v1 JSON (runs used, missing)");
  add_read_db_option(*cmd, o->db);
}

}  // namespace daq
