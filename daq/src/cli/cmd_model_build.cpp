// daq model build --machine NAME: the machine's model (caldaq.model.v1) from its stored runs,
// the latest complete run of each component (docs/volumetric-walkthrough.md).
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cal/analysis/error.hpp"
#include "database.hpp"
#include "model/model_build.hpp"
#include "model/model_file.hpp"
#include "model_cli.hpp"
#include "run_quality.hpp"
#include "stored_model.hpp"

namespace daq {

namespace kin = cal::kinematics;
namespace mdl = cal::daq::model;
using nlohmann::json;

namespace {

struct BuildCliOptions {
  std::string machine, db, output;
  std::string topology;
  std::vector<double> tool_offset_mm;
  std::vector<std::int64_t> accept_suspect;  // suspect runs used knowingly (run_quality.hpp)
  bool allow_missing = false, json = false;
};

void run_build(const BuildCliOptions& o) {
  const auto store = open_database_read_only(o.db);
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
  if (!accepted.empty()) {  // the model says it was built from suspect runs, knowingly
    auto prov = json::parse(r.model.provenance.json);
    prov["accepted_suspect_runs"] = accepted;
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
}

}  // namespace

void add_model_build_command(CLI::App& model) {
  auto o = std::make_shared<BuildCliOptions>();
  auto* cmd = model.add_subcommand(
      "build",
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
  add_db_option(*cmd, o->db);
  cmd->callback([o] { run_build(*o); });
}

}  // namespace daq
