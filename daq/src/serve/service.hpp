#pragma once
// `daq serve`: the operator's page and its API (docs/web.md) on one event loop with the
// instruments: the set-up (checked by the configuration loader), each instrument's state while
// idle and during a run, runs started and stopped from the page, results and reports; with
// `--simulate`, the built-in simulated shop in the same process.
#include <cstdint>
#include <string>
#include <vector>

#include "run_setup.hpp"
#include "server.hpp"

namespace daq::serve {

struct ServeOptions {
  RunOptions run;  // config (empty with simulate), db, give_up_after
  std::string address = "127.0.0.1", token, capture_dir;
  std::uint16_t port = 8080;
  std::vector<std::string> allowed_hosts;
  std::vector<std::string> allowed_devices;  // --allow-device patterns (serve/device_allow.hpp)
  std::size_t max_connections = 256;
  std::size_t max_connections_per_client = 64;
  double request_timeout_s = 10.0;
  bool simulate = false;  // the SIMULATED shop in this process, its configuration as set-up
  double speed = 10.0;    // of the simulated shop
};

// The HTTP server's options from the command line's (address, port, token, hosts, limits).
cal::daq::web::ServerOptions server_options(const ServeOptions& o);

// Runs until SIGINT or SIGTERM. Throws cal::InputError for options or a configuration at fault
// (the capture directory that cannot be created or written, an address without a token).
void serve(const ServeOptions& o);

}  // namespace daq::serve
