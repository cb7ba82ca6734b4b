// daq demo: an analysis demonstration on a SIMULATED axis with known injected errors. Later
// issues replace it with the whole acquisition chain (simulated machine, instrument twins,
// storage); until then it exercises the analysis library end to end and prints the
// simulated truth beside what the analysis recovers.
#include <fmt/format.h>

#include <cmath>
#include <numbers>
#include <random>

#include "cal/analysis/air.hpp"
#include "cal/analysis/compensation.hpp"
#include "cal/analysis/iso230_2.hpp"
#include "cal/analysis/iso230_2_targets.hpp"
#include "cal/analysis/uncertainty.hpp"
#include "commands.hpp"
#include "iso230_2_output.hpp"

namespace daq {
namespace {

// The simulated axis: a scale error, a periodic (ball-screw lead) error, a reversal
// (backlash) and random noise, in micrometres.
struct SimulatedAxis {
  double scale_um_per_m = 6.0;
  double periodic_amplitude_um = 1.5;
  double periodic_pitch_mm = 20.0;
  double backlash_um = 3.0;  // up runs stop +B/2, down runs -B/2
  double noise_sigma_um = 0.4;

  double systematic_um(double x_mm, cal::iso230_2::Direction d) const {
    const double half = d == cal::iso230_2::Direction::up ? backlash_um / 2 : -backlash_um / 2;
    return scale_um_per_m * x_mm / 1000.0 +
           periodic_amplitude_um * std::sin(2 * std::numbers::pi * x_mm / periodic_pitch_mm) + half;
  }
};

void run_demo() {
  fmt::print("daq demo: ISO 230-2 positioning test of a SIMULATED axis (0 .. 1000 mm)\n");
  fmt::print("(the acquisition chain with simulated instruments arrives with later issues)\n\n");

  // 1. Air and material on a simulated shop floor.
  cal::air::Conditions air;
  air.temperature_degc = 22.5;
  air.pressure_pa = 100500.0;
  air.humidity = cal::air::Humidity::relative_pct(45.0);
  const auto n = cal::air::refractive_index(air, cal::air::Equation::ciddor);
  const double material_degc = 21.2, alpha = 11.5e-6;
  const auto f = cal::comp::combined_factor(n.n, alpha, material_degc);
  fmt::print("Air 22.5 degC, 1005.00 hPa, 45 %RH: n (Ciddor) = {:.9f}\n", n.n);
  fmt::print(
      "Material 21.2 degC, alpha 11.5 ppm/K: compensation {:+.3f} ppm (air {:+.3f}, "
      "material {:+.3f})\n",
      f.total_ppm, f.air_ppm, f.material_ppm);
  fmt::print("An uncompensated reading at 1000 mm would be off by {:.1f} um.\n\n",
             -f.total_ppm * 1e-3 * 1000.0);

  // 2. The test plan: 11 targets with random spacing, the standard linear cycle, 5 runs.
  cal::iso230_2::TargetSpec ts{.first_mm = 0,
                               .last_mm = 1000,
                               .interval_mm = 100.0,
                               .count = std::nullopt,
                               .random_fraction = 0.25,
                               .seed = 2026};
  const auto plan = cal::iso230_2::make_plan(ts, {});
  fmt::print("Plan: {} targets, {} moves (linear cycle, 5 runs each way)\n\n",
             plan.targets_mm.size(), plan.moves.size());

  // 3. "Measure": the simulated truth plus noise at every measure move.
  const SimulatedAxis axis;
  std::mt19937_64 rng(42);
  std::normal_distribution<double> noise(0.0, axis.noise_sigma_um);
  std::vector<cal::iso230_2::Measurement> data;
  for (const auto& m : plan.moves) {
    if (m.kind != cal::iso230_2::MoveKind::measure) continue;
    data.push_back({m.position_mm, m.run, m.direction,
                    axis.systematic_um(m.position_mm, m.direction) + noise(rng)});
  }
  const auto e = cal::iso230_2::evaluate(data, cal::iso230_2::Standard::iso230_2_2014);
  print(e);

  // 4. Truth beside result.
  double up_max = -1e9, up_min = 1e9, all_max = -1e9, all_min = 1e9;
  for (double t : plan.targets_mm) {
    for (auto d : {cal::iso230_2::Direction::up, cal::iso230_2::Direction::down}) {
      const double v = axis.systematic_um(t, d);
      all_max = std::max(all_max, v);
      all_min = std::min(all_min, v);
      if (d == cal::iso230_2::Direction::up) {
        up_max = std::max(up_max, v);
        up_min = std::min(up_min, v);
      }
    }
  }
  fmt::print("\nSimulated truth vs measured (noise sigma {:.1f} um, 5 runs):\n",
             axis.noise_sigma_um);
  fmt::print("  B   truth {:7.3f} um   measured {:7.3f} um\n", axis.backlash_um,
             e.at("B_mean").value_um);
  fmt::print("  E↑  truth {:7.3f} um   measured {:7.3f} um\n", up_max - up_min,
             e.at("E_up").value_um);
  fmt::print("  E   truth {:7.3f} um   measured {:7.3f} um\n", all_max - all_min,
             e.at("E_bi").value_um);
  fmt::print(
      "  R↑  truth {:7.3f} um   measured {:7.3f} um  (4 sigma; the max over targets of 4 s)\n",
      4 * axis.noise_sigma_um, e.at("R_up").value_um);

  // 5. Measurement uncertainty of this set-up.
  cal::unc::PositioningSetup s;
  s.length_m = 1.0;
  s.air = air;
  s.material_degc = material_degc;
  s.environmental_variation_um = 0.5;
  s.misalignment_offset_mm = 0.5;
  s.dead_path_m = 0.1;
  fmt::print("\n");
  print(cal::unc::positioning_budget(s), s.length_m);
}

}  // namespace

void add_demo_command(CLI::App& app) {
  auto* cmd = app.add_subcommand("demo", "Run the demonstration on a simulated axis");
  cmd->callback([] { run_demo(); });
}

}  // namespace daq
