#pragma once
// The SIMULATED five-axis ballbar session (issue 36): a five-axis machine (its truth, a model
// with injected location errors) runs the five-axis ballbar program its control computed (the
// control's model, maybe holding a correction) while the ballbar's gauge twin streams on a
// pseudo-terminal; the gauge driver reads it as a real bar, and a RotaryBallbarRun stores and
// analyses the stream. All on simulated time in this process.
#include <cstdint>
#include <vector>

#include "ballbar5x_run.hpp"

namespace daq {

struct SimulatedBallbar5x {
  cal::kinematics::FiveAxisMachine truth;  // the machine as it is
  double noise_um = 0.5;                   // Gaussian noise of each bar sample
  std::vector<double> offset_um;           // each test's bar zero (missing: 0)
  std::uint64_t seed = 1;
};

// The bar's reading (mm) at `t_s` seconds after the program's start, noise-free: what the twin
// prints besides its noise. Exposed for the tests.
double simulated_bar_mm(const SimulatedBallbar5x& sim, const RotaryBallbarRunSetup& run,
                        double t_s);
// The program's duration (s): every test's set-up, feed-in, stops, moves and feed-out.
double simulated_program_s(const RotaryBallbarRunSetup& run);

// Runs the session: the twin, the gauge instrument on it (setup.ballbar is made here), the run.
// Throws cal::InputError when the run did not complete, with its reason.
RotaryBallbarRunOutcome run_simulated_ballbar5x(const SimulatedBallbar5x& sim,
                                                RotaryBallbarRunSetup setup);

}  // namespace daq
