// daq model probe | probe-sim: sphere probing of the rotary table axes. probe fits each table
// axis's average line (location errors with their uncertainty, the residuals as the axis's
// error motion) to the sphere centres a control's probing cycle exported; probe-sim is the
// simulated touch probe: the centres a model (the simulated machine's truth) gives, with noise.
// The maths: cal::kinematics (rotary.hpp), docs/kinematics.md "Sphere probing".
#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <sstream>

#include "cal/analysis/error.hpp"
#include "cal/analysis/rotary.hpp"
#include "cal/analysis/swivel_data.hpp"
#include "cal/analysis/text.hpp"
#include "cal/analysis/trt_kins.hpp"
#include "cli_checks.hpp"
#include "command.hpp"
#include "csv_columns.hpp"
#include "model_cli.hpp"
#include "output_file.hpp"
#include "probe_cli.hpp"

namespace daq {

namespace {

// --- probe: the fit ---------------------------------------------------------------------------

struct ProbeOptions : ProbeFitOptions {
  std::string axis;
  std::string hal, swivel;  // the control's correction: the fit is against its lines
  std::vector<double> pivot_mm;
};

struct AxisCentres {
  std::vector<kin::ProbedCentre> centres;
  std::vector<int> lines;
};

// The centres of each axis, in file order. With --axis the whole file is that axis; otherwise
// its "axis" column says which (A, B or C).
std::map<kin::RotaryLetter, AxisCentres> read_centres(const ProbeOptions& o) {
  const bool by_column = o.axis.empty();
  const auto csv =
      read_csv_columns(o.centres, {"angle_deg", "x_mm", "y_mm", "z_mm"},
                       by_column ? std::vector<std::string>{"axis"} : std::vector<std::string>{});
  std::map<kin::RotaryLetter, AxisCentres> out;
  const kin::RotaryLetter fixed =
      by_column ? kin::RotaryLetter::c : kin::rotary_letter_from_string(o.axis);
  for (std::size_t r = 0; r < csv.rows(); ++r) {
    kin::RotaryLetter letter = fixed;
    if (by_column) {
      const std::string& s = csv.texts.at("axis")[r];
      if (s != "A" && s != "B" && s != "C" && s != "a" && s != "b" && s != "c")
        throw cal::InputError(fmt::format("{}:{}: axis: '{}' is not a rotary axis (A, B or C)",
                                          o.centres, csv.line[r], cal::text::terminal_safe(s)));
      letter = kin::rotary_letter_from_string(s);
    }
    auto& a = out[letter];
    a.centres.push_back(
        {csv.numbers.at("angle_deg")[r],
         {csv.numbers.at("x_mm")[r], csv.numbers.at("y_mm")[r], csv.numbers.at("z_mm")[r]}});
    a.lines.push_back(csv.line[r]);
  }
  return out;
}

// The rotary axis of that letter the fit is against: the model's (its nominal pivot, no location
// error) or, with --hal / --swivel, the control's holding that correction (its line's point and
// direction; table axes only). `index`: its place in the chain; `line` nullptr without --model
// (--pivot-mm: a table axis).
struct AxisRef {
  kin::Vec3 pivot{};
  kin::Side side = kin::Side::table;
  std::size_t index = 0;
  const kin::RotaryAxis* line = nullptr;
};

AxisRef axis_of(const ProbeOptions& o, const std::optional<kin::FiveAxisMachine>& reference,
                kin::RotaryLetter l) {
  if (!reference)
    return {{o.pivot_mm.at(0), o.pivot_mm.at(1), o.pivot_mm.at(2)}, kin::Side::table, 0, nullptr};
  for (std::size_t i = 0; i < reference->rotary.size(); ++i) {
    const auto& r = reference->rotary[i];
    if (r.letter != l) continue;
    if (r.side != kin::Side::table && (!o.hal.empty() || !o.swivel.empty()))
      throw cal::InputError(
          fmt::format("{}: the {} axis is on the spindle side: the fit against a control's "
                      "correction (--hal, --swivel) is of table axes only (docs/kinematics.md)",
                      o.model, kin::to_string(l)));
    return {r.pivot_mm, r.side, i, &r};
  }
  throw cal::InputError(
      fmt::format("{}: {} has centres of the {} axis, the model has no such "
                  "rotary axis",
                  o.centres, o.model, kin::to_string(l)));
}

// The fit's four location errors (ISO 230-1 names, e.g. E_X0C, E_Y0C, E_A0C, E_B0C): the two
// positions across the axis, then the two tilts; the slots along the axis are not errors of it.
struct LocationValue {
  std::string name;
  double value = 0, uncertainty = 0;  // uncertainty NaN: not estimated
  const char* unit = "um";
};

std::vector<LocationValue> location_values(const kin::AxisLineFit& f) {
  const auto names = kin::location_error_names(f.letter);
  const std::size_t own = kin::direction_index(f.letter);
  std::vector<LocationValue> out;
  for (std::size_t slot = 0; slot < 6; ++slot) {
    if (slot % 3 == own) continue;
    const bool pos = slot < 3;
    out.push_back({.name = std::string(names[out.size()]),
                   .value = pos ? f.position_um[slot] : f.orientation_urad[slot - 3],
                   .uncertainty = pos ? f.position_u_um[slot] : f.orientation_u_urad[slot - 3],
                   .unit = pos ? "um" : "urad"});
  }
  return out;
}

// `against_control`: the fit was made against a corrected control's line (probe --hal /
// --swivel), so the pivot is the control's, not the nominal one.
json fit_json(const kin::AxisLineFit& f, const AxisRef& ax, const AxisCentres& a,
              const kin::HeadAxisFit* head, bool against_control) {
  const kin::Vec3& pivot = ax.pivot;
  json loc = json::object();
  for (const auto& l : location_values(f))
    loc[l.name] = {{"value", l.value},
                   {"uncertainty", std::isnan(l.uncertainty) ? json(nullptr) : json(l.uncertainty)},
                   {"unit", l.unit}};
  json res = json::array();
  for (std::size_t k = 0; k < a.centres.size(); ++k)
    res.push_back({{"line", a.lines[k]},
                   {"angle_deg", a.centres[k].angle_deg},
                   {"radial_um", f.radial_um[k]},
                   {"axial_um", f.axial_um[k]},
                   {"tangential_um", f.tangential_um[k]}});
  json sphere = nullptr;
  if (head)
    sphere = {
        {"mm", json::array({head->sphere_mm[0], head->sphere_mm[1], head->sphere_mm[2]})},
        {"u_um", json::array({head->sphere_u_um[0], head->sphere_u_um[1], head->sphere_u_um[2]})}};
  return {{"axis", kin::to_string(f.letter)},
          {"side", kin::to_string(ax.side)},
          {against_control ? "control_pivot_mm" : "nominal_pivot_mm",
           json::array({pivot[0], pivot[1], pivot[2]})},
          {"sphere", sphere},
          {"centres", a.centres.size()},
          {"location", loc},
          {"radius_mm", f.radius_mm},
          {"plane_offset_mm", f.plane_offset_mm},
          {"rms_um", f.rms_um},
          {"sigma_um", f.sigma_um},
          {"dof", f.dof},
          {"residuals", res}};
}

void print_fit(const kin::AxisLineFit& f, const AxisRef& ax, const AxisCentres& a,
               const kin::HeadAxisFit* head, bool against_control) {
  const kin::Vec3& pivot = ax.pivot;
  fmt::print("Axis {} ({} side): {} probed centres, {} pivot ({:g}, {:g}, {:g}) mm\n",
             kin::to_string(f.letter), kin::to_string(ax.side), a.centres.size(),
             against_control ? "the control's" : "nominal", pivot[0], pivot[1], pivot[2]);
  for (const auto& l : location_values(f))
    fmt::print("  {:6} {:+10.3f} {:4}  u = {}\n", l.name, l.value, l.unit,
               std::isnan(l.uncertainty)
                   ? std::string("not estimated (3 angles: give --probe-u-um)")
                   : fmt::format("{:.3f} {}", l.uncertainty, l.unit));
  if (head) {
    const auto& s = head->sphere_mm;
    const auto& u = head->sphere_u_um;
    fmt::print("  sphere at ({:.4f}, {:.4f}, {:.4f}) mm (u = {:.3f}, {:.3f}, {:.3f} um)\n", s[0],
               s[1], s[2], u[0], u[1], u[2]);
    fmt::print(
        "  probe tip {:.4f} mm from the fitted line, {:+.4f} mm along it from the pivot's plane "
        "(the tool offset must be calibrated: an error of it across the axis reads as the "
        "line's position)\n",
        f.radius_mm, f.plane_offset_mm);
  } else {
    fmt::print("  circle radius {:.4f} mm, its plane {:+.4f} mm from the pivot along the axis\n",
               f.radius_mm, f.plane_offset_mm);
  }
  fmt::print(
      "  residuals (the axis's error motion at the {}, and probing noise): RMS {:.3f} "
      "um, sigma {:.3f} um, {} degrees of freedom\n",
      head ? "probe tip" : "sphere", f.rms_um, f.sigma_um, f.dof);
  fmt::print("  {:>6} {:>10} {:>10} {:>10} {:>12}\n", "line", "angle_deg", "radial_um", "axial_um",
             "tangential_um");
  for (std::size_t k = 0; k < a.centres.size(); ++k)
    fmt::print("  {:6} {:10.3f} {:+10.3f} {:+10.3f} {:+12.3f}\n", a.lines[k],
               a.centres[k].angle_deg, f.radial_um[k], f.axial_um[k], f.tangential_um[k]);
}

void put_fit(mdl::RotaryEntry& r, const kin::AxisLineFit& f, const std::string& centres,
             std::size_t count) {
  put_location_fit(r, f,
                   json{{"kind", "sphere probing"},
                        {"centres_file", centres},
                        {"centres", count},
                        {"rms_um", f.rms_um}});
}

// Whether the model holds any measured linear-axis error (a component or a squareness).
bool has_linear_errors(const mdl::Model& m) {
  return std::any_of(m.components.begin(), m.components.end(),
                     [](const auto& c) { return c.given; }) ||
         std::any_of(m.squareness.begin(), m.squareness.end(),
                     [](const auto& q) { return q.given; });
}

// The model's linear-axis errors taken out of one axis's centres (kin::remove_linear_errors),
// said on standard error (text) or returned for the JSON: the largest correction and where.
json remove_linear(const mdl::Model& m, const ProbeOptions& o, kin::RotaryLetter letter,
                   AxisCentres& a) {
  kin::LinearCorrection c;
  try {
    c = kin::remove_linear_errors(m.machine, a.centres);
  } catch (const cal::InputError& e) {
    throw cal::InputError(
        fmt::format("{}: removing {}'s linear-axis errors from the {} axis's "
                    "centres: {} (--keep-linear-errors fits them as probed)",
                    o.centres, o.model, kin::to_string(letter), e.what()));
  }
  std::size_t worst = 0;
  double worst_um = 0.0;
  for (std::size_t k = 0; k < c.correction_um.size(); ++k) {
    const auto& e = c.correction_um[k];
    const double n = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
    if (n > worst_um) worst_um = n, worst = k;
  }
  a.centres = c.centres;
  if (!o.json)
    fmt::print(
        "Axis {}: the linear axes' errors of {} removed from the centres before the fit "
        "(largest {:.3f} um, line {}; --keep-linear-errors to fit them as probed)\n",
        kin::to_string(letter), o.model, worst_um, a.lines.empty() ? 0 : a.lines[worst]);
  json rows = json::array();
  for (const auto& e : c.correction_um) rows.push_back(json::array({e[0], e[1], e[2]}));
  return {{"model", o.model}, {"largest_um", worst_um}, {"correction_um", rows}};
}

std::string read_text(const std::string& path, std::string_view what) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  if (!in || !(ss << in.rdbuf()))
    throw cal::InputError(fmt::format("{}: cannot read the {}", path, what));
  return ss.str();
}

// The fit made against the control's line instead of the nominal one: the location errors the
// correction left (the actual line less the control's). The fit is made at the control's pivot,
// so the positions are already relative to its line's point; the control's tilts (a swivel
// record's V) are taken off the fitted ones (first order: both are micro-radians).
void relative_to(kin::AxisLineFit& f, const kin::RotaryAxis& control) {
  for (std::size_t k = 0; k < 3; ++k) {
    f.position_um[k] -= control.location_position_um[k];
    f.orientation_urad[k] -= control.location_orientation_urad[k];
  }
}

// The fit of a head axis: against the model as the control's kinematics (what computed the
// centres), with the model's linear-axis errors in the fitted machine unless kept out.
kin::HeadAxisFit fit_head(const ProbeOptions& o, const mdl::Model& m, const AxisRef& ax,
                          kin::RotaryLetter letter, const AxisCentres& a, bool linear) {
  if (linear && !o.json)
    fmt::print(
        "Axis {}: the linear axes' errors of {} are in the fitted machine (a head axis's "
        "centres are not corrected one by one; --keep-linear-errors to fit as if the linear "
        "axes were perfect)\n",
        kin::to_string(letter), o.model);
  return kin::fit_head_axis_line(mdl::five_axis(m), ax.index, a.centres, o.probe_u_um, linear);
}

void run_probe(const ProbeOptions& given) {
  ProbeOptions o = given;  // o.model: the file, or the stored model's label (what the output names)
  if (o.model.empty() && (o.axis.empty() || o.pivot_mm.size() != 3))
    throw cal::InputError("give --model (the pivots of its rotary axes) or --axis and --pivot-mm");
  if (!o.model.empty() && !o.pivot_mm.empty())
    throw cal::InputError("--pivot-mm is for a fit without --model (the model has the pivots)");
  if (!o.write.empty() && o.model.empty())
    throw cal::InputError("--write needs --model (the model the fitted errors go into)");
  const std::string& correction = o.hal.empty() ? o.swivel : o.hal;
  if (!correction.empty() && o.model.empty())
    throw cal::InputError("--hal and --swivel need --model (the nominal machine they correct)");
  if (!correction.empty() && !o.write.empty())
    throw cal::InputError(
        "--write with --hal or --swivel: the fit against a correction is what it left, not the "
        "machine's location errors; fit against the nominal model to write them");
  std::optional<mdl::Model> m;
  // What the fit is against: the nominal lines of the model's table axes (its pivots, no
  // location error), or the control's lines with the correction applied.
  std::optional<kin::FiveAxisMachine> reference;
  if (!o.model.empty()) {
    auto in = read_model_input(o.model, o.db);
    o.model = in.label;
    m = std::move(in.model);
    reference = control_machine(*m, o.model, o.hal, o.swivel);
    if (correction.empty())
      for (auto& r : reference->rotary) r.location_position_um = r.location_orientation_urad = {};
  }
  auto by_axis = read_centres(o);
  const bool remove = m && has_linear_errors(*m) && !o.keep_linear;
  if (!correction.empty() && !o.json)
    fmt::print(
        "The lines fitted against the control's kinematics ({} with {}): the location errors "
        "below are what the correction left\n",
        o.model, correction);
  json fits = json::array();
  for (auto& [letter, a] : by_axis) {
    const AxisRef ax = axis_of(o, reference, letter);
    const bool is_head = ax.side == kin::Side::spindle;
    json removed = nullptr;
    if (remove && !is_head) removed = remove_linear(*m, o, letter, a);
    kin::AxisLineFit f;
    std::optional<kin::HeadAxisFit> head;
    try {
      if (is_head) {
        head = fit_head(o, *m, ax, letter, a, remove);
        f = head->line;
      } else {
        f = kin::fit_axis_line(letter, ax.pivot, a.centres, o.probe_u_um);
      }
    } catch (const cal::InputError& e) {
      throw cal::InputError(fmt::format("{}: the {} axis's {} centres (lines {} .. {}): {}",
                                        o.centres, kin::to_string(letter), a.centres.size(),
                                        a.lines.front(), a.lines.back(), e.what()));
    }
    if (ax.line && !is_head) relative_to(f, *ax.line);
    const kin::HeadAxisFit* h = head ? &*head : nullptr;
    if (o.json) {
      fits.push_back(fit_json(f, ax, a, h, !correction.empty()));
      fits.back()["linear_errors_removed"] = removed;
      if (is_head) fits.back()["linear_errors_in_fit"] = remove;
    } else {
      print_fit(f, ax, a, h, !correction.empty());
    }
    if (m && correction.empty()) put_fit(m->rotary.at(ax.index), f, o.centres, a.centres.size());
  }
  if (o.json)
    fmt::print("{}\n", json{{"schema", "caldaq.axis-line-fit.v1"},
                            {"centres_file", o.centres},
                            {"probe_u_um", o.probe_u_um},
                            {"against", correction.empty() ? json(nullptr) : json(correction)},
                            {"linear_errors_removed", remove},
                            {"axes", fits}}
                           .dump(2));
  if (!o.write.empty()) {
    mdl::write(*m, o.write);
    fmt::print(stderr, "model with the fitted location errors written to {}\n", o.write);
  }
}

// --- probe-check: the centres against the control's kinematics --------------------------------

struct CheckOptions {
  std::string centres, model, hal, swivel, axis, db;
  bool json = false;
};

// The deviation of each probed centre from where the control's kinematics expects it: the
// sphere's place on the workpiece is what the control saw at angle 0 (where location errors
// move nothing), found so that the control's own prediction there is the centre probed there.
void run_probe_check(const CheckOptions& given) {
  auto in = read_model_input(given.model, given.db);
  CheckOptions o = given;
  o.model = in.label;  // the file, or the stored model: what the output names
  const mdl::Model m = std::move(in.model);
  // The correction as the control holds it: the kinematics file applied to the nominal model.
  const kin::FiveAxisMachine control = control_machine(m, o.model, o.hal, o.swivel);
  const std::string& correction = o.hal.empty() ? o.swivel : o.hal;
  ProbeOptions as_probe;
  as_probe.centres = o.centres;
  as_probe.axis = o.axis;
  json axes = json::array();
  for (const auto& [letter, a] : read_centres(as_probe)) {
    std::size_t index = control.rotary.size();
    for (std::size_t i = 0; i < control.rotary.size(); ++i)
      if (control.rotary[i].letter == letter) index = i;
    if (index == control.rotary.size())
      throw cal::InputError(fmt::format("{}: centres of the {} axis, {} has no such axis",
                                        o.centres, kin::to_string(letter), o.model));
    const auto angles_at = [&](double deg) {
      std::vector<double> v(control.rotary.size(), 0.0);
      v[index] = deg;
      return v;
    };
    const auto zero = std::find_if(a.centres.begin(), a.centres.end(), [](const auto& c) {
      return std::abs(std::remainder(c.angle_deg, 360.0)) < 1e-9;
    });
    if (zero == a.centres.end())
      throw cal::InputError(
          fmt::format("{}: no centre of the {} axis at 0 deg (the sphere's place "
                      "on the workpiece is taken there)",
                      o.centres, kin::to_string(letter)));
    kin::Vec3 sphere = zero->centre_mm;
    for (int it = 0; it < 6; ++it) {
      const auto at0 = kin::probed_centre_mm(control, control, sphere, angles_at(zero->angle_deg));
      for (std::size_t k = 0; k < 3; ++k) sphere[k] += zero->centre_mm[k] - at0[k];
    }
    double sum = 0.0, worst = 0.0;
    json rows = json::array();
    if (!o.json)
      fmt::print("Axis {}: {} centres against {}{}\n  {:>6} {:>10} {:>9} {:>9} {:>9} {:>9}\n",
                 kin::to_string(letter), a.centres.size(), o.model,
                 correction.empty() ? "" : " with " + correction, "line", "angle_deg", "dx_um",
                 "dy_um", "dz_um", "|d|_um");
    for (std::size_t k = 0; k < a.centres.size(); ++k) {
      // What the control reports on a machine that is as it believes (for a head axis: the
      // sphere itself at every angle).
      const auto want =
          kin::probed_centre_mm(control, control, sphere, angles_at(a.centres[k].angle_deg));
      kin::Vec3 d;
      for (std::size_t i = 0; i < 3; ++i) d[i] = 1e3 * (a.centres[k].centre_mm[i] - want[i]);
      const double n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      sum += n * n;
      worst = std::max(worst, n);
      if (o.json)
        rows.push_back({{"line", a.lines[k]},
                        {"angle_deg", a.centres[k].angle_deg},
                        {"deviation_um", json::array({d[0], d[1], d[2]})}});
      else
        fmt::print("  {:6} {:10.3f} {:+9.3f} {:+9.3f} {:+9.3f} {:9.3f}\n", a.lines[k],
                   a.centres[k].angle_deg, d[0], d[1], d[2], n);
    }
    const double rms = std::sqrt(sum / static_cast<double>(a.centres.size()));
    if (o.json)
      axes.push_back({{"axis", kin::to_string(letter)},
                      {"max_um", worst},
                      {"rms_um", rms},
                      {"centres", rows}});
    else
      fmt::print("  largest deviation {:.3f} um, RMS {:.3f} um\n", worst, rms);
  }
  if (o.json)
    fmt::print("{}\n", json{{"schema", "caldaq.probe-check.v1"},
                            {"centres_file", o.centres},
                            {"model", o.model},
                            {"hal", o.hal},
                            {"swivel", o.swivel},
                            {"axes", axes}}
                           .dump(2));
}

// --- probe-sim: the simulated touch probe ----------------------------------------------------

struct SimOptions : ProbeSimOptions {
  std::string axis;
  std::vector<double> angles_deg;
};

void run_probe_sim(const SimOptions& given) {
  SimOptions o = given;
  // The control that reports the centres: its kinematics (a head axis's centres are where it
  // puts the turned tip).
  const auto [m, machine, control] = read_probe_sim_models(o);
  const kin::RotaryLetter letter = kin::rotary_letter_from_string(o.axis);
  std::size_t index = machine.rotary.size();
  for (std::size_t i = 0; i < machine.rotary.size(); ++i)
    if (machine.rotary[i].letter == letter) index = i;
  if (index == machine.rotary.size())
    throw cal::InputError(
        fmt::format("{}: no {} axis in the model", o.truth, kin::to_string(letter)));
  const kin::Vec3 sphere{o.sphere_mm.at(0), o.sphere_mm.at(1), o.sphere_mm.at(2)};
  std::mt19937 rng(o.seed);
  std::normal_distribution<double> noise(0.0, o.noise_um * 1e-3);
  std::string text = fmt::format(
      "# simulated touch probe: sphere at ({:g}, {:g}, {:g}) mm on the workpiece, machine {}, "
      "control {}, noise {:g} um per coordinate (seed {})\naxis,angle_deg,x_mm,y_mm,z_mm\n",
      sphere[0], sphere[1], sphere[2], o.truth,
      o.control.empty() ? "nominal" : cal::text::terminal_safe(o.control), o.noise_um, o.seed);
  for (double deg : o.angles_deg) {
    std::vector<double> angles(machine.rotary.size(), 0.0);
    angles[index] = deg;
    kin::Vec3 c;
    try {
      c = kin::probed_centre_mm(machine, control, sphere, angles);
    } catch (const cal::InputError& e) {
      throw cal::InputError(fmt::format("{} probed by {}: {}", o.truth,
                                        o.control.empty() ? "its nominal control" : o.control,
                                        e.what()));
    }
    for (double& x : c) x += o.noise_um > 0.0 ? noise(rng) : 0.0;
    text += fmt::format("{},{:g},{:.6f},{:.6f},{:.6f}\n", kin::to_string(letter), deg, c[0], c[1],
                        c[2]);
  }
  if (o.output.empty()) return fmt::print("{}", text);
  write_output_file(o.output, text, "centres");
  fmt::print(stderr, "{} probed centres written to {}\n", o.angles_deg.size(), o.output);
}

}  // namespace

