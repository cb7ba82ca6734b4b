// A run database's path for one test under the system's temporary directory, named with the
// process id and a random number so that tests running in parallel (ctest -j) never share one,
// and its removal with SQLite's write-ahead log and shared-memory files.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <random>
#include <string>
#include <string_view>

namespace cal::test {

// <tmp>/<prefix>-<name>-<pid>-<random><ext>
inline std::filesystem::path temp_path(std::string_view prefix, std::string_view name,
                                       std::string_view ext = ".sqlite") {
  return std::filesystem::temp_directory_path() /
         (std::string(prefix) + "-" + std::string(name) + "-" + std::to_string(::getpid()) + "-" +
          std::to_string(std::random_device{}()) + std::string(ext));
}

inline void remove_db(const std::filesystem::path& p) {
  for (const char* s : {"", "-wal", "-shm"}) std::filesystem::remove(p.string() + s);
}

}  // namespace cal::test
