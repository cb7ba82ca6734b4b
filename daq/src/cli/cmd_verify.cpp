// daq verify: the as-left run of an axis against the compensation table written before it.
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>

#include "cal/analysis/error.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "compensation/compensation_check.hpp"
#include "database.hpp"
#include "output_file.hpp"
#include "terminal.hpp"

namespace daq {
namespace {

struct VerifyOptions {
  std::string db, corrected;
  std::int64_t run = 0;
  std::optional<std::int64_t> compensation;
  bool json = false, list = false;
};

void list_compensations(const cal::storage::RunReader& store) {
  const auto all = store.compensations();
  if (all.empty())
    fmt::print("no compensation tables stored (daq compensate --run RUN stores one)\n");
  for (const auto& c : all)
    print_line("compensation {}: axis {}, {} from {}, machine {}", c.id, c.axis, c.format, c.source,
               c.machine_id);
}

// A stored file name as a name inside --corrected: the store may come from elsewhere (a
// central server, a colleague's file), so a name that leaves the directory ("../x", "/etc/x")
// or is no file name at all is refused before anything is written.
void check_file_name(const std::string& name, std::int64_t compensation_id) {
  const bool plain =
      !name.empty() && name != "." && name != ".." &&
      name.find_first_of(std::string_view("/\\\0", 3)) == std::string::npos &&
      std::none_of(name.begin(), name.end(), [](unsigned char c) { return c < 0x20 || c == 0x7f; });
  if (!plain)
    throw cal::InputError(fmt::format(
        "verify: compensation {} names a file {}, which is not a plain file name: nothing written",
        compensation_id, nlohmann::json(name).dump()));
}

void run(const VerifyOptions& o) {
  const auto reader = open_run_reader(o.db);  // either store (--db postgresql://...)
  const auto& store = *reader;
  if (o.list) return list_compensations(store);
  if (o.run == 0) throw cal::InputError("verify: give the as-left RUN (or --list)");
  const auto check = check_run(store, o.run, o.compensation);
  if (!check)
    throw cal::InputError(fmt::format(
        "{}: run {}: no compensation of its axis on its machine was stored before it (or none "
        "of its stops lies where the table was made): nothing to verify",
        store.name(), o.run));
  if (o.json) {
    auto j = to_json(*check);
    j["schema"] = "caldaq.verification.v1";
    j["run"] = o.run;
    fmt::print("{}\n", j.dump(2));
  } else {
    print_line("run {}: {}", o.run, loop_text(*check));
    const auto& v = check->verification;
    fmt::print(
        "  largest |deviation|: predicted {:.3f} um, measured {:.3f} um ({} points; "
        "agreement within {:.3f} um rms, found {:.3f})\n",
        v.predicted_max_um, v.measured_max_um, check->points, v.tolerance_um, v.mismatch_rms_um);
  }
  if (o.corrected.empty()) return;
  // One file to --corrected; a compensation of several files (ISG lists, the volumetric list
  // and its CSV) into --corrected as a directory, by their names.
  const auto files = corrected_files(*check);
  const bool one = files.size() == 1 && files.front().first.empty();
  if (!one)
    for (const auto& f : files) check_file_name(f.first, check->compensation.id);
  if (!one) std::filesystem::create_directories(o.corrected);
  for (const auto& [name, text] : files) {
    const auto path =
        one ? std::filesystem::path(o.corrected) : std::filesystem::path(o.corrected) / name;
    write_output_file(path, text, "corrected table");
    fmt::print(stderr, "written {}: the corrected table ({})\n", path.string(),
               check->compensation.format);
  }
}

}  // namespace

void add_verify_command(CLI::App& app) {
  const auto [cmd, o] = add_command<VerifyOptions>(
      app, "verify", run,
      "Compare an as-left run with the compensation table written before it: as predicted, or "
      "an inverted sign, a unit or a reference-point error; a straightness run against the "
      "cross-axis compensation written before it (docs/compensation-tables.md)");
  cmd->add_option("run", o->run, "The as-left run (measured with the table loaded)");
  add_read_db_option(*cmd, o->db);
  cmd->add_option("--compensation", o->compensation,
                  "The stored compensation to compare with (default: the newest of the run's "
                  "machine and axis stored before the run)");
  cmd->add_option("--corrected", o->corrected,
                  "Write the table corrected for what was found (sign, units, reference point, "
                  "position shift); "
                  "a compensation of several files goes into this directory");
  cmd->add_flag("--list", o->list, "List the stored compensation tables");
  cmd->add_flag("--json", o->json, "Print caldaq.verification.v1 JSON");
}

}  // namespace daq