// model_control.hpp. Shared by probe-check (the centres against it), probe (the lines fitted
// against it) and ballbar5x-run (the simulated control's program).
kin::FiveAxisMachine control_machine(const mdl::Model& m, const std::string& model,
                                     const std::string& hal, const std::string& swivel) {
  kin::FiveAxisMachine control = mdl::five_axis(m);
  if (!hal.empty() && !swivel.empty())
    throw cal::InputError("--hal and --swivel: give one control's kinematics");
  const std::string& correction = hal.empty() ? swivel : hal;
  try {
    if (!hal.empty())
      control = kin::trt_control_machine(
          kin::parse_linuxcnc_trt_hal(read_text(hal, "HAL file"), hal), control);
    if (!swivel.empty())
      control = kin::swivel_control_machine(
          kin::parse_sinumerik_swivel_program(read_text(swivel, "swivel data"), swivel), control);
  } catch (const cal::InputError& e) {
    throw cal::InputError(fmt::format("{} with {}: {}", correction, model, e.what()));
  }
  return control;
}

void add_probe_fit_options(CLI::App& cmd, ProbeFitOptions& o, const ProbeFitHelp& help) {
  cmd.add_option("centres", o.centres, help.centres)->required();
  auto* model = cmd.add_option("--model", o.model,
                               help.model + "; or a stored model's UUID or number with --db");
  if (help.model_required) model->required();
  add_model_db_option(cmd, o.db);
  cmd.add_option("--probe-u-um", o.probe_u_um, help.probe_u)->check(finite_in(0.0, 1e4));
  cmd.add_option("--write", o.write,
                 "Write the model with the fitted location errors (and their uncertainty and "
                 "source) to this file");
  cmd.add_flag("--keep-linear-errors", o.keep_linear, help.keep_linear);
  cmd.add_flag("--json", o.json, help.json);
}

