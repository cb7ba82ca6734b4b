#pragma once
// Where the run store lives, for every command that reads or writes runs.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <string>

namespace daq {

// --db PATH, else $CALDAQ_DB, else $XDG_DATA_HOME/caldaq/site.sqlite (default
// ~/.local/share/caldaq/site.sqlite). The directory is created when writing.
std::filesystem::path database_path(const std::string& option);
// Adds the --db option to a command.
void add_db_option(CLI::App& cmd, std::string& target);

}  // namespace daq
