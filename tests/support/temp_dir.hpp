// A fresh directory under the system's temporary directory for one test, removed with
// everything in it when the test ends. The name carries the process id and a random number,
// so tests running in parallel (ctest -j) never share one.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <random>
#include <string>
#include <string_view>

namespace cal::test {

struct TempDir {
  std::filesystem::path path;
  explicit TempDir(std::string_view prefix = "caldaq-test") {
    path = std::filesystem::temp_directory_path() /
           (std::string(prefix) + "-" + std::to_string(::getpid()) + "-" +
            std::to_string(std::random_device{}()));
    std::filesystem::create_directories(path);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  ~TempDir() {
    std::error_code ec;  // a destructor must not throw
    std::filesystem::remove_all(path, ec);
  }
};

}  // namespace cal::test
