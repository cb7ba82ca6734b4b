// daq model show | map: the machine model file (caldaq.model.v1/v2) and its volumetric error
// (with rotary axes: cmd_model_rotary.cpp).
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "cal/analysis/error.hpp"
#include "cli_checks.hpp"
#include "command.hpp"
#include "commands.hpp"
#include "csv_columns.hpp"
#include "model_cli.hpp"
#include "output_file.hpp"
#include "terminal.hpp"

namespace daq {

json vec_json(const kin::Vec3& v) { return json::array({v[0], v[1], v[2]}); }

json grid_json(const kin::Grid& g) {
  return {{"min_mm", vec_json(g.min_mm)},
          {"max_mm", vec_json(g.max_mm)},
          {"count", {g.count[0], g.count[1], g.count[2]}}};
}

namespace {
constexpr std::array kAxis{"X", "Y", "Z"};
}

std::string describe_topology(kin::Topology t) {
  const auto order = kin::chain_order(t);
  const int k = kin::workpiece_side_axes(t);
  std::string chain = "workpiece";
  for (int n = k - 1; n >= 0; --n) chain += fmt::format(" <- {}", kAxis[order[n]]);
  chain += " <- F";
  for (int n = k; n < 3; ++n) chain += fmt::format(" -> {}", kAxis[order[n]]);
  chain += " -> tool";
  std::string table_axes, tool_axes;
  for (int n = 0; n < 3; ++n) {
    std::string& side = n < k ? table_axes : tool_axes;
    side += (side.empty() ? "" : ", ") + std::string(kAxis[order[n]]);
  }
  return fmt::format("{}: {} ({} moving the workpiece, {} moving the tool)", kin::to_string(t),
                     chain, table_axes.empty() ? "no axis" : table_axes,
                     tool_axes.empty() ? "no axis" : tool_axes);
}

// An error's source (the model file's free-form JSON object) as words for the page: a run that
// daq model build took it from as "run 3 (roll, 2026-11-28T15:53:53Z); stationary axes at (200,
// 240, 180) mm; probe offset (0, 0, -100) mm; relative to the first target", other keys as "key:
// value" (it printed every key, "kind: run; measure: roll; probe_offset_mm: 0.0, 0.0, -100.0;
// run_id: 3; ..."); the terminal and anything not an object keep the text as stored.
static std::string source_words(const std::string& source, bool html) {
  const auto j = json::parse(source, nullptr, false);
  if (!html || !j.is_object()) return source;
  const auto text = [](const json& value) {
    std::string v;
    if (value.is_string()) return value.get<std::string>();
    if (!value.is_array()) return value.dump();
    for (const auto& x : value)
      v += (v.empty() ? "" : ", ") + (x.is_string()   ? x.get<std::string>()
                                      : x.is_number() ? fmt::format("{:g}", x.get<double>())
                                                      : x.dump());
    return v;
  };
  std::vector<std::string> parts;
  std::set<std::string> said;
  const auto say = [&](const char* key, const std::string& words) {
    if (!j.contains(key)) return;
    parts.push_back(words);
    said.insert(key);
  };
  const std::string kind = j.value("kind", "");
  if (kind == "run" && j.contains("run_id")) {
    std::string what = "run " + text(j["run_id"]);
    std::string detail;
    if (j.contains("measure")) detail = text(j["measure"]);
    if (j.contains("started_utc")) detail += (detail.empty() ? "" : ", ") + text(j["started_utc"]);
    parts.push_back(detail.empty() ? what : what + " (" + detail + ")");
    said.insert({"kind", "run_id", "measure", "started_utc"});
  } else if (kind == "runs" && j.contains("run_ids")) {
    parts.push_back("runs " + text(j["run_ids"]));
    said.insert({"kind", "run_ids"});
  }
  if (j.contains("stationary_mm"))
    say("stationary_mm", "stationary axes at (" + text(j["stationary_mm"]) + ") mm");
  if (j.contains("probe_offset_mm"))
    say("probe_offset_mm", "probe offset (" + text(j["probe_offset_mm"]) + ") mm");
  if (j.contains("treatment")) say("treatment", text(j["treatment"]));
  if (j.contains("from")) say("from", text(j["from"]));
  for (const auto& [key, value] : j.items())
    if (!said.count(key)) parts.push_back(key + ": " + text(value));
  return fmt::format("{}", fmt::join(parts, "; "));
}

std::vector<std::vector<std::string>> describe_components(const mdl::Model& m, bool html) {
  const char* um_unit = html ? "µm" : "um";
  const char* urad_unit = html ? "µrad" : "urad";
  const char* over_90 = html ? "µm/m over 90°" : "um/m over 90 deg";
  std::vector<std::vector<std::string>> rows;
  for (kin::Component c : kin::all_components()) {
    const auto& f = kin::component(m.machine, c);
    const auto& entry = m.components[static_cast<std::size_t>(c)];
    const auto axis = static_cast<std::size_t>(c) / 6;
    const bool angle = static_cast<std::size_t>(c) % 6 >= 3;
    const char* unit = angle ? urad_unit : um_unit;
    std::string form, values;
    if (!entry.given && f.is_zero()) {
      form = "not given (zero)";
    } else if (f.is_table()) {
      const auto q = f.positions_mm();
      const auto v = f.values();
      form = fmt::format("table, {} points, {:g} .. {:g} mm", q.size(), q.front(), q.back());
      values = fmt::format("{:.3f} .. {:.3f} {}", *std::min_element(v.begin(), v.end()),
                           *std::max_element(v.begin(), v.end()), unit);
    } else {
      form = fmt::format("polynomial, degree {}",
                         std::max<std::size_t>(f.coefficients().size(), 1) - 1);
      if (m.travel_mm) {
        double lo = INFINITY, hi = -INFINITY;
        const auto [a, b] = (*m.travel_mm)[axis];
        for (int i = 0; i <= 100; ++i) {
          const double v = f(a + (b - a) * i / 100.0);
          lo = std::min(lo, v), hi = std::max(hi, v);
        }
        values = fmt::format("{:.3f} .. {:.3f} {} over the travel", lo, hi, unit);
      } else {
        values = fmt::format("{:.3f} {} at 0", f(0.0), unit);
      }
    }
    rows.push_back(
        {std::string(kin::to_string(c)), form, values, source_words(entry.source.json, html)});
  }
  for (kin::Plane p : {kin::Plane::xy, kin::Plane::xz, kin::Plane::yz}) {
    const auto& s = m.squareness[static_cast<std::size_t>(p)];
    const double v = m.machine.squareness.of(p);
    std::string form =
        s.given ? fmt::format("squareness, stated as {}", s.stated_as) : "not given (zero)";
    std::string how;
    if (!s.method.empty()) how += ", " + s.method;
    if (!s.placement.empty()) how += ", " + s.placement;
    if (s.position_mm)
      how += fmt::format(" at ({:g}, {:g}, {:g}) mm", (*s.position_mm)[0], (*s.position_mm)[1],
                         (*s.position_mm)[2]);
    rows.push_back({std::string(kin::location_error_name(p)), form + how,
                    fmt::format("{:+.3f} {} ({:+.3f} {}), carried by {}", v, urad_unit,
                                kin::angle_over_90_from_location_error(p, v), over_90,
                                kAxis[m.carriers.of(p)]),
                    source_words(s.source.json, html)});
  }
  return rows;
}

cal::daq::report::ModelPage model_page_of(const mdl::Model& m, const std::string& path,
                                          const kin::Grid& g, kin::Method method) {
  cal::daq::report::ModelPage page;
  page.title = m.name;
  page.source = path;
  // Stored in the model's provenance (by daq model build, from the runs' origins); a file
  // without it (written before, or by hand) by its name, as before.
  page.origin = model_origin(m);
  page.simulated = page.origin.find("SIMULATED") != std::string::npos ||
                   m.name.find("simulated") != std::string::npos ||
                   m.name.find("SIMULATED") != std::string::npos;
  page.machine = m.machine;
  page.grid = g;
  page.method = method;
  page.facts = {
      {"topology", describe_topology(m.machine.topology)},
      {"tool offset", fmt::format("({:g}, {:g}, {:g}) mm", m.machine.tool_offset_mm[0],
                                  m.machine.tool_offset_mm[1], m.machine.tool_offset_mm[2])},
      {"table offset", fmt::format("({:g}, {:g}, {:g}) mm", m.machine.table_offset_mm[0],
                                   m.machine.table_offset_mm[1], m.machine.table_offset_mm[2])}};
  page.origins = model_origin_parts(m);
  if (!page.origin.empty())
    page.facts.push_back(
        {"origin",
         page.origin + (page.origin == "MIXED" ? " (the model's provenance: some errors were not "
                                                 "measured on the machine)"
                                               : " (the model's provenance: not a real machine)")});
  for (auto& r : describe_components(m, true)) page.components.push_back(std::move(r));
  page.software = "daq 0.1.0";
  return page;
}

namespace {

// An origin's label as it may be printed into a controller file: capitals, commas and spaces.
std::string label_text(const std::string& s) {
  std::string out;
  for (const char c : s)
    if ((c >= 'A' && c <= 'Z') || c == ',' || c == ' ') out += c;
  return out.substr(0, 40);
}

}  // namespace

std::string model_origin(const mdl::Model& m) {
  if (m.provenance.json.empty()) return "";
  const auto j = json::parse(m.provenance.json, nullptr, false);
  if (!j.is_object() || !j.contains("origin") || !j["origin"].is_string()) return "";
  return label_text(j["origin"].get<std::string>());
}

std::map<std::string, std::string> model_origin_parts(const mdl::Model& m) {
  std::map<std::string, std::string> parts;
  if (m.provenance.json.empty()) return parts;
  const auto j = json::parse(m.provenance.json, nullptr, false);
  if (!j.is_object() || !j.contains("origins") || !j["origins"].is_object()) return parts;
  for (const auto& [name, label] : j["origins"].items()) {
    if (!label.is_string()) continue;
    std::string error;  // an error's name: E_XX, E_C0Y
    for (const char c : name)
      if (std::isalnum(static_cast<unsigned char>(c)) || c == '_') error += c;
    if (const auto l = label_text(label.get<std::string>()); !error.empty() && !l.empty())
      parts[error.substr(0, 16)] = l;
  }
  return parts;
}

kin::Method method_from_string(const std::string& s) {
  if (s == "htm" || s == "exact") return kin::Method::htm;
  if (s == "first-order" || s == "first_order") return kin::Method::first_order;
  throw cal::InputError(fmt::format("method '{}' (expected htm or first-order)", s));
}

std::string method_name(kin::Method method) {
  return method == kin::Method::htm ? "htm" : "first-order";
}

json map_json_head(std::string_view schema, const std::string& file, kin::Method method) {
  return {{"schema", schema}, {"model", file}, {"method", method_name(method)}};
}

namespace {

// --- show ------------------------------------------------------------------------------------

struct ShowOptions {
  std::string file, db;
  bool json = false;
};

// A rotary axis of a v2 model: where it is, its location errors (with their uncertainty) and
// its component errors over its range.
void print_rotary(const mdl::RotaryEntry& r) {
  const auto& a = r.axis;
  print_line("Rotary axis {} ({} side): pivot ({:g}, {:g}, {:g}) mm, range {:g} .. {:g} deg",
             kin::to_string(a.letter), kin::to_string(a.side), a.pivot_mm[0], a.pivot_mm[1],
             a.pivot_mm[2], r.range_deg[0], r.range_deg[1]);
  const auto names = kin::location_error_names(a.letter);
  const std::size_t own = kin::direction_index(a.letter);
  std::size_t n = 0;
  for (std::size_t slot = 0; slot < 6; ++slot) {
    if (slot % 3 == own) continue;
    const double v =
        slot < 3 ? a.location_position_um[slot] : a.location_orientation_urad[slot - 3];
    const auto& e = r.location[n];
    const char* unit = slot < 3 ? "um" : "urad";
    print_line("  {:6} {:44} {:+.3f} {}{}", names[n],
               e.given ? "location error" : "not given (zero)", v, unit,
               e.uncertainty ? fmt::format(" (u = {:.3f} {})", *e.uncertainty, unit) : "");
    ++n;
  }
  for (std::size_t d = 0; d < 6; ++d) {
    const auto name = mdl::rotary_component_name(a.letter, d);
    const auto& f = mdl::rotary_component(a, d);
    if (!r.components[d].given) continue;
    double lo = INFINITY, hi = -INFINITY;
    for (int i = 0; i <= 100; ++i) {
      const double v = f(r.range_deg[0] + (r.range_deg[1] - r.range_deg[0]) * i / 100.0);
      lo = std::min(lo, v), hi = std::max(hi, v);
    }
    print_line("  {:6} {:44} {:.3f} .. {:.3f} {} over the range", name,
               f.is_table() ? fmt::format("table, {} points", f.positions_mm().size())
                            : "polynomial in the angle (deg)",
               lo, hi, d < 3 ? "um" : "urad");
  }
}

void run_show(const ShowOptions& o) {
  const auto in = read_model_input(o.file, o.db);
  const mdl::Model& m = in.model;
  if (o.json) return fmt::print("{}", mdl::to_json(m));
  print_line("Model {}{}", m.name.empty() ? "(unnamed)" : m.name, " (" + in.label + ")");
  if (const auto origin = model_origin(m); !origin.empty()) {
    print_line("  {}: not measured on a real machine (the model's provenance)", origin);
    if (origin == "MIXED")
      for (const auto& [name, label] : model_origin_parts(m))
        print_line("    {} from a {} run", name, label);
  }
  print_line("  topology      {}", describe_topology(m.machine.topology));
  const auto& t = m.machine.tool_offset_mm;
  const auto& w = m.machine.table_offset_mm;
  fmt::print("  tool offset   ({:g}, {:g}, {:g}) mm\n  table offset  ({:g}, {:g}, {:g}) mm\n", t[0],
             t[1], t[2], w[0], w[1], w[2]);
  if (m.travel_mm)
    print_line("  travel        X {:g} .. {:g}, Y {:g} .. {:g}, Z {:g} .. {:g} mm",
               (*m.travel_mm)[0][0], (*m.travel_mm)[0][1], (*m.travel_mm)[1][0],
               (*m.travel_mm)[1][1], (*m.travel_mm)[2][0], (*m.travel_mm)[2][1]);
  else
    print_line("  travel        not given (maps need --min-mm and --max-mm)");
  print_line("Errors (translations in um, angles in urad):");
  std::vector<std::string> missing;
  for (const auto& r : describe_components(m, false)) {
    print_line("  {:6} {:44} {}", r[0], r[1], r[2]);
    if (r[1].rfind("not given", 0) == 0) missing.push_back(r[0]);
  }
  if (!missing.empty())
    print_line("Not given ({} of 21, taken as zero): {}", missing.size(), fmt::join(missing, ", "));
  for (const auto& r : m.rotary) print_rotary(r);
}

// --- map -------------------------------------------------------------------------------------

struct MapOptions {
  std::string file, db, points, report, method = "htm";
  std::vector<double> min_mm, max_mm;
  std::vector<std::size_t> count{5, 5, 5};
  std::size_t angle_count = 5;
  bool json = false;
};

// The map, its 21 contributions and its JSON are held in memory: a few million points at most.
constexpr double kMaxMapPoints = 2e6;

kin::Grid grid_of(const MapOptions& o, const mdl::Model& m) {
  if (o.count.size() != 3 ||
      std::any_of(o.count.begin(), o.count.end(), [](auto c) { return c == 0; }))
    throw cal::InputError("--count needs three counts >= 1 (X Y Z)");
  if (static_cast<double>(o.count[0]) * static_cast<double>(o.count[1]) *
          static_cast<double>(o.count[2]) >
      kMaxMapPoints)
    throw cal::InputError(fmt::format("--count {} {} {}: more than {:g} points", o.count[0],
                                      o.count[1], o.count[2], kMaxMapPoints));
  if (o.min_mm.empty() != o.max_mm.empty())
    throw cal::InputError("give both --min-mm and --max-mm, or neither (the model's travel)");
  if (o.min_mm.empty()) return mdl::travel_grid(m, {o.count[0], o.count[1], o.count[2]});
  kin::Grid g;
  for (std::size_t i = 0; i < 3; ++i) {
    g.min_mm[i] = o.min_mm.at(i);
    g.max_mm[i] = o.max_mm.at(i);
    g.count[i] = o.count[i];
  }
  return g;
}

void run_map(const MapOptions& o) {
  const auto in = read_model_input(o.file, o.db);
  const mdl::Model& m = in.model;
  const std::string& file = in.label;  // the file, or the stored model
  const kin::Method method = method_from_string(o.method);
  if (!m.rotary.empty()) {
    if (!o.report.empty())
      throw cal::InputError(fmt::format(
          "{}: rotary: --report does not draw a model with rotary axes yet (use --json)", file));
    if (!o.points.empty() && !o.min_mm.empty())
      throw cal::InputError("--points maps the given poses: no grid options with it");
    FiveAxisMapRequest q{file, o.points, {}, o.angle_count, method, o.json};
    if (o.points.empty()) q.grid = grid_of(o, m);
    return run_five_axis_map(m, q);
  }
  if (!o.points.empty()) {
    if (!o.min_mm.empty() || !o.report.empty())
      throw cal::InputError("--points maps the given points: no grid options or --report with it");
    const auto csv = read_csv_columns(o.points, {"x_mm", "y_mm", "z_mm"});
    json pts = json::array();
    if (!o.json)
      fmt::print("{:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10}\n", "x_mm", "y_mm", "z_mm",
                 "ex_um", "ey_um", "ez_um", "|e|_um");
    for (std::size_t r = 0; r < csv.rows(); ++r) {
      const kin::Vec3 p{csv.numbers.at("x_mm")[r], csv.numbers.at("y_mm")[r],
                        csv.numbers.at("z_mm")[r]};
      kin::VolumetricError e;
      try {
        e = kin::volumetric_error(m.machine, p, method);
      } catch (const cal::InputError& err) {
        throw cal::InputError(fmt::format("{}:{}: {}", o.points, csv.line[r], err.what()));
      }
      const auto& t = e.translation_um;
      require_finite(
          std::array{t[0], t[1], t[2], e.rotation_urad[0], e.rotation_urad[1], e.rotation_urad[2]},
          fmt::format("{}:{}: the error at ({}, {}, {}) mm", o.points, csv.line[r], p[0], p[1],
                      p[2]));
      if (o.json)
        pts.push_back({{"position_mm", vec_json(p)},
                       {"error_um", vec_json(t)},
                       {"rotation_urad", vec_json(e.rotation_urad)}});
      else
        fmt::print("{:>10} {:>10} {:>10} {:>10} {:>10} {:>10} {:10.3f}\n", fixed_text(p[0], 3),
                   fixed_text(p[1], 3), fixed_text(p[2], 3), fixed_text(t[0], 3),
                   fixed_text(t[1], 3), fixed_text(t[2], 3),
                   std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]));
    }
    if (o.json) {
      auto j = map_json_head("caldaq.volumetric-map.v1", file, method);
      j["points"] = std::move(pts);
      fmt::print("{}\n", j.dump(2));
    }
    return;
  }
  const kin::Grid g = grid_of(o, m);
  const auto mapped = mdl::model_map(m, g, method);
  const auto& s = mapped.summary;
  const auto& contributions = mapped.contributions;
  if (!o.report.empty())
    write_report_page(o.report, cal::daq::report::model_page(model_page_of(m, file, g, method)));
  if (o.json) {
    auto j = map_json_head("caldaq.volumetric-map.v1", file, method);
    j.update(mdl::model_map_json(mapped, true));
    fmt::print("{}\n", j.dump(2));
    return;
  }
  fmt::print(
      "Volumetric error of {} ({} model), {} x {} x {} points over ({:g} .. {:g}, {:g} .. "
      "{:g}, {:g} .. {:g}) mm\n",
      m.name.empty() ? file : m.name, method_name(method), g.count[0], g.count[1], g.count[2],
      g.min_mm[0], g.max_mm[0], g.min_mm[1], g.max_mm[1], g.min_mm[2], g.max_mm[2]);
  fmt::print("  largest |e|  {:.3f} um at ({:g}, {:g}, {:g}) mm\n", s.max_norm_um,
             s.max_norm_at_mm[0], s.max_norm_at_mm[1], s.max_norm_at_mm[2]);
  for (std::size_t i = 0; i < 3; ++i)
    fmt::print("  e{}  {:>9} .. {:>9} um (range {:.3f})\n", static_cast<char>('x' + i),
               fixed_text(s.min_um[i], 3), fixed_text(s.max_um[i], 3), s.range_um[i]);
  fmt::print("Contributions, ranked (largest |e| of each error alone, first order):\n");
  for (std::size_t k = 0; k < contributions.size(); ++k) {
    const auto& c = contributions[k];
    if (c.max_norm_um == 0.0) break;
    fmt::print("  {:2}. {:6} {:9.3f} um  (RMS {:.3f})\n", k + 1, c.name, c.max_norm_um, c.rms_um);
  }
}

}  // namespace

