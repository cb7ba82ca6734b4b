// daq replay CAPTURE: the recorded bytes through the same instruments and pipeline again,
// into a new stored run. The same capture always gives the same readings and results.
#include <fmt/format.h>

#include <boost/asio/io_context.hpp>
#include <filesystem>

#include "cal/analysis/error.hpp"
#include "cal/replay/session.hpp"
#include "commands.hpp"
#include "database.hpp"
#include "iso230_2_output.hpp"
#include "linear_run.hpp"
#include "session_spec.hpp"

namespace daq {
namespace {

using nlohmann::json;
using namespace std::chrono_literals;

struct ReplayOptions {
  std::string capture;
  std::string db;
  double speed = 0.0;
  bool json = false;
};

void run_replay(const ReplayOptions& o) {
  boost::asio::io_context io;
  cal::replay::ReplayBus bus(io, o.capture, o.speed);
  const json header = json::parse(bus.header_json(), nullptr, false);
  if (header.is_discarded() || header.value("format", "") != "caldaq.capture-header.v1")
    throw cal::InputError(
        fmt::format("{}: the capture header is not a caldaq session header", o.capture));
  const auto config = config_from_json(header.at("config"));
  if (!config.linear)
    throw cal::InputError(fmt::format("{}: not a linear (ISO 230-2) session", o.capture));

  LinearRunSetup setup;
  setup.config = config;
  setup.database = database_path(o.db);
  setup.capture_path = std::filesystem::absolute(o.capture).string();
  setup.software_version = "daq 0.1.0 (replay of " + header.value("software", "?") + ")";
  for (const auto& j : header.at("instruments")) {
    const auto spec = instrument_spec_from_json(j);
    auto inst = make_instrument(io, spec, bus.transport(spec.device, spec.transport),
                                {.name = spec.role, .clock = bus.clock(), .replay = true});
    if (spec.role == "laser")
      setup.laser = std::move(inst);
    else if (spec.role == "air")
      setup.air = std::move(inst);
    else if (spec.role == "material")
      setup.material.push_back(std::move(inst));
  }
  if (!setup.laser || !setup.air)
    throw cal::InputError(
        fmt::format("{}: the session has no laser or no air instrument", o.capture));
  LinearRun run(io, std::move(setup));
  run.start();
  std::optional<cal::replay::ReplayEnd> end;
  bus.start([&](const cal::replay::ReplayEnd& e) { end = e; });
  while (!run.finished() && !end) io.run_for(50ms);
  if (!run.finished()) {
    std::string why = "the capture ended before every stop was captured";
    if (end && end->damage)
      why = fmt::format("the capture is damaged at byte {} (block {}): {}", end->damage->offset,
                        end->damage->block, end->damage->what);
    run.stop(why);
  }
  const auto& out = run.outcome();
  if (!out.complete)
    throw cal::InputError(fmt::format("{}: replay stored as run {} but incomplete: {}", o.capture,
                                      out.run_id, out.reason));
  if (o.json) {
    json j = to_json(*out.evaluation);
    j["run_id"] = out.run_id;
    return fmt::print("{}\n", j.dump(2));
  }
  fmt::print("replayed {} into run {} ({} readings)\n\n", o.capture, out.run_id, out.readings);
  print(*out.evaluation);
}

}  // namespace

void add_replay_command(CLI::App& app) {
  auto o = std::make_shared<ReplayOptions>();
  auto* cmd = app.add_subcommand(
      "replay",
      "Replay a wire-level capture through the same instruments and pipeline into a new run");
  cmd->add_option("CAPTURE", o->capture, "Capture file (.cdq)")->required();
  add_db_option(*cmd, o->db);
  cmd->add_option("--speed", o->speed, "0: as fast as possible; 1: real time; 2: twice ...")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--json", o->json, "Print the result as caldaq.iso230-2.v1 JSON");
  cmd->callback([o] { run_replay(*o); });
}

}  // namespace daq
