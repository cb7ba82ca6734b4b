// SIMULATED five-axis ballbar session (see sim_ballbar5x.hpp).
#include "sim_ballbar5x.hpp"

#include <fmt/format.h>

#include <boost/asio/io_context.hpp>
#include <cmath>
#include <random>

#include "cal/analysis/error.hpp"
#include "cal/drivers/loop_time.hpp"
#include "cal/drivers/transport/transport.hpp"
#include "line_gauge/instrument.hpp"
#include "line_gauge/twin.hpp"
#include "roles.hpp"

namespace daq {

namespace kin = cal::kinematics;
namespace sim = cal::drivers::sim;

namespace {

constexpr double kProgramStartS = 1.0;  // the gauge streams from 0; the program starts here

// Where the program is at a time: the test, the rotary angle and how far out the spindle ball
// is (0 on the bar's length, 1 the whole feed-in out).
struct ProgramPoint {
  std::size_t test = 0;
  double angle_deg = 0.0;
  double out = 1.0;
};

ProgramPoint program_point(const RotaryBallbarRunSetup& run, double t) {
  const auto& tm = run.timing;
  for (std::size_t n = 0; n < run.tests.size(); ++n) {
    const auto& a = run.tests[n].angles_deg;
    const auto starts = tm.stop_starts_s(a);
    if (t < tm.out_s) return {n, a.front(), 1.0};
    t -= tm.out_s;
    if (t < tm.feed_in_s) return {n, a.front(), 1.0 - t / tm.feed_in_s};
    t -= tm.feed_in_s;
    const double end = starts.back() + tm.dwell_s;
    if (t < end) {
      for (std::size_t k = 0; k + 1 < starts.size(); ++k) {
        const double move_from = starts[k] + tm.dwell_s;
        if (t < move_from) return {n, a[k], 0.0};
        if (t < starts[k + 1])
          return {n, a[k] + (a[k + 1] - a[k]) * (t - move_from) / (starts[k + 1] - move_from), 0.0};
      }
      return {n, a.back(), 0.0};
    }
    t -= end;
    if (t < tm.feed_in_s) return {n, a.back(), t / tm.feed_in_s};
    t -= tm.feed_in_s;
  }
  return {run.tests.size() - 1, run.tests.back().angles_deg.back(), 1.0};
}

}  // namespace

double simulated_program_s(const RotaryBallbarRunSetup& run) {
  double s = 0.0;
  for (const auto& t : run.tests)
    s += run.timing.out_s + 2 * run.timing.feed_in_s +
         run.timing.stop_starts_s(t.angles_deg).back() + run.timing.dwell_s;
  return s;
}

double simulated_bar_mm(const SimulatedBallbar5x& sim, const RotaryBallbarRunSetup& run,
                        double t_s) {
  const ProgramPoint p = program_point(run, t_s);
  kin::RotaryBallbarTest test = run.tests[p.test];
  test.angles_deg = {p.angle_deg};
  // The linear axes follow the ball at every angle (the program's blocks of at most 1 deg
  // leave a sag of up to 9.5 um between them, which a real bar reads on the move; the stops,
  // which the run reads, are the blocks' end points, where there is none).
  const double e_um = kin::rotary_ballbar_readings_um(sim.truth, run.control, test).front();
  const double offset_um = p.test < sim.offset_um.size() ? sim.offset_um[p.test] : 0.0;
  return 1e-3 * (e_um + offset_um) + p.out * run.timing.feed_in_mm;
}

RotaryBallbarRunOutcome run_simulated_ballbar5x(const SimulatedBallbar5x& s,
                                                RotaryBallbarRunSetup setup) {
  boost::asio::io_context io;
  auto& vt = cal::drivers::VirtualTime::install(io);
  sim::World world(sim::MachineConfig{}, sim::AirConfig{});
  const sim::Clock clock = [&vt] { return vt.now_s(); };
  std::mt19937_64 rng(s.seed);
  std::normal_distribution<double> noise(0.0, s.noise_um);
  const RotaryBallbarRunSetup& run_view = setup;  // the tests and timing, read by the twin
  // Copied for the twin: `setup` moves into the run below.
  const RotaryBallbarRunSetup program{.config = {},
                                      .control = run_view.control,
                                      .tests = run_view.tests,
                                      .timing = run_view.timing};
  sim::GaugeTwin twin(io, world, clock,
                      {.zero_length_mm = 0.0,
                       .sample_rate_hz = setup.timing.sample_rate_hz,
                       .continuous = true,
                       .decimals = 5,
                       .value = [&](const sim::World& w) {
                         const double t = w.time_s() - kProgramStartS;
                         return simulated_bar_mm(s, program, t < 0 ? 0.0 : t) +
                                (s.noise_um > 0 ? 1e-3 * noise(rng) : 0.0);
                       }});
  namespace t = cal::drivers::transport;
  setup.ballbar = cal::drivers::make_gauge(
      io, t::make_serial(io, {.device = twin.device_path(), .baud = 115200}),
      {.device = RunDevices().device(Role::ballbar),
       .name = "ballbar",
       .clock = [&vt] { return vt.now_ns(); }},
      {.min_si = -0.1, .max_si = 0.1});
  // Which twin: a run's origin says it (daq show, the report's banner and instruments).
  setup.ballbar_origin = {.kind = "simulated",
                          .detail =
                              "a twin of a ballbar on the simulated five-axis machine of "
                              "daq model ballbar5x-run"};
  const double end_s = kProgramStartS + simulated_program_s(program) + 5.0;
  RotaryBallbarRun run(io, std::move(setup));
  run.start();
  vt.run_until([&run] { return run.finished(); }, static_cast<std::int64_t>(end_s * 1e9));
  if (!run.finished()) run.stop("the simulated program ended before the run was complete");
  const auto out = run.outcome();
  if (!out.complete)
    throw cal::InputError(fmt::format("run {} aborted: {}", out.run_id, out.reason));
  return out;
}

}  // namespace daq
