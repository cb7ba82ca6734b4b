// The real recordings (../shared/realdata beside the checkout; the test's CMake target defines
// CALDAQ_REALDATA_DIR), read whole.
#pragma once

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

namespace cal::test {

inline std::filesystem::path realdata() { return std::filesystem::path(CALDAQ_REALDATA_DIR); }

// The recording `name`, or std::runtime_error naming the file and where it is expected.
inline std::string read_realdata(const std::string& name) {
  const auto path = realdata() / name;
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw std::runtime_error(
        "cannot read " + path.string() +
        ": the real recordings are expected in ../shared/realdata beside the checkout");
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace cal::test
