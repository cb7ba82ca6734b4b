// Models kept in a store (issue 35; docs/storage.md, "Models"): daq model store FILE, daq model
// list, daq model build --store, and the model argument of every model command that reads one
// (a file, or with --db a stored model by its UUID or number, from either store).
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cal/analysis/error.hpp"
#include "cal/analysis/text.hpp"
#include "command.hpp"
#include "database.hpp"
#include "model_cli.hpp"
#include "provenance.hpp"
#include "terminal.hpp"

namespace daq {

namespace st = cal::storage;

namespace {

bool all_digits(std::string_view s) {
  return !s.empty() && s.size() < 19 &&
         std::all_of(s.begin(), s.end(), [](unsigned char c) { return std::isdigit(c) != 0; });
}

// The stored model `ref` names (its UUID, or its number in that store), or InputError.
st::ModelRecord find_stored_model(const st::RunReader& store, const std::string& ref) {
  std::optional<st::ModelRecord> found;
  if (st::is_uuid(ref))
    found = store.model_by_uuid(ref);
  else if (all_digits(ref))
    found = store.model(std::stoll(ref));
  else
    throw cal::InputError(fmt::format(
        "--db: '{}': a stored model is named by its UUID or its number in the store (daq model "
        "list --db ... lists them)",
        cal::text::terminal_safe(ref)));
  if (!found)
    throw cal::InputError(fmt::format("{}: no model {} (daq model list --db ... lists them)",
                                      store.name(), cal::text::terminal_safe(ref)));
  return *found;
}

}  // namespace

ModelInput read_model_input(const std::string& arg, const std::string& db) {
  std::error_code ec;
  // A file of that name is the file (daq model compensate's --db is also where --machine stores
  // the table it writes).
  if (db.empty() || std::filesystem::exists(arg, ec)) {
    if (db.empty() && st::is_uuid(arg) && !std::filesystem::exists(arg, ec))
      throw cal::InputError(
          fmt::format("{}: no such file; a model kept in a store is read with --db STORE (daq "
                      "model list --db STORE lists them)",
                      arg));
    return {mdl::read(arg), arg};
  }
  const auto store = open_run_reader(db);
  const auto record = find_stored_model(*store, arg);
  // Named by its UUID, which is the same in every store: the output is the same from each.
  const auto label = "model " + record.uuid;
  return {mdl::parse(record.json, label), label};
}

void add_model_db_option(CLI::App& cmd, std::string& db, bool writes_runs) {
  if (writes_runs) {
    cmd.add_option("--model-db", db,
                   "Read the models from this store when a model argument is not a file: its "
                   "UUID or its number there (daq model list); a SQLite file or the central "
                   "store, postgresql://... (default: --db; docs/storage.md, \"Models\")");
    return;
  }
  cmd.add_option("--db", db,
                 "Read the model from this store when the model argument is not a file: its UUID "
                 "or its number there (daq model list); a SQLite file or the central store, "
                 "postgresql://... (docs/storage.md, \"Models\")");
}

void add_truth_control_options(CLI::App& cmd, TruthControlOptions& o,
                               const TruthControlHelp& help) {
  cmd.add_option("truth", o.truth,
                 "Model of the simulated machine (its truth): a file, or a stored model's UUID or "
                 "number with " +
                     std::string(help.writes_runs ? "--model-db" : "--db"))
      ->required();
  auto* control = cmd.add_option("--control", o.control, help.control);
  if (help.control_required) control->required();
  add_model_db_option(cmd, o.model_db, help.writes_runs);
}

TruthControl read_truth_control(const TruthControlOptions& o, const std::string& db) {
  const auto& from = model_db_of(o.model_db, db);
  TruthControl out{read_model_input(o.truth, from), std::nullopt};
  if (!o.control.empty()) out.control = read_model_input(o.control, from);
  return out;
}

namespace {

// caldaq.model-provenance.v1: how a model came into the store (`how`), with what the caller adds.
nlohmann::json model_provenance(std::string_view how) {
  return {{"schema", "caldaq.model-provenance.v1"},
          {"how", how},
          {"software", "daq 0.1.0"},
          {"stored_utc", utc_now_iso()}};
}

// Keeps `m` in the local store at `db` for its machine (which must be there); returns the record.
st::ModelRecord keep_model(const std::string& db, const std::string& machine, const mdl::Model& m,
                           const nlohmann::json& provenance) {
  const auto path = database_path(db);
  if (std::error_code ec; !std::filesystem::exists(path, ec))
    throw cal::InputError(
        fmt::format("{}: no such database (see --db): a model is kept beside its machine's runs",
                    path.string()));
  st::Store store(path);
  const auto there = store.machine_by_name(machine);
  if (!there)
    throw cal::InputError(fmt::format("{}: no machine '{}' (see daq runs; --machine)", store.name(),
                                      cal::text::terminal_safe(machine)));
  const auto id = store.add_model({.machine_id = there->id,
                                   .name = m.name,
                                   .json = mdl::to_json(m),
                                   .provenance_json = provenance.dump(),
                                   .stored_by = user_name(),
                                   .stored_from = host_name()});
  return *store.model(id);
}

void print_kept(const st::ModelRecord& r, const std::string& db) {
  print_line("Kept in {} as model {}, {} (daq model map {} --db ...)", database_path(db).string(),
             r.id, r.uuid, r.uuid);
}

}  // namespace

namespace {

// The runs of a model built (`used`: error -> run ids), each once with the errors it gave.
nlohmann::json built_model_runs(
    const st::RunReader& store,
    std::span<const std::pair<std::string, std::vector<std::int64_t>>> used) {
  std::map<std::int64_t, std::vector<std::string>> errors_of;  // run -> the errors it gave
  for (const auto& [name, ids] : used)
    for (const auto id : ids) errors_of[id].push_back(name);
  auto runs = nlohmann::json::array();
  for (const auto& [id, errors] : errors_of) {
    const auto r = store.run(id);
    if (!r) continue;
    // The version of its stops read: the central store's current one; a local store keeps one
    // version of a run (null: the stops as that store has them).
    nlohmann::json version = nullptr;
    for (const auto& v : store.versions(id))
      if (v.current) version = v.version;
    runs.push_back({{"id", id},
                    {"uuid", r->uuid},
                    {"kind", r->kind},
                    {"axis", r->axis},
                    {"started_utc", utc_iso(r->started_unix_ms)},
                    {"version", version},
                    {"errors", errors}});
  }
  return runs;
}

}  // namespace

st::ModelRecord store_built_model(
    const std::string& db, const st::RunReader& read_from, const std::string& machine,
    const mdl::Model& m, std::span<const std::pair<std::string, std::vector<std::int64_t>>> used) {
  auto provenance = model_provenance("daq model build");
  provenance["built_from"] = read_from.name();
  provenance["runs"] = built_model_runs(read_from, used);
  return keep_model(db, machine, m, provenance);
}

namespace {

struct StoreModelOptions {
  std::string file, machine, db;
};

void run_store(const StoreModelOptions& o) {
  const auto m = mdl::read(o.file);
  auto provenance = model_provenance("daq model store");
  provenance["file"] = std::filesystem::absolute(o.file).string();
  print_kept(keep_model(o.db, o.machine.empty() ? m.name : o.machine, m, provenance), o.db);
}

struct ListOptions {
  std::string db, machine;
  bool json = false;
};

nlohmann::json model_json(const st::ModelRecord& r, const std::string& machine) {
  auto provenance = nlohmann::json::parse(r.provenance_json, nullptr, false);
  if (provenance.is_discarded()) provenance = r.provenance_json;  // kept as it was stored
  return {{"id", r.id},
          {"uuid", r.uuid},
          {"machine", machine},
          {"name", r.name},
          {"stored_by", r.stored_by},
          {"stored_from", r.stored_from},
          {"stored_utc", utc_iso(r.stored_unix_ms)},
          {"provenance", provenance}};
}

void run_list(const ListOptions& o) {
  const auto store = open_run_reader(o.db);
  std::int64_t machine_id = 0;
  if (!o.machine.empty()) {
    const auto m = store->machine_by_name(o.machine);
    if (!m)
      throw cal::InputError(
          fmt::format("{}: no machine '{}'", store->name(), cal::text::terminal_safe(o.machine)));
    machine_id = m->id;
  }
  const auto models = store->models(machine_id);
  std::map<std::int64_t, std::string> names;  // machine id -> name
  for (const auto& r : models)
    if (!names.contains(r.machine_id)) {
      const auto m = store->machine(r.machine_id);
      names[r.machine_id] = m ? m->name : "?";
    }
  if (o.json) {
    auto list = nlohmann::json::array();
    for (const auto& r : models) list.push_back(model_json(r, names[r.machine_id]));
    return fmt::print(
        "{}\n",
        nlohmann::json{{"schema", "caldaq.model-list.v1"}, {"db", store->name()}, {"models", list}}
            .dump(2));
  }
  print_line("{}: {} model{}", store->name(), models.size(), models.size() == 1 ? "" : "s");
  for (const auto& r : models) {
    const auto provenance = nlohmann::json::parse(r.provenance_json, nullptr, false);
    std::size_t runs = 0;
    std::string how;
    if (provenance.is_object()) {
      how = provenance.value("how", "");
      if (provenance.contains("runs") && provenance["runs"].is_array())
        runs = provenance["runs"].size();
    }
    print_line("{:>4}  {}  {}  '{}'  {} by {} on {}  ({}{})", r.id, r.uuid,
               utc_iso(r.stored_unix_ms), names[r.machine_id], how.empty() ? "stored" : how,
               r.stored_by, r.stored_from, runs, runs == 1 ? " run" : " runs");
  }
}

}  // namespace

void add_model_store_commands(CLI::App& model) {
  const auto [store, s] = add_command<StoreModelOptions>(
      model, "store", run_store,
      "Keep a model file in the local store (a stable UUID, who and when), for daq sync and the "
      "model commands' --db");
  store->add_option("file", s->file, "Model file (caldaq.model.v1/v2)")->required();
  store->add_option("--machine", s->machine,
                    "The machine it models (default: the model's name); it must be in the store");
  add_db_option(*store, s->db);

  const auto [list, l] = add_command<ListOptions>(
      model, "list", run_list,
      "The models kept in a store (daq model build --store, daq model store, daq sync)");
  list->add_option("--machine", l->machine, "Only this machine's");
  list->add_flag("--json", l->json, "Print caldaq.model-list.v1 JSON (with each provenance)");
  add_read_db_option(*list, l->db);
}

}  // namespace daq
