// daq model probe-poses | probe-poses-sim: the location errors of every rotary axis that turns in
// a probing program, fitted together, when the program turns several axes at once (a trunnion's
// C and A in one cycle, a table axis with a head axis). The centres: one row per probed pose, a
// column per rotary axis's angle (c_deg, a_deg, ...) and the centre as the control reports it
// (x_mm, y_mm, z_mm, machine coordinates). The maths: cal::kinematics::fit_location_errors
// (rotary_fit.hpp), docs/kinematics.md "Several rotary axes fitted together".
#include <fmt/format.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <random>

#include "cal/analysis/error.hpp"
#include "cal/analysis/rotary_fit.hpp"
#include "cal/analysis/text.hpp"
#include "cli_checks.hpp"
#include "command.hpp"
#include "csv_columns.hpp"
#include "model_cli.hpp"
#include "output_file.hpp"
#include "probe_cli.hpp"

namespace daq {

namespace {

struct PosesOptions : ProbeFitOptions {};

struct Poses {
  std::vector<kin::ProbedPose> poses;
  std::vector<int> lines;
};

Poses read_poses(const std::string& path, const mdl::Model& m, bool with_centres) {
  std::vector<std::string> columns = rotary_angle_columns(m);
  if (with_centres)
    for (const char* c : {"x_mm", "y_mm", "z_mm"}) columns.emplace_back(c);
  const auto csv = read_csv_columns(path, columns);
  Poses out;
  const std::size_t n_axes = m.rotary.size();
  for (std::size_t r = 0; r < csv.rows(); ++r) {
    kin::ProbedPose p;
    for (std::size_t i = 0; i < n_axes; ++i) p.angles_deg.push_back(csv.numbers.at(columns[i])[r]);
    if (with_centres)
      p.centre_mm = {csv.numbers.at("x_mm")[r], csv.numbers.at("y_mm")[r],
                     csv.numbers.at("z_mm")[r]};
    out.poses.push_back(std::move(p));
  }
  out.lines = csv.line;
  return out;
}

// The per-axis view of the joint fit, for printing and for put_location_fit.
kin::AxisLineFit axis_view(const kin::LocationFit& f, const kin::FiveAxisMachine& m,
                           std::size_t a) {
  kin::AxisLineFit v;
  v.letter = m.rotary[f.axes[a]].letter;
  v.position_um = f.position_um[a];
  v.position_u_um = f.position_u_um[a];
  v.orientation_urad = f.orientation_urad[a];
  v.orientation_u_urad = f.orientation_u_urad[a];
  v.rms_um = f.rms_um;
  v.sigma_um = f.sigma_um;
  v.dof = f.dof;
  return v;
}

// The four location errors of a view: name, value, u, unit (positions then orientations).
struct Named {
  std::string name;
  double value, u;
  const char* unit;
};
std::vector<Named> named(const kin::AxisLineFit& v) {
  const auto names = kin::location_error_names(v.letter);
  const std::size_t own = kin::direction_index(v.letter);
  std::vector<Named> out;
  for (std::size_t slot = 0; slot < 6; ++slot) {
    if (slot % 3 == own) continue;
    const bool pos = slot < 3;
    out.push_back({names[out.size()], pos ? v.position_um[slot] : v.orientation_urad[slot - 3],
                   pos ? v.position_u_um[slot] : v.orientation_u_urad[slot - 3],
                   pos ? "um" : "urad"});
  }
  return out;
}

void run_poses(const PosesOptions& given) {
  auto in_model = read_model_input(given.model, given.db);
  PosesOptions o = given;
  o.model = in_model.label;  // the file, or the stored model: what the output names
  mdl::Model m = std::move(in_model.model);
  const kin::FiveAxisMachine machine = mdl::five_axis(m);
  if (machine.rotary.empty())
    throw cal::InputError(fmt::format("{}: the model has no rotary axis", o.model));
  const Poses in = read_poses(o.centres, m, true);
  // The axes to fit: those that turn somewhere in the program.
  std::vector<std::size_t> axes;
  for (std::size_t i = 0; i < machine.rotary.size(); ++i)
    for (const auto& p : in.poses)
      if (p.angles_deg[i] != 0.0) {
        axes.push_back(i);
        break;
      }
  if (axes.empty())
    throw cal::InputError(
        fmt::format("{}: no rotary axis turns in its {} poses", o.centres, in.poses.size()));
  kin::LocationFit f;
  try {
    f = kin::fit_location_errors(machine, axes, in.poses, o.probe_u_um, !o.keep_linear);
  } catch (const cal::InputError& e) {
    throw cal::InputError(fmt::format("{}: {} poses (lines {} .. {}): {}", o.centres,
                                      in.poses.size(), in.lines.front(), in.lines.back(),
                                      e.what()));
  }
  std::string letters;
  for (std::size_t a : axes)
    letters +=
        (letters.empty() ? "" : ", ") + std::string(kin::to_string(machine.rotary[a].letter));
  json jaxes = json::array(), offsets = json::array();
  if (!o.json)
    fmt::print("Axes {} fitted together from {} probed poses ({}), {} parameters\n", letters,
               in.poses.size(), o.centres, 3 + 4 * axes.size());
  for (std::size_t a = 0; a < axes.size(); ++a) {
    const kin::AxisLineFit v = axis_view(f, machine, a);
    const auto& r = machine.rotary[axes[a]];
    json loc = json::object();
    if (!o.json)
      fmt::print("Axis {} ({} side), nominal pivot ({:g}, {:g}, {:g}) mm\n",
                 kin::to_string(v.letter), kin::to_string(r.side), r.pivot_mm[0], r.pivot_mm[1],
                 r.pivot_mm[2]);
    for (const auto& n : named(v)) {
      loc[n.name] = {{"value", n.value},
                     {"uncertainty", std::isnan(n.u) ? json(nullptr) : json(n.u)},
                     {"unit", n.unit}};
      if (!o.json)
        fmt::print("  {:6} {:+10.3f} {:4}  u = {:.3f} {}\n", n.name, n.value, n.unit, n.u, n.unit);
    }
    jaxes.push_back(
        {{"axis", kin::to_string(v.letter)}, {"side", kin::to_string(r.side)}, {"location", loc}});
    put_location_fit(m.rotary[axes[a]], v,
                     json{{"kind", "sphere probing, axes fitted together"},
                          {"centres_file", o.centres},
                          {"poses", in.poses.size()},
                          {"axes", letters},
                          {"rms_um", f.rms_um}});
  }
  for (std::size_t a = 0; a < axes.size(); ++a)
    for (std::size_t b = a + 1; b < axes.size(); ++b) {
      const kin::LineOffset off = kin::line_offset(machine, f, a, b);
      const auto la = kin::to_string(machine.rotary[axes[a]].letter);
      const auto lb = kin::to_string(machine.rotary[axes[b]].letter);
      offsets.push_back(
          {{"from", la}, {"to", lb}, {"offset_mm", off.distance_mm}, {"u_um", off.u_um}});
      if (!o.json)
        fmt::print(
            "Offset of the {} line from the {} line (their common perpendicular, along {} x "
            "{}): {:+.4f} mm, u = {:.3f} um\n",
            lb, la, la, lb, off.distance_mm, off.u_um);
    }
  const auto& s = f.sphere_mm;
  if (!o.json) {
    fmt::print(
        "Sphere at ({:.4f}, {:.4f}, {:.4f}) mm on the workpiece (u = {:.3f}, {:.3f}, {:.3f} um)\n",
        s[0], s[1], s[2], f.sphere_u_um[0], f.sphere_u_um[1], f.sphere_u_um[2]);
    fmt::print("Residuals: RMS {:.3f} um, sigma {:.3f} um, {} degrees of freedom{}\n", f.rms_um,
               f.sigma_um, f.dof,
               o.keep_linear ? " (linear axes taken as perfect: --keep-linear-errors)" : "");
  }
  json res = json::array();
  for (std::size_t k = 0; k < in.poses.size(); ++k)
    res.push_back({{"line", in.lines[k]},
                   {"angles_deg", in.poses[k].angles_deg},
                   {"residual_um", vec_json(f.residual_um[k])}});
  if (o.json)
    fmt::print("{}\n", json{{"schema", "caldaq.location-fit.v1"},
                            {"centres_file", o.centres},
                            {"model", o.model},
                            {"probe_u_um", o.probe_u_um},
                            {"linear_errors_in_fit", !o.keep_linear},
                            {"axes", jaxes},
                            {"line_offsets", offsets},
                            {"sphere_mm", vec_json(s)},
                            {"sphere_u_um", vec_json(f.sphere_u_um)},
                            {"rms_um", f.rms_um},
                            {"sigma_um", f.sigma_um},
                            {"dof", f.dof},
                            {"residuals", res}}
                           .dump(2));
  if (!o.write.empty()) {
    mdl::write(m, o.write);
    fmt::print(stderr, "model with the fitted location errors written to {}\n", o.write);
  }
}

struct PosesSimOptions : ProbeSimOptions {
  std::string poses;
};

void run_poses_sim(const PosesSimOptions& given) {
  PosesSimOptions o = given;
  const auto [m, machine, control] = read_probe_sim_models(o);
  const Poses in = read_poses(o.poses, m, false);
  const kin::Vec3 sphere{o.sphere_mm.at(0), o.sphere_mm.at(1), o.sphere_mm.at(2)};
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> noise(0.0, o.noise_um * 1e-3);
  const auto columns = rotary_angle_columns(m);
  std::string header;
  for (const auto& c : columns) header += c + ",";
  std::string text = fmt::format(
      "# simulated touch probe: sphere at ({:g}, {:g}, {:g}) mm on the workpiece, machine {}, "
      "control {}, noise {:g} um per coordinate (seed {})\n{}x_mm,y_mm,z_mm\n",
      sphere[0], sphere[1], sphere[2], cal::text::terminal_safe(o.truth),
      o.control.empty() ? "nominal" : cal::text::terminal_safe(o.control), o.noise_um, o.seed,
      header);
  for (std::size_t k = 0; k < in.poses.size(); ++k) {
    kin::Vec3 c;
    try {
      c = kin::probed_centre_mm(machine, control, sphere, in.poses[k].angles_deg);
    } catch (const cal::InputError& e) {
      throw cal::InputError(fmt::format("{}:{}: {}", o.poses, in.lines[k], e.what()));
    }
    for (double& x : c) x += o.noise_um > 0.0 ? noise(rng) : 0.0;
    for (double a : in.poses[k].angles_deg) text += fmt::format("{:g},", a);
    text += fmt::format("{:.6f},{:.6f},{:.6f}\n", c[0], c[1], c[2]);
  }
  if (o.output.empty()) return fmt::print("{}", text);
  write_output_file(o.output, text, "centres");
  fmt::print(stderr, "{} probed poses written to {}\n", in.poses.size(), o.output);
}

}  // namespace

void add_model_probe_poses_command(CLI::App& model) {
  const auto [fit, p] = add_command<PosesOptions>(
      model, "probe-poses", run_poses,
      "Fit the location errors of every rotary axis that turns in a probing program together "
      "(poses that turn several axes at once): a CSV of c_deg, a_deg, ... (one per rotary axis "
      "of the model), x_mm, y_mm, z_mm");
  add_probe_fit_options(
      *fit, *p,
      {.centres = "CSV of probed poses: the angle of each rotary axis (c_deg, a_deg, ...) and the "
                  "centre as the control reports it (x_mm, y_mm, z_mm, machine coordinates)",
       .model = "Model file (caldaq.model.v2): the nominal pivots, and the control's kinematics "
                "that computed the centres",
       .probe_u = "Standard uncertainty of one probed centre per coordinate (0: from the "
                  "residuals)",
       .keep_linear = "Fit as if the linear axes were perfect, even when --model holds their "
                      "errors (by default they are part of the fitted machine)",
       .json = "Print caldaq.location-fit.v1 JSON",
       .model_required = true});

  const auto [sim, s] = add_command<PosesSimOptions>(
      model, "probe-poses-sim", run_poses_sim,
      "Simulated touch probe at poses that turn several rotary axes: the centres a model (the "
      "simulated machine's truth) reports, as a CSV for daq model probe-poses");
  add_probe_sim_options(*sim, *s,
                        "Model file of the control's kinematics that reports the centres "
                        "(default: the truth's nominal kinematics)");
  sim->add_option("--poses", s->poses,
                  "CSV of the poses: one column per rotary axis of the model (c_deg, a_deg, ...)")
      ->required();
}

}  // namespace daq
