// Runs the built `daq` binary (CALDAQ_DAQ_BINARY, set by the test target) with arguments,
// its stdout and stderr into a file; the exit status and what it printed.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace cal::test {

struct Cli {
  int status = 0;
  std::string output;
};

inline Cli daq_cli(const std::string& args, const std::filesystem::path& out) {
  const int rc = std::system(
      (std::string(CALDAQ_DAQ_BINARY) + " " + args + " >'" + out.string() + "' 2>&1").c_str());
  std::ifstream in(out);
  std::stringstream text;
  text << in.rdbuf();
  return {rc, text.str()};
}

}  // namespace cal::test