ProbeSimModels read_probe_sim_models(ProbeSimOptions& o) {
  auto models = read_truth_control(o);
  o.truth = models.truth.label;
  if (models.control) o.control = models.control->label;
  auto machine = mdl::five_axis(models.truth.model);
  auto control =
      models.control ? mdl::five_axis(models.control->model) : kin::nominal_kinematics(machine);
  return {std::move(models.truth.model), std::move(machine), std::move(control)};
}

void add_probe_sim_options(CLI::App& cmd, ProbeSimOptions& o, const std::string& control_help) {
  add_truth_control_options(cmd, o, {.control = control_help});
  cmd.add_option("--sphere-mm", o.sphere_mm, "Sphere centre on the workpiece X Y Z (home)")
      ->required()
      ->expected(3)
      ->check(finite_in(-kMaxPositionMm, kMaxPositionMm));
  cmd.add_option("--noise-um", o.noise_um,
                 "Gaussian noise per coordinate of each centre, standard deviation")
      ->check(finite_in(0.0, 1e4));
  cmd.add_option("--seed", o.seed, "Seed of the noise")->capture_default_str();
  cmd.add_option("-o,--output", o.output, "Write the CSV here (default: standard output)");
}

void put_location_fit(mdl::RotaryEntry& r, const kin::AxisLineFit& f, const json& source) {
  const std::size_t own = kin::direction_index(f.letter);
  std::size_t n = 0;
  for (std::size_t slot = 0; slot < 6; ++slot) {
    if (slot % 3 == own) continue;
    const bool pos = slot < 3;
    (pos ? r.axis.location_position_um[slot] : r.axis.location_orientation_urad[slot - 3]) =
        pos ? f.position_um[slot] : f.orientation_urad[slot - 3];
    const double u = pos ? f.position_u_um[slot] : f.orientation_u_urad[slot - 3];
    auto& e = r.location[n++];
    e.given = true;
    e.uncertainty = std::isnan(u) ? std::optional<double>{} : std::optional<double>{u};
    e.source = {source.dump()};
  }
}

