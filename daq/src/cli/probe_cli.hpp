#pragma once
// What the sphere-probing commands share (cmd_model_probe.cpp, cmd_model_probe_poses.cpp) and
// the five-axis ballbar run uses: the simulated control's kinematics, and the option sets that
// `probe` and `probe-poses` (the fits) and `probe-sim` and `probe-poses-sim` (the simulated
// probe) declare alike.
#include <string>
#include <vector>

#include "model_cli.hpp"

namespace daq {

// The model's machine; or with a correction file (LinuxCNC trunnion pins from `hal`, a
// SINUMERIK swivel data record from `swivel`) the nominal model with its rotary axes on that
// file's lines (trt_control_machine, swivel_control_machine). `model` names the model file in
// errors. Throws cal::InputError for both files, or one that cannot be read or parsed.
kin::FiveAxisMachine control_machine(const mdl::Model& m, const std::string& model,
                                     const std::string& hal, const std::string& swivel);

// The options of a fit of probed centres (probe, probe-poses).
struct ProbeFitOptions {
  std::string centres, model, write, db;  // db: where --model is kept when not a file
  double probe_u_um = 0.0;
  bool json = false;
  bool keep_linear = false;
};
// Their help where the two commands differ.
struct ProbeFitHelp {
  std::string centres, model, probe_u, keep_linear, json;
  bool model_required = false;
};
void add_probe_fit_options(CLI::App& cmd, ProbeFitOptions& o, const ProbeFitHelp& help);

// The options of a simulated probe (probe-sim, probe-poses-sim); `control_help` says what a
// missing --control means.
struct ProbeSimOptions : TruthControlOptions {
  std::string output;
  std::vector<double> sphere_mm;
  double noise_um = 0.0;
  unsigned seed = 1;
};
void add_probe_sim_options(CLI::App& cmd, ProbeSimOptions& o, const std::string& control_help);
// What a simulated probe reads (probe-sim, probe-poses-sim): the truth's model and machine, and
// the control's kinematics that report the centres (--control's, by default the truth's nominal
// kinematics). `o.truth` and `o.control` become the models' labels: what the output names.
struct ProbeSimModels {
  mdl::Model truth;
  kin::FiveAxisMachine machine, control;
};
ProbeSimModels read_probe_sim_models(ProbeSimOptions& o);

}  // namespace daq