void add_model_commands(CLI::App& app) {
  auto* model =
      add_group(app, "model",
                "The machine model (caldaq.model.v1, v2 with rotary axes): show it, map its error, "
                "write a compensation, predict a test piece, probe and correct rotary axes");

  const auto [show, s] = add_command<ShowOptions>(
      *model, "show", run_show, "Print a model file: chain, offsets, the 21 errors");
  show->add_option("file", s->file, "Model file (caldaq.model.v1 JSON, docs/model-file.md)")
      ->required();
  show->add_flag("--json", s->json, "Print the model as normalised caldaq.model.v1 JSON");
  add_model_db_option(*show, s->db);

  const auto [map, o] = add_command<MapOptions>(
      *model, "map", run_map,
      "Volumetric error over a grid (default: the model's travel, 5 x 5 x 5) or at points; "
      "with rotary axes (caldaq.model.v2) the tool tip's position and orientation error over "
      "the travel and the rotary range");
  map->add_option("file", o->file, "Model file")->required();
  map->add_option("--min-mm", o->min_mm, "Grid corner X Y Z (with --max-mm)")
      ->expected(3)
      ->check(finite_in(-kMaxPositionMm, kMaxPositionMm));
  map->add_option("--max-mm", o->max_mm, "Grid corner X Y Z")
      ->expected(3)
      ->check(finite_in(-kMaxPositionMm, kMaxPositionMm));
  map->add_option("--count", o->count, "Points per axis X Y Z")->expected(3)->capture_default_str();
  map->add_option("--points", o->points,
                  "CSV of points to evaluate: x_mm,y_mm,z_mm (and with rotary axes one column "
                  "per axis: c_deg, a_deg, ...)");
  map->add_option("--angle-count", o->angle_count,
                  "With rotary axes: angles per rotary axis over its range_deg")
      ->capture_default_str()
      ->check(whole_in(1, 1000));
  map->add_option("--method", o->method, "htm (exact) or first-order")->capture_default_str();
  map->add_option("--report", o->report,
                  "Also write an HTML page: error vectors in three slices, contributions ranked");
  map->add_flag("--json", o->json, "Print caldaq.volumetric-map.v1 JSON");
  add_model_db_option(*map, o->db);

  add_model_build_command(*model);
  add_model_store_commands(*model);
  add_model_compare_command(*model);
  add_model_compensate_command(*model);
  add_model_testpiece_command(*model);
  add_model_probe_commands(*model);
  add_model_probe_poses_command(*model);
  add_model_ballbar5x_commands(*model);
  add_model_kinematics_command(*model);
}

}  // namespace daq