void add_model_probe_commands(CLI::App& model) {
  const auto [probe, p] = add_command<ProbeOptions>(
      model, "probe", run_probe,
      "Fit each rotary axis's average line (table or head) to probed sphere centres (a CSV: "
      "axis, angle_deg, x_mm, y_mm, z_mm): its location errors with their uncertainty and the "
      "residuals");
  add_probe_fit_options(
      *probe, *p,
      {.centres = "CSV of probed centres in machine coordinates: angle_deg, x_mm, y_mm, z_mm, "
                  "and axis (A, B or C) unless --axis is given",
       .model = "Model file (caldaq.model.v2) giving each rotary axis's nominal pivot; for a head "
                "axis also the control's kinematics that computed the centres",
       .probe_u = "Standard uncertainty of one probed centre per coordinate (0: from the "
                  "residuals, needs 4 or more angles)",
       .keep_linear = "Fit the centres as probed, even when --model holds linear-axis errors (by "
                      "default those are removed from each centre first)",
       .json = "Print caldaq.axis-line-fit.v1 JSON"});
  probe
      ->add_option("--axis", p->axis,
                   "The rotary axis of every centre (the file has no axis column)")
      ->check(CLI::IsMember({"A", "B", "C", "a", "b", "c"}));
  probe->add_option("--pivot-mm", p->pivot_mm, "Nominal pivot X Y Z (with --axis, no --model)")
      ->expected(3)
      ->check(finite_in(-kMaxPositionMm, kMaxPositionMm));
  probe->add_option("--hal", p->hal,
                    "Fit against the control holding these LinuxCNC trunnion pins (--model the "
                    "nominal machine): the location errors the correction left");
  probe->add_option("--swivel", p->swivel,
                    "Fit against the control holding this SINUMERIK CYCLE800 swivel data record "
                    "(--model the nominal machine): the location errors the correction left");

  const auto [check, c] = add_command<CheckOptions>(
      model, "probe-check", run_probe_check,
      "Compare probed sphere centres with where the control's kinematics expects them (the "
      "model's, LinuxCNC trunnion pins from --hal or a SINUMERIK swivel data record from "
      "--swivel): the residual before and after a correction");
  check->add_option("centres", c->centres, "CSV of probed centres, as for daq model probe")
      ->required();
  check
      ->add_option("--model", c->model,
                   "Model file, or a stored model's UUID or number with --db: the machine as the "
                   "control believes it")
      ->required();
  add_model_db_option(*check, c->db);
  check->add_option("--hal", c->hal,
                    "HAL file of xyzac-trt-kins / xyzbc-trt-kins pivot pins (setp lines, as daq "
                    "model kinematics writes them): the control's rotary axes on those lines");
  check->add_option("--swivel", c->swivel,
                    "SINUMERIK CYCLE800 swivel data record ($TC_CARR assignments, as daq model "
                    "kinematics -f sinumerik-cycle800 writes them): the control's table axes on "
                    "its lines");
  check->add_option("--axis", c->axis, "The rotary axis of every centre (no axis column)")
      ->check(CLI::IsMember({"A", "B", "C", "a", "b", "c"}));
  check->add_flag("--json", c->json, "Print caldaq.probe-check.v1 JSON");

  const auto [sim, s] = add_command<SimOptions>(
      model, "probe-sim", run_probe_sim,
      "Simulated touch probe: the sphere centres a model (the simulated machine's truth) reports "
      "at the given angles of one rotary axis (table or head), the other at 0, as a CSV for daq "
      "model probe");
  add_probe_sim_options(*sim, *s,
                        "Model file of the control's kinematics that reports the centres (a head "
                        "axis's centres are where it puts the turned probe tip; default: the "
                        "truth's nominal kinematics)");
  sim->add_option("--axis", s->axis, "The rotary axis turned (table or head)")
      ->required()
      ->check(CLI::IsMember({"A", "B", "C", "a", "b", "c"}));
  sim->add_option("--angles-deg", s->angles_deg, "Angles of the axis at which to probe")
      ->required()
      ->check(finite_in(-3600.0, 3600.0));
}

}  // namespace daq
