#pragma once
// Where the run store lives, for every command that reads or writes runs.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <memory>
#include <string>

#include "cal/storage/store.hpp"

namespace daq {

// --db PATH, else $CALDAQ_DB, else $XDG_DATA_HOME/caldaq/site.sqlite (default
// ~/.local/share/caldaq/site.sqlite). The default directory is created: for commands that
// write.
std::filesystem::path database_path(const std::string& option);
// The run store for a command that only reads (runs, show, export, report, analyse RUN,
// compensate --run): the same path without creating anything, opened read-only, so the
// database must exist and be caldaq's and is never created, migrated or changed; it works on
// a full disk and a read-only medium (see docs/storage.md).
cal::storage::Store open_database_read_only(const std::string& option);
// What the read commands read (runs, show, export, report, analyse RUN, model build, ballbar
// history, verify): the run store opened read-only as above, or, when `option` is a
// postgresql:// URI, the central store (storage/pg), through one interface. The commands that
// write refuse such a URI with that reason (database_path, open_database_read_only).
std::unique_ptr<cal::storage::RunReader> open_run_reader(const std::string& option);
// Who and where, recorded with what is stored or sent (a run's version, a model): $USER, else
// the account's name; the host's name ("?" when unknown).
std::string user_name();
std::string host_name();
// Adds the --db option to a command; add_read_db_option's help names the central store too.
void add_db_option(CLI::App& cmd, std::string& target);
void add_read_db_option(CLI::App& cmd, std::string& target);

}  // namespace daq
