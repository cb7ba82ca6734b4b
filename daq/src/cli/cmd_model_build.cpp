// daq model build --machine NAME: the machine's model (caldaq.model.v1) from its stored runs,
// the latest complete run of each component (docs/volumetric-walkthrough.md).
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "cal/analysis/error.hpp"
#include "cal/storage/pg/sync.hpp"
#include "command.hpp"
#include "database.hpp"
#include "model/model_build.hpp"
#include "model/model_file.hpp"
#include "model_cli.hpp"
#include "model_from_runs.hpp"
#include "run_quality.hpp"
#include "terminal.hpp"

namespace daq {

namespace {

struct BuildCliOptions {
  std::string machine, db, output;
  std::string topology;
  std::vector<double> tool_offset_mm;
  std::vector<std::int64_t> accept_suspect;  // suspect runs used knowingly (run_quality.hpp)
  bool allow_missing = false, json = false, store = false;
};

void run_build(const BuildCliOptions& o) {
  if (o.output.empty() && !o.store)
    throw cal::InputError(
        "give -o FILE (write the model), --store (keep it in the store), or both");
  if (o.store && cal::storage::pg::is_postgresql_url(o.db))
    throw cal::InputError(
        "--store keeps the model in the local store, which it is built from: build it from the "
        "local store (daq sync --from brings a machine's runs), or write it (-o) and keep the "
        "file with daq model store");
  const auto reader = open_run_reader(o.db);  // either store (--db postgresql://...)
  const auto& store = *reader;
  ModelFromRunsOptions options{
      .machine = o.machine, .accept_suspect = o.accept_suspect, .allow_missing = o.allow_missing};
  if (!o.topology.empty()) options.topology = kin::topology_from_string(o.topology);
  if (!o.tool_offset_mm.empty())
    options.tool_offset_mm =
        kin::Vec3{o.tool_offset_mm[0], o.tool_offset_mm[1], o.tool_offset_mm[2]};
  const auto built = model_from_runs(store, options);
  const auto& r = built.report;
  const auto& stored = built.stored;
  const auto& accepted = built.accepted;
  const auto& origin = built.origin;
  if (!o.output.empty()) mdl::write(r.model, o.output);
  std::optional<cal::storage::ModelRecord> kept;
  if (o.store) kept = store_built_model(o.db, store, o.machine, r.model, r.used);
  if (o.json) {
    auto j = model_build_json(built, o.machine, o.output);
    if (kept)
      j["stored"] = {{"db", database_path(o.db).string()}, {"id", kept->id}, {"uuid", kept->uuid}};
    return fmt::print("{}\n", j.dump(2));
  }
  print_line("Model of '{}' ({}) {}", o.machine, describe_topology(built.topology),
             o.output.empty() ? std::string("built") : "written to " + o.output);
  if (kept)
    print_line("Kept in {} as model {}, {} (daq model map {} --db ...)",
               database_path(o.db).string(), kept->id, kept->uuid, kept->uuid);
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
        id, quality_text(run_quality(store, id)));
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
  cmd->add_option("-o,--output", o->output, "The model file to write (-o, --store or both)");
  cmd->add_flag("--store", o->store,
                "Keep the model in the local store (--db) with the runs it was built from (their "
                "UUIDs and versions), who and when, under a stable UUID: daq model list, daq sync "
                "and the model commands' --db read it");
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
