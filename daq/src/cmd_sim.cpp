// daq sim: the built-in SIMULATED shop as a separate process, for practising and for testing
// `daq run linear|circle` end to end: the twins listen on a loopback TCP port and on
// pseudo-terminals, a configuration file naming them is written, and after a delay the
// simulated machine runs the test's program. The acquiring process only sees devices.
#include <fmt/format.h>

#include <boost/asio/io_context.hpp>
#include <chrono>
#include <fstream>

#include "cal/analysis/error.hpp"
#include "circle_run.hpp"
#include "commands.hpp"
#include "linear_run.hpp"
#include "sim_shop.hpp"

namespace daq {
namespace {

using namespace std::chrono_literals;

struct SimOptions {
  std::string config_out = "caldaq-sim.toml";
  std::string test = "circle";
  double speed = 1.0;
  double start_after_s = 5.0;
  bool position_feed = false;
};

// The configuration of the shop's devices and tests. Times the acquiring process measures on
// its own clock (the trigger's dwell) are divided by the speed: it sees the program `speed`
// times faster than the program's own times.
std::string sim_config(const SimulatedShop& shop, double speed, bool position_feed, bool set) {
  const auto& t = shop.truth();
  // One full circle in XY, or the standard set: XY 360 deg, ZX and YZ 220 deg over the top,
  // each at a slow and a fast feed (docs/circle.md, "The standard set").
  const std::string tests =
      set ? "planes = [\"XY\", \"ZX\", \"YZ\"]\nfeeds_mm_per_min = [1000, 3000]\n"
          : "plane = \"XY\"\nfeed_mm_per_min = 1000\n";
  return fmt::format(
      R"TOML(# Written by `daq sim`: the devices of the built-in SIMULATED shop (running {speed}x
# faster than real time). Valid while that process runs.
campaign = "simulated"

[machine]
name = "SIMULATED VMC"
description = "built-in simulated 3-axis machine with injected errors (daq sim)"

{devices}
[environment]
equation = "ciddor"
expansion_ppm_per_k = {alpha}

[trigger]
tolerance_um = 1
dwell_s = {trigger_dwell}
window_mm = 0.5

[test.linear]
axis = "X"
first_mm = 0
last_mm = 500
interval_mm = 50
random_fraction = 0.2
runs = 5
overrun_mm = 3
feed_mm_per_min = 6000
dwell_s = 3

[test.circle]
{tests}radius_mm = {radius}
sample_rate_hz = 1000
overshoot_deg = 45
centre_mm = [{cx}, {cy}, {cz}]
calibrated_radius_mm = {radius}  # the simulated bar's exact length (simulation)
)TOML",
      fmt::arg("devices", shop.devices_toml(0.05 / speed, position_feed)), fmt::arg("speed", speed),
      fmt::arg("alpha", t.expansion_ppm_per_k), fmt::arg("trigger_dwell", 1.5 / speed),
      fmt::arg("radius", t.ballbar_mm), fmt::arg("cx", t.pivot_mm[0]),
      fmt::arg("cy", t.pivot_mm[1]), fmt::arg("cz", t.pivot_mm[2]), fmt::arg("tests", tests));
}

void run_sim(const SimOptions& o) {
  if (o.test != "linear" && o.test != "circle" && o.test != "circle-set")
    throw cal::InputError(
        fmt::format("--test '{}' (expected linear, circle or circle-set)", o.test));
  const bool set = o.test == "circle-set";
  boost::asio::io_context io;
  SimulatedShop shop(io, set ? ShopTruth::three_planes() : ShopTruth{}, o.speed);
  const std::string text = sim_config(shop, o.speed, o.position_feed, set);
  {
    std::ofstream out(o.config_out);
    if (!(out << text)) throw cal::InputError(fmt::format("{}: cannot write", o.config_out));
  }
  const auto config = cal::daq::parse_config(text, o.config_out);
  fmt::print(
      "daq sim: SIMULATED shop running {}x faster than real time; devices in {}\n"
      "  start `daq run {} --config {}` now: the machine starts the program in {} s\n",
      o.speed, o.config_out, set ? "circle" : o.test, o.config_out, o.start_after_s);
  std::fflush(stdout);
  // The shop's clock advances when it is read (a starved process slows the simulation down
  // rather than skipping it), so the loop reads it every few milliseconds itself: the twins
  // alone read it only when a client asks.
  const auto run_until = [&](double sim_s) {
    while (shop.now_s() < sim_s) io.run_for(2ms);
  };
  run_until(shop.now_s() + o.start_after_s * o.speed);
  const double t0_s = shop.now_s();
  if (set) {
    std::vector<cal::daq::BallbarSetTest> program;
    for (const auto& t : circle_tests(config)) program.push_back({t.plane, t.program});
    shop.run_circle_set(program);
  } else if (o.test == "circle") {
    shop.run_circle(circle_test(config).first);
  } else {
    const auto& l = *config.linear;
    shop.run_linear(linear_plan(l), l.feed_mm_per_min, l.dwell_s);
  }
  fmt::print("daq sim: program started ({:.0f} s of simulated time)\n",
             shop.program_end_s() - t0_s);
  std::fflush(stdout);
  // The program, then a little more so the acquiring side can finish reading.
  run_until(shop.program_end_s() + 3.0 * o.speed);
  fmt::print("daq sim: program ended\n");
}

}  // namespace

void add_sim_command(CLI::App& app) {
  auto o = std::make_shared<SimOptions>();
  auto* cmd = app.add_subcommand(
      "sim", "Run the built-in SIMULATED machine and instruments for `daq run` in another process");
  cmd->add_option("--test", o->test,
                  "linear, circle (XY) or circle-set (XY, ZX, YZ at two feeds): the program the "
                  "machine runs")
      ->capture_default_str();
  cmd->add_option("-o,--config-out", o->config_out, "Where to write the devices' configuration")
      ->capture_default_str();
  cmd->add_option("--speed", o->speed, "Simulated time per real time")
      ->capture_default_str()
      ->check(CLI::Range(1.0, 100.0));
  cmd->add_option("--start-after-s", o->start_after_s, "Wall-clock delay before the program")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_flag("--position-feed", o->position_feed,
                "Configure the MTConnect SHDR position feed (position-assisted trigger)");
  cmd->callback([o] { run_sim(*o); });
}

}  // namespace daq
