// daq: data acquisition and analysis for machine-tool calibration.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "cal/analysis/error.hpp"
#include "cal/replay/capture.hpp"
#include "cal/storage/store.hpp"
#include "cli_checks.hpp"
#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{
      "daq - machine-tool calibration: laser interferometer, environment and ballbar\n"
      "acquisition, compensation and ISO 230 analysis.\n\n"
      "Every command that prints results takes --json for machine-readable output."};
  app.require_subcommand(1);
  app.set_version_flag("--version", "daq 0.1.0");

  CLI::App* analyse = app.add_subcommand("analyse", "Evaluate a measured test by a standard");
  analyse->alias("analyze");

  daq::add_env_command(app);
  daq::add_iso230_2_commands(app, *analyse);
  daq::add_demo_command(app);
  daq::add_devices_command(app);
  daq::add_decode_command(app);
  daq::add_runs_commands(app);
  daq::add_stored_run_commands(app, *analyse);
  daq::add_replay_command(app);
  daq::add_run_commands(app);
  daq::add_sim_command(app);
  daq::add_import_commands(app);
  daq::add_geometry_commands(app, *analyse);
  daq::add_circle_commands(app, *analyse);
  daq::add_compensate_commands(app, *analyse);
  daq::add_verify_command(app);
  daq::add_report_command(app);
  daq::add_model_commands(app);
  daq::add_ballbar_commands(app);
  daq::add_serve_command(app);
  daq::add_bench_commands(app);
  daq::check_numbers(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version are "parse errors" with status 0; every usage error is status 2,
    // as for any other bad input (CLI11's own codes are 104-109).
    return app.exit(e) == 0 ? 0 : 2;
  } catch (const cal::InputError& e) {
    std::fprintf(stderr, "daq: error: %s\n", e.what());
    return 2;
  } catch (const cal::replay::CaptureError& e) {
    std::fprintf(stderr, "daq: error: %s\n", e.what());
    return 2;
  } catch (const cal::storage::StoreError& e) {
    std::fprintf(stderr, "daq: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "daq: error: %s\n", e.what());
    return 1;
  }
  return 0;
}
