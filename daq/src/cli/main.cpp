// daq: data acquisition and analysis for machine-tool calibration.
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include "cal/analysis/error.hpp"
#include "cal/replay/capture.hpp"
#include "cal/storage/store.hpp"
#include "cli_checks.hpp"
#include "commands.hpp"
#include "suggest.hpp"

namespace {

// One line, one prefix: "daq: error: WHAT (see daq report --help)"; status 2, for a usage error
// and for any input, file, device or port the user named that cannot be used.
int usage_error(const std::string& what, const std::string& command) {
  const std::string help = command.empty() ? "" : fmt::format(" (see {} --help)", command);
  std::fflush(stdout);  // what a command printed before its error comes first
  fmt::print(stderr, "daq: error: {}{}\n", what, help);
  return 2;
}

}  // namespace

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
  daq::add_sync_command(app);
  daq::add_approve_command(app);
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
  daq::add_docs_commands(app);  // last: the pages and completion cover every command above
  daq::check_numbers(app);

  // A mistyped command or option is named with the nearest right one, before CLI11 reads the
  // words after it as something else.
  const std::vector<std::string> args(argv + 1, argv + argc);
  if (const auto unknown = daq::unknown_word(app, args)) return usage_error(*unknown, "");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version are "parse errors" with status 0; every usage error is status 2,
    // as for any other bad input (CLI11's own codes are 104-109).
    if (e.get_exit_code() == 0) return app.exit(e);
    return usage_error(e.what(), daq::parsed_command(app));
  } catch (const cal::InputError& e) {
    return usage_error(e.what(), "");
  } catch (const cal::replay::CaptureError& e) {
    return usage_error(e.what(), "");
  } catch (const cal::storage::StoreError& e) {
    return usage_error(e.what(), "");
  } catch (const std::exception& e) {
    std::fflush(stdout);
    fmt::print(stderr, "daq: error: {}\n", e.what());
    return 1;
  }
  return 0;
}
