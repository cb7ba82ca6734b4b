#include "database.hpp"

#include <cstdlib>

namespace daq {

std::filesystem::path database_path(const std::string& option) {
  if (!option.empty()) return option;
  if (const char* env = std::getenv("CALDAQ_DB"); env && *env) return env;
  std::filesystem::path base;
  if (const char* xdg = std::getenv("XDG_DATA_HOME"); xdg && *xdg)
    base = xdg;
  else if (const char* home = std::getenv("HOME"); home && *home)
    base = std::filesystem::path(home) / ".local" / "share";
  else
    base = ".";
  std::filesystem::create_directories(base / "caldaq");
  return base / "caldaq" / "site.sqlite";
}

void add_db_option(CLI::App& cmd, std::string& target) {
  cmd.add_option("--db", target,
                 "Run database (default: $CALDAQ_DB, else ~/.local/share/caldaq/site.sqlite)");
}

}  // namespace daq
