#pragma once
// Each file cmd_*.cpp adds its subcommands to the application.
#include <CLI/CLI.hpp>

namespace daq {

void add_env_command(CLI::App& app);
void add_iso230_2_commands(CLI::App& app, CLI::App& analyse);
void add_demo_command(CLI::App& app);
// devices: attached and reachable instruments, the drivers and their options
void add_devices_command(CLI::App& app);
// decode DRIVER FILE: what a driver makes of a dump of bytes
void add_decode_command(CLI::App& app);
// sync --to postgresql://...: the local runs copied to the central store
void add_sync_command(CLI::App& app);
// approve RUN: a reviewer's sign-off of a result (either store)
void add_approve_command(CLI::App& app);
// runs, show, export: stored runs
void add_runs_commands(CLI::App& app);
// analyse RUN, recompensate RUN: stored runs
void add_stored_run_commands(CLI::App& app, CLI::App& analyse);
// replay CAPTURE
void add_replay_command(CLI::App& app);
// run linear|circle, gcode linear|circle
void add_run_commands(CLI::App& app);
// sim: the simulated shop in its own process
void add_sim_command(CLI::App& app);
// import rtx: measurements from other software
void add_import_commands(CLI::App& app);
// analyse straightness, analyse squareness
void add_geometry_commands(CLI::App& app, CLI::App& analyse);
// analyse circle
void add_circle_commands(CLI::App& app, CLI::App& analyse);
// compensate
void add_compensate_commands(CLI::App& app, CLI::App& analyse);
// daq verify: an as-left run against the compensation written before it (cmd_verify.cpp).
void add_verify_command(CLI::App& app);
// serve: the live web readout and its API
void add_serve_command(CLI::App& app);
// report: HTML/PDF reports of stored runs
void add_report_command(CLI::App& app);
// bench ingest: throughput against the storage ceilings, measured on this machine
void add_bench_commands(CLI::App& app);
// model show|map|compensate|testpiece: the machine model file
void add_model_commands(CLI::App& app);
// ballbar calibrate|calibrations|volumetric|history
void add_ballbar_commands(CLI::App& app);

// man-pages DIR, completion bash: the manual pages and shell completion from the command tree
void add_docs_commands(CLI::App& app);

}  // namespace daq
