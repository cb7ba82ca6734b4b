#include "database.hpp"

#include <fmt/format.h>
#include <pwd.h>
#include <unistd.h>

#include <cstdlib>

#include "cal/analysis/error.hpp"
#include "cal/storage/pg/central.hpp"
#include "cal/storage/pg/sync.hpp"
#include "cli_checks.hpp"
#include "run_version.hpp"

namespace daq {
namespace {

std::filesystem::path default_directory() {
  if (const char* xdg = std::getenv("XDG_DATA_HOME"); xdg && *xdg)
    return std::filesystem::path(xdg) / "caldaq";
  if (const char* home = std::getenv("HOME"); home && *home)
    return std::filesystem::path(home) / ".local" / "share" / "caldaq";
  return std::filesystem::path(".") / "caldaq";
}

std::filesystem::path chosen_path(const std::string& option) {
  if (cal::storage::pg::is_postgresql_url(option))
    throw cal::InputError(fmt::format(
        "--db {}: this command writes the local store (the SQLite file at the machine); the "
        "read commands (runs, show, export, report, analyse RUN without --store, model build, "
        "ballbar history, verify) read the central store (docs/storage.md, \"Central store\")",
        cal::storage::pg::redacted(option)));
  if (!option.empty()) return option;
  if (const char* env = std::getenv("CALDAQ_DB"); env && *env) return env;
  return default_directory() / "site.sqlite";
}

}  // namespace

std::filesystem::path database_path(const std::string& option) {
  const auto path = chosen_path(option);
  if (option.empty() && path.parent_path() == default_directory())
    std::filesystem::create_directories(path.parent_path());
  return path;
}

cal::storage::Store open_database_read_only(const std::string& option) {
  return cal::storage::Store(chosen_path(option), {.read_only = true});
}

std::unique_ptr<cal::storage::RunReader> open_run_reader(const std::string& option) {
  if (cal::storage::pg::is_postgresql_url(option)) return cal::storage::pg::open_central(option);
  return std::make_unique<cal::storage::Store>(open_database_read_only(option));
}

std::string user_name() {
  if (const char* user = std::getenv("USER"); user && *user) return user;
  if (const passwd* pw = getpwuid(geteuid())) return pw->pw_name;
  return "?";
}

std::string host_name() {
  char name[256] = {};
  if (gethostname(name, sizeof name - 1) != 0) return "?";
  return name;
}

void add_db_option(CLI::App& cmd, std::string& target) {
  cmd.add_option("--db", target,
                 "Run database (default: $CALDAQ_DB, else ~/.local/share/caldaq/site.sqlite)");
}

void add_read_db_option(CLI::App& cmd, std::string& target) {
  cmd.add_option("--db", target,
                 "Run database (default: $CALDAQ_DB, else ~/.local/share/caldaq/site.sqlite), "
                 "or the central store: postgresql://... (docs/storage.md, \"Central store\")");
}

void add_version_option(CLI::App& cmd, int& target) {
  cmd.add_option("--version", target,
                 "Read this version of the run's stops, not the current one (a central store "
                 "keeps one per place the run was changed in: daq show RUN --db postgresql://... "
                 "lists them)")
      ->check(whole_in(1, 1000000));
}

void choose_version(cal::storage::RunReader& store, const std::string& db, std::int64_t run,
                    int version) {
  if (version == 0) return;
  if (!store.run(run))
    throw cal::InputError(fmt::format("{}: no run {} (see daq runs)", store.name(), run));
  if (!cal::storage::pg::is_postgresql_url(db))
    throw cal::InputError(fmt::format(
        "{}: run {} has no version {} here: a local store keeps one version of each run (the "
        "versions of a run changed in two places are the central store's: daq show RUN --db "
        "postgresql://... lists them)",
        store.name(), run, version));
  cal::storage::pg::read_version(store, run, version);
}

}  // namespace daq
