// daq serve: the operator's page and an HTTP/WebSocket API (docs/web.md); the service itself is
// in serve/service.cpp.
#include "cal/analysis/error.hpp"
#include "cal/storage/pg/sync.hpp"
#include "cli_checks.hpp"
#include "commands.hpp"
#include "database.hpp"
#include "serve/fleet_serve.hpp"
#include "serve/service.hpp"

namespace daq {

void add_serve_command(CLI::App& app) {
  auto o = std::make_shared<serve::ServeOptions>();
  auto* cmd = app.add_subcommand(
      "serve",
      "Serve the operator's page (set-up, instruments, runs, results, reports) and its "
      "HTTP/WebSocket API on 127.0.0.1 (docs/web.md); with --db postgresql://... the fleet view "
      "of the central store instead (machines by site, trends, due dates, approvals; reader "
      "only)");
  auto* config =
      cmd->add_option("-c,--config", o->run.config,
                      "Machine/campaign TOML (docs/config.md): the set-up to start with");
  auto* simulate = cmd->add_flag(
      "--simulate", o->simulate,
      "Run the built-in SIMULATED shop (machine and instrument twins) in this process and start "
      "with its set-up; its machine runs each test's program when the run starts");
  config->excludes(simulate);
  cmd->add_option("--speed", o->speed,
                  "--simulate: SIMULATED time per real time (POST /api/simulation/speed "
                  "changes it while serving)")
      ->capture_default_str()
      ->check(finite_in(1.0, 100.0));
  cmd->add_option(
      "--db", o->run.db,
      "Run database (default: $CALDAQ_DB, else ~/.local/share/caldaq/site.sqlite) the runs are "
      "written to; a postgresql:// URI serves the fleet view of that central store instead "
      "(nothing written; no -c or --simulate): docs/web.md, \"The fleet view\"");
  cmd->add_option("--address", o->address, "Listen address; not loopback only with --token")
      ->capture_default_str();
  cmd->add_option("--port", o->port, "TCP port (0: any free port)")->capture_default_str();
  cmd->add_option("--token", o->token, "Required from every client (Bearer or ?token=)");
  cmd->add_option("--allow-host", o->allowed_hosts,
                  "A Host name accepted beside localhost and the address (repeatable), e.g. the "
                  "machine's name when serving beyond loopback");
  cmd->add_option("--allow-device", o->allowed_devices,
                  "A device a set-up applied from the page may open beside the configuration's "
                  "own (repeatable; anything else is refused with 403 before it is opened): a "
                  "path glob (/dev/ttyUSB*), HOST:PORT or HOST:LOW-HIGH, or 'hid VID:PID'");
  cmd->add_option("--max-connections", o->max_connections,
                  "Open connections at most (at the cap the stalest is closed: one refused, then "
                  "the HTTP connection without progress for longest, WebSockets last)")
      ->capture_default_str()
      ->check(whole_in(4, 100000));
  cmd->add_option("--max-connections-per-client", o->max_connections_per_client,
                  "Open connections from one address at most (its own stalest is closed for a "
                  "new one)")
      ->capture_default_str()
      ->check(whole_in(2, 100000));
  cmd->add_option("--request-timeout-s", o->request_timeout_s,
                  "A request, header and body, must arrive within this (idle connections, slow "
                  "headers and slow bodies are closed)")
      ->capture_default_str()
      ->check(finite_in(0.1, 3600.0));
  cmd->add_option("--capture-dir", o->capture_dir,
                  "Record each run's capture in this directory as run-N.cdq (created at start; "
                  "refused at start if it cannot be created or written)");
  cmd->add_option("--give-up-after", o->run.give_up_after,
                  "Reconnection attempts before a run's device is given up")
      ->capture_default_str();
  // The page shows every device's state and refuses Start while one is not ready, so the
  // service starts whatever state the devices are in; --check-s S > 0 asks for the start-up
  // check of `daq run` first (refused naming the device that did not speak).
  o->run.check_s = 0;
  cmd->add_option("--check-s", o->run.check_s,
                  "Before serving, every configured device must open and speak within this time, "
                  "as daq run checks (0: no check; the page shows each device's state anyway)")
      ->capture_default_str()
      ->check(finite_non_negative());
  cmd->callback([o] {
    // --db postgresql://...: the fleet view of the central store, a reader only.
    if (cal::storage::pg::is_postgresql_url(o->run.db)) return serve::serve_fleet(*o);
    if (!o->simulate && o->run.config.empty())
      throw cal::InputError(
          "daq serve needs a set-up: give -c FILE (a configuration) or --simulate (or --db "
          "postgresql://... for the fleet view of a central store)");
    serve::serve(*o);
  });
}

}  // namespace daq
