// daq model compensate: the model's compensation in a controller's format, with what it leaves.
#include <fmt/format.h>
#include <fmt/ranges.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>

#include "cal/analysis/comp_formats.hpp"
#include "cal/analysis/comp_meaning.hpp"
#include "cal/analysis/comp_read.hpp"
#include "cal/analysis/error.hpp"
#include "cal/analysis/volumetric_comp.hpp"
#include "cal/storage/store.hpp"
#include "command.hpp"
#include "compensation/compensation_check.hpp"
#include "database.hpp"
#include "model_cli.hpp"
#include "output_file.hpp"
#include "provenance.hpp"

namespace daq {
namespace {

namespace vc = cal::volcomp;
namespace ct = cal::comptable;

constexpr std::array kAxis{"X", "Y", "Z"};
constexpr double kResolutionMm = 0.0001;  // what the writers keep: 0.1 um

struct Options {
  std::string file, format = "csv", output, output_dir, report, isg_csv_path = "volcomp.csv";
  std::string db, machine;  // --machine: stored with that machine for daq verify
  std::vector<double> interval_mm, reference_mm;
  std::vector<int> axis_numbers{1, 2, 3};
  std::optional<double> fanuc_reference_mm;  // default: the start of each travel
  double fanuc_unit_um = 1.0;
  int fanuc_first_point = 0, fanuc_magnification = 1;
  bool json = false;
};

std::array<vc::AxisGrid, 3> grid_of(const Options& o, const mdl::Model& m) {
  if (!m.travel_mm)
    throw cal::InputError(
        fmt::format("{}: the model has no travel_mm: the tables need it", o.file));
  if (o.interval_mm.size() != 3)
    throw cal::InputError("--interval-mm needs three intervals (X Y Z)");
  std::array<vc::AxisGrid, 3> g;
  for (std::size_t i = 0; i < 3; ++i) {
    const auto [lo, hi] = (*m.travel_mm)[i];
    const double iv = o.interval_mm[i];
    if (!(iv > 0) || !std::isfinite(iv))
      throw cal::InputError(fmt::format("--interval-mm {}: {} is not > 0", kAxis[i], iv));
    const double steps = (hi - lo) / iv;
    if (steps > 100000)
      throw cal::InputError(
          fmt::format("--interval-mm {}: {:g} mm gives more than 100000 points "
                      "over the travel",
                      kAxis[i], iv));
    if (std::abs(steps - std::round(steps)) > 1e-6 * std::max(1.0, steps))
      throw cal::InputError(
          fmt::format("--interval-mm {}: the travel {:g} .. {:g} mm is not a whole "
                      "number of {:g} mm intervals",
                      kAxis[i], lo, hi, iv));
    g[i] = {lo, iv, static_cast<int>(std::llround(steps)) + 1};
  }
  return g;
}

// Default reference: the grid point nearest the middle of each travel (the frozen product
// terms grow with the distance from it, so the middle halves the largest).
kin::Vec3 reference_of(const Options& o, const std::array<vc::AxisGrid, 3>& g) {
  if (!o.reference_mm.empty()) {
    if (o.reference_mm.size() != 3) throw cal::InputError("--reference-mm needs X Y Z");
    return {o.reference_mm[0], o.reference_mm[1], o.reference_mm[2]};
  }
  kin::Vec3 r{};
  for (std::size_t i = 0; i < 3; ++i)
    r[i] = g[i].start_mm + g[i].interval_mm * std::round((g[i].points - 1) / 2.0);
  return r;
}

std::map<std::string, int> numbers_of(const Options& o) {
  if (o.axis_numbers.size() != 3)
    throw cal::InputError("--axis-numbers needs three numbers (X Y Z)");
  return {{"X", o.axis_numbers[0]}, {"Y", o.axis_numbers[1]}, {"Z", o.axis_numbers[2]}};
}

// The tables as written: every value rounded to what the writers keep (0.1 um), and with
// own_only the cross tables left out (formats that correct an axis along itself only).
vc::CrossTables as_written(const vc::CrossTables& t, bool own_only) {
  vc::CrossTables w = t;
  for (auto& table : w.tables)
    for (auto& um : table.correction_um)
      um = (own_only && table.input != table.output)
               ? 0.0
               : std::round(um * 1e-3 / kResolutionMm) * kResolutionMm * 1e3;
  return w;
}

// FANUC's own-axis tables as the control applies them: the steps summed from the reference
// position (zero there: the correction's constant at the reference position is not in the
// table), rounded to the detection unit (comp_formats.hpp, fanuc_applied).
vc::CrossTables fanuc_as_written(const vc::CrossTables& t,
                                 const std::array<ct::FanucOptions, 3>& f) {
  vc::CrossTables w = as_written(t, true);
  for (std::size_t a = 0; a < 3; ++a) {
    const auto axis = static_cast<kin::Axis>(a);
    const auto applied =
        ct::fanuc_applied(ct::own_axis_table(t, axis, kResolutionMm), f[a]).forward_um;
    auto& table = w.tables.at(3 * a + a);
    table.correction_um = applied;
  }
  return w;
}

struct Written {
  std::vector<std::pair<std::string, std::string>> files;    // name, text
  std::string what;                                          // the compensation, in words
  std::vector<std::string> notes;                            // what it leaves out
  std::function<kin::Vec3(const kin::Vec3&)> correction_um;  // what the control adds
};

Written write_format(const Options& o, const mdl::Model& m, const std::array<vc::AxisGrid, 3>& g,
                     const vc::CrossTables& tables) {
  Written w;
  // What the written files add at p (um): computed from the values as written, so that the
  // residual is what the files leave (rounding, FANUC's reference, what a format cannot hold).
  const auto all = [w = as_written(tables, false)](const kin::Vec3& p) {
    return vc::table_correction_um(w, p);
  };
  const auto own = [w = as_written(tables, true)](const kin::Vec3& p) {
    return vc::table_correction_um(w, p);
  };
  const auto numbers = numbers_of(o);
  const std::string frozen = fmt::format(
      "One-dimensional tables cannot hold the products of an angular error with the travel of an "
      "axis it carries: they are frozen at the reference position ({:g}, {:g}, {:g}) mm and "
      "what remains grows with the distance from it.",
      tables.reference_mm[0], tables.reference_mm[1], tables.reference_mm[2]);
  const auto nonzero = ct::from_model(tables, kResolutionMm, true);
  if (o.format == "csv") {
    const auto every = ct::from_model(tables, kResolutionMm, false);
    w.files.push_back({"", ct::write_cross_csv(every)});
    w.what = "the nine cross-axis tables (caldaq CSV)";
    w.correction_um = all;
    w.notes.push_back(frozen);
  } else if (o.format == "siemens-cec") {
    w.files.push_back({"", ct::write_sinumerik_cec(nonzero, numbers)});
    w.what = fmt::format("SINUMERIK CEC, {} tables", nonzero.size());
    w.correction_um = all;
    w.notes.push_back(frozen);
  } else if (o.format == "isg-cross") {
    for (std::size_t out = 0; out < 3; ++out) {
      std::vector<const ct::CrossAxisTable*> masters;
      for (const auto& t : nonzero)
        if (t.output == kAxis[out] && t.input != t.output) masters.push_back(&t);
      if (masters.size() > 1)
        throw cal::InputError(fmt::format(
            "axis {} is corrected as a function of {} and {}: ISG cross compensation takes one "
            "master axis per list (kw.crosscomp.master_ax_nr); use -f isg-volumetric, which "
            "takes the whole model",
            kAxis[out], masters[0]->input, masters[1]->input));
      if (masters.size() == 1)
        w.files.push_back({fmt::format("crosscomp_{}.lis", kAxis[out]),
                           ct::write_isg_cross(*masters[0], numbers.at(kAxis[out]),
                                               numbers.at(masters[0]->input))});
      ct::Table pitch = ct::own_axis_table(tables, static_cast<kin::Axis>(out), kResolutionMm,
                                           ct::format_meaning("isg").written);
      w.files.push_back({fmt::format("ssfk_{}.lis", kAxis[out]), ct::write_isg(pitch)});
    }
    w.what = "ISG cross compensation lists and leadscrew error compensation lists";
    w.correction_um = all;
    w.notes.push_back(frozen);
  } else if (o.format == "isg-volumetric") {
    w.files.push_back({"volcomp.lis",
                       ct::write_isg_volumetric_list(m.machine.topology, numbers, o.isg_csv_path)});
    w.files.push_back({"volcomp.csv", ct::write_isg_volumetric_csv(m.machine, g)});
    w.what = "ISG volumetric compensation (the whole model)";
    const auto carriers = m.carriers;
    const auto machine = m.machine;
    w.correction_um = [machine, carriers](const kin::Vec3& p) {
      return vc::correction_um(machine, p, carriers);
    };
    w.notes.push_back(
        "The residual assumes the control evaluates the same first-order model; ISG's "
        "documentation does not state its reference points for table-side axes (see "
        "docs/compensation-tables.md). The squareness goes to the control as the ISO 230-1 "
        "location errors: the carriers chosen in the model file do not apply.");
  } else if (o.format == "heidenhain") {
    std::vector<std::pair<std::string, std::string>> assigned;
    for (std::size_t in = 0; in < 3; ++in) {
      std::vector<ct::CrossAxisTable> same;
      for (const auto& t : nonzero)
        if (t.input == kAxis[in]) same.push_back(t);
      if (same.empty()) continue;
      const std::string name = fmt::format("{}.COM", kAxis[in]);
      w.files.push_back({name, ct::write_heidenhain_com(same)});
      assigned.emplace_back(kAxis[in], name);
    }
    // The input axis of each *.COM is named in the *.CMA, not in the *.COM.
    w.files.push_back({"config.cma", ct::write_heidenhain_cma(assigned)});
    w.what =
        "HEIDENHAIN nonlinear axis error compensation tables (*.COM, one per input axis, and "
        "their assignment config.cma)";
    w.correction_um = all;
    w.notes.push_back(frozen);
  } else if (o.format == "fanuc") {
    std::string text;
    std::array<ct::FanucOptions, 3> fanuc;
    for (std::size_t a = 0; a < 3; ++a) {
      ct::FanucOptions& fo = fanuc[a];
      fo.reference_mm = o.fanuc_reference_mm.value_or(g[a].start_mm);
      fo.first_point = o.fanuc_first_point;
      fo.detection_unit_um = o.fanuc_unit_um;
      fo.magnification = o.fanuc_magnification;
      text += ct::write_fanuc_pitch(
                  ct::own_axis_table(tables, static_cast<kin::Axis>(a), kResolutionMm), fo) +
              "\n";
    }
    w.files.push_back({"", text});
    w.what = "FANUC pitch error compensation of X, Y and Z";
    w.correction_um = [f = fanuc_as_written(tables, fanuc)](const kin::Vec3& p) {
      return vc::table_correction_um(f, p);
    };
    w.notes.push_back(
        "FANUC's table is zero at the reference position: the correction's value there is not "
        "in it and stays in the residual (shift the reference position by it, or choose the "
        "reference where the error is small).");
    w.notes.push_back(
        "Pitch error compensation corrects each axis along itself: straightness, "
        "squareness and the Abbe terms of other axes stay (they need cross-axis "
        "tables, which the public FANUC material found does not describe).");
  } else if (o.format == "linuxcnc") {
    for (std::size_t a = 0; a < 3; ++a) {
      ct::Table t = ct::own_axis_table(tables, static_cast<kin::Axis>(a), kResolutionMm);
      w.files.push_back({fmt::format("{}.comp", kAxis[a]), ct::write_linuxcnc(t)});
    }
    w.files.push_back(
        {"matrixkins.hal", ct::write_linuxcnc_matrixkins(m.machine.squareness, m.carriers)});
    kin::Machine squareness_only;
    squareness_only.squareness = m.machine.squareness;
    const auto carriers = m.carriers;
    w.correction_um = [own, squareness_only, carriers](const kin::Vec3& p) {
      const kin::Vec3 a = own(p), s = vc::correction_um(squareness_only, p, carriers);
      return kin::Vec3{a[0] + s[0], a[1] + s[1], a[2] + s[2]};
    };
    w.what = "LinuxCNC COMP_FILE per axis and matrixkins for the squareness";
    w.notes.push_back(
        "LinuxCNC documents no cross-axis table: straightness and the Abbe terms of "
        "other axes stay.");
  } else {
    throw cal::InputError(fmt::format(
        "format '{}' (expected csv, siemens-cec, isg-cross, isg-volumetric, heidenhain, fanuc or "
        "linuxcnc)",
        o.format));
  }
  return w;
}

// The controller functions a format's files are for (comp_meaning.hpp): what their values mean.
std::vector<const ct::FormatMeaning*> meanings_of(const std::string& format) {
  std::vector<const ct::FormatMeaning*> m{&ct::format_meaning(format)};
  if (format == "isg-cross") m.push_back(&ct::format_meaning("isg"));
  if (format == "linuxcnc") m.push_back(&ct::format_meaning("linuxcnc-matrixkins"));
  return m;
}

json meaning_json(const std::vector<const ct::FormatMeaning*>& meanings) {
  json j = json::array();
  for (const auto* m : meanings)
    j.push_back({{"function", m->name},
                 {"values", m->written == ct::Sign::error ? "error" : "correction"},
                 {"applied", m->applied},
                 {"reference", m->reference},
                 {"evidence", ct::to_string(m->evidence)},
                 {"source", m->source},
                 {"quote", m->quote}});
  return j;
}

void put(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  if (!(out << text) || !(out.close(), out))
    throw cal::InputError(fmt::format("{}: cannot write", path));
}

struct Extremes {
  double max_um = 0.0;
  kin::Vec3 at{};
};

Extremes largest(const std::array<vc::AxisGrid, 3>& g,
                 const std::function<kin::Vec3(const kin::Vec3&)>& f) {
  Extremes e;
  for (int k = 0; k < g[2].points; ++k)
    for (int j = 0; j < g[1].points; ++j)
      for (int i = 0; i < g[0].points; ++i) {
        const kin::Vec3 p{g[0].start_mm + g[0].interval_mm * i,
                          g[1].start_mm + g[1].interval_mm * j,
                          g[2].start_mm + g[2].interval_mm * k};
        const kin::Vec3 v = f(p);
        const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        if (n > e.max_um) e = {n, p};
      }
  return e;
}

// The comment that starts a line of a written file, where the format has one (nullopt: none;
// the command's output says what the file cannot). ISG's CSV parameter file: "Row comments
// start by a double slash" (Beckhoff Infosys TF5280, ISG CSV format), and a "#" line there is a
// file break, not a comment.
std::optional<std::string> comment_of(const std::string& format, const std::string& name,
                                      const std::string& text) {
  if (format == "fanuc") return "";  // a listing of parameters to enter, not a file to load
  if (text.starts_with("//")) return "// ";
  if (text.starts_with("#") || name.starts_with("ssfk_")) return "# ";
  if (text.starts_with(";") || text.starts_with("%_N_")) return "; ";
  return std::nullopt;
}

// A model not measured on real instruments says so at the top of every file that can hold it
// (for a mixed model, which errors came from where); the files that cannot are returned.
std::vector<std::string> say_origin(Written& w, const std::string& format,
                                    const std::string& origin,
                                    const std::map<std::string, std::string>& parts) {
  std::vector<std::string> silent;
  if (origin.empty()) return silent;
  const auto lines = daq::table_origin_lines(
      origin,
      origin == "MIXED" && !parts.empty()
          ? "the errors above came from runs not measured on real instruments (the model's "
            "provenance)"
          : "from a model built from runs not measured on real instruments (its provenance), "
            "not a model of a real machine",
      parts);
  for (auto& [name, text] : w.files) {
    const auto c = comment_of(format, name, text);
    if (!c) {
      silent.push_back(name.empty() ? "the table" : name);
      continue;
    }
    std::string header;
    for (const auto& l : lines) header += *c + l + "\n";
    // A SINUMERIK file's first line names it (%_N_..._INI): the comment goes after it.
    const auto at = text.starts_with("%_N_") ? text.find('\n') + 1 : 0;
    text.insert(at, header);
  }
  return silent;
}

// The cross-axis part of what was written, stored with the machine (--machine) so that the next
// straightness run of an axis it corrects is compared with it (daq verify RUN). LinuxCNC's
// COMP_FILEs are positioning tables: only matrixkins.hal is kept. Made and checked (the format,
// the files read back as the control reads them, the machine) before anything is written: a
// refused --machine leaves no files behind (docs/compensation-tables.md, "Verification").
struct ToStore {
  CrossCompensation compensation;
  std::int64_t machine_id = 0;
};

std::optional<ToStore> to_store(const Options& o, const Written& w) {
  if (o.machine.empty()) return std::nullopt;
  const std::string format = o.format == "linuxcnc" ? "linuxcnc-matrixkins" : o.format;
  if (o.format == "fanuc")
    throw cal::InputError(
        "--machine: a FANUC compensation is not stored for daq verify: FANUC's pitch error "
        "tables correct each axis along itself, which a straightness run cannot verify (a "
        "positioning run verifies a pitch table: daq compensate --run RUN -f fanuc); nothing "
        "was written");
  if (!ct::is_cross_format(format))
    throw cal::InputError(fmt::format(
        "--machine: a {} compensation cannot be read back for daq verify; nothing was written",
        o.format));
  ToStore s{CrossCompensation{
                .format = format, .files = {}, .axis_numbers = numbers_of(o), .file = o.output},
            0};
  std::vector<ct::CompFile> texts;
  for (const auto& [name, text] : w.files)
    if (format != "linuxcnc-matrixkins" || name == "matrixkins.hal") {
      s.compensation.files.push_back({name, text});
      texts.push_back({name, text});
    }
  // What daq verify will read: refused now, not after the files are written.
  (void)ct::read_cross_applied(format, texts, s.compensation.axis_numbers);
  cal::storage::Store store(database_path(o.db));
  const auto machine = store.machine_by_name(o.machine);
  if (!machine)
    throw cal::InputError(
        fmt::format("{}: no machine '{}' (daq runs lists them); nothing was written",
                    store.path().string(), o.machine));
  s.machine_id = machine->id;
  return s;
}

void store_with_machine(const Options& o, const ToStore& s, const std::string& origin) {
  cal::storage::Store store(database_path(o.db));
  // The source: "model FILE", or a stored model's label ("model UUID") as it is.
  const auto source = o.file.starts_with("model ") ? o.file : "model " + o.file;
  const auto id =
      store_cross_compensation(store, s.machine_id, 0, source, s.compensation, {{"label", origin}});
  fmt::print(stderr,
             "stored as compensation {} of machine '{}': the next straightness run of an axis it "
             "corrects is compared with it (daq verify RUN)\n",
             id, o.machine);
}

void run(const Options& given) {
  const auto in = read_model_input(given.file, given.db);
  Options o = given;
  o.file = in.label;  // the file, or the stored model: what the output names
  const mdl::Model& m = in.model;
  mdl::require_no_rotary(m, o.file, "daq model compensate (the linear axes' tables)");
  const auto g = grid_of(o, m);
  const kin::Vec3 ref = reference_of(o, g);
  const auto tables = vc::cross_tables(m.machine, g, ref, m.carriers);
  Written w = write_format(o, m, g, tables);
  const std::string origin = model_origin(m);
  const auto parts = model_origin_parts(m);
  const auto silent = say_origin(w, o.format, origin, parts);
  const auto machine = m.machine;
  const auto before = [machine](const kin::Vec3& p) {
    return kin::volumetric_error_um(machine, p, kin::Method::htm);
  };
  const auto correction = w.correction_um;
  const auto after = [machine, correction](const kin::Vec3& p) {
    return vc::residual_um(machine, p, correction(p));
  };
  // Evaluated on at most 21 points per axis over the travel (a fine table grid would make
  // billions of points); off the table nodes, so interpolation between them shows too.
  std::array<vc::AxisGrid, 3> eval = g;
  for (auto& e : eval) {
    const double end = e.end_mm();
    e.points = std::min(e.points, 21);
    e.interval_mm = (end - e.start_mm) / (e.points - 1);
  }
  const Extremes b = largest(eval, before), a = largest(eval, after);
  const auto storing = to_store(o, w);
  // Write only once everything is computed and checked: a refusal leaves no partial files.
  std::vector<std::string> written;
  const bool several = w.files.size() > 1 || !w.files.front().first.empty();
  if (several) {
    if (o.output_dir.empty())
      throw cal::InputError(fmt::format("format {} writes {} files: give --output-dir DIR",
                                        o.format, w.files.size()));
    std::filesystem::create_directories(o.output_dir);
    for (const auto& [name, text] : w.files) {
      const std::string path = (std::filesystem::path(o.output_dir) / name).string();
      put(path, text);
      written.push_back(path);
    }
  } else if (!o.output.empty()) {
    put(o.output, w.files.front().second);
    written.push_back(o.output);
  } else if (!o.json) {
    fmt::print("{}", w.files.front().second);
  }
  if (storing) store_with_machine(o, *storing, origin);
  if (!o.report.empty()) {
    kin::Grid grid;
    for (std::size_t i = 0; i < 3; ++i) {
      grid.min_mm[i] = g[i].start_mm;
      grid.max_mm[i] = g[i].start_mm + g[i].interval_mm * (g[i].points - 1);
      grid.count[i] = static_cast<std::size_t>(std::min(g[i].points, 11));
    }
    auto page = model_page_of(m, o.file, grid, kin::Method::htm);
    page.compensated = cal::daq::report::ModelPage::Compensated{w.what, after, w.notes};
    write_report_page(o.report, cal::daq::report::model_page(page));
  }
  if (o.json) {
    fmt::print("{}\n", json{{"schema", "caldaq.model-compensation.v1"},
                            {"model", o.file},
                            {"format", o.format},
                            {"compensation", w.what},
                            {"files", written},
                            {"reference_mm", {ref[0], ref[1], ref[2]}},
                            {"before_max_um", b.max_um},
                            {"before_max_at_mm", {b.at[0], b.at[1], b.at[2]}},
                            {"after_max_um", a.max_um},
                            {"after_max_at_mm", {a.at[0], a.at[1], a.at[2]}},
                            {"notes", w.notes},
                            {"origin", origin},
                            {"origins", parts},
                            {"meaning", meaning_json(meanings_of(o.format))}}
                           .dump(2));
    return;
  }
  for (const auto& f : written) fmt::print(stderr, "written {}\n", f);
  for (const auto& l : daq::table_origin_lines(origin, "", parts)) fmt::print(stderr, "{}\n", l);
  if (!silent.empty())
    fmt::print(stderr, "{}: the format has no comments, so the file does not say it\n",
               fmt::join(silent, ", "));
  fmt::print(stderr,
             "{}: largest |e| over the travel ({} x {} x {} points) {:.3f} um before, {:.3f} um "
             "with the compensation applied to the model (at {:g}, {:g}, {:g} mm)\n",
             w.what, eval[0].points, eval[1].points, eval[2].points, b.max_um, a.max_um, a.at[0],
             a.at[1], a.at[2]);
  for (const auto& n : w.notes) fmt::print(stderr, "note: {}\n", n);
  for (const auto* meaning : meanings_of(o.format))
    fmt::print(stderr, "{}\n", ct::meaning_text(*meaning));
}

}  // namespace

void add_model_compensate_command(CLI::App& model) {
  const auto [cmd, o] = add_command<Options>(
      model, "compensate", run,
      "The model's compensation in a controller format, with what remains when applied");
  cmd->add_option("file", o->file,
                  "Model file (caldaq.model.v1), or a model kept in the store --db names (its "
                  "UUID or number: daq model list)")
      ->required();
  cmd->add_option("-f,--format", o->format,
                  "csv, siemens-cec, isg-cross, isg-volumetric, heidenhain, fanuc or linuxcnc")
      ->capture_default_str();
  cmd->add_option("--interval-mm", o->interval_mm,
                  "Table interval per axis X Y Z (the tables span the model's travel)")
      ->expected(3)
      ->required();
  cmd->add_option("--reference-mm", o->reference_mm,
                  "Where the product terms are frozen (default: the grid point nearest the middle)")
      ->expected(3);
  cmd->add_option("--axis-numbers", o->axis_numbers,
                  "The control's numbers of X Y Z (AXn, logical axis numbers)")
      ->expected(3)
      ->capture_default_str();
  cmd->add_option("-o,--output", o->output, "File for a one-file format (default stdout)");
  cmd->add_option("--output-dir", o->output_dir, "Directory for formats of several files");
  cmd->add_option("--isg-csv-path", o->isg_csv_path,
                  "isg-volumetric: the parameter file's path as the control sees it")
      ->capture_default_str();
  cmd->add_option("--fanuc-reference-mm", o->fanuc_reference_mm,
                  "fanuc: the reference position (default: the start of each travel)");
  cmd->add_option("--fanuc-first-point", o->fanuc_first_point, "fanuc: number of the first point")
      ->capture_default_str();
  cmd->add_option("--fanuc-unit-um", o->fanuc_unit_um, "fanuc: detection unit")
      ->capture_default_str();
  cmd->add_option("--fanuc-magnification", o->fanuc_magnification, "fanuc: parameter 3623")
      ->capture_default_str();
  cmd->add_option("--report", o->report,
                  "Also write the volumetric error page with what remains after compensation");
  cmd->add_flag("--json", o->json,
                "Print caldaq.model-compensation.v1 JSON (files via -o/--output-dir)");
  cmd->add_option("--machine", o->machine,
                  "Store the written compensation with this machine of --db: the next "
                  "straightness run of an axis it corrects is checked against it (daq verify)");
  // Not add_db_option's "Run database": here --db is where a stored model is read from (the
  // central store too) and where --machine keeps the written compensation (local only).
  cmd->add_option("--db", o->db,
                  "Store the model is read from when FILE is a UUID or number (a local file, or "
                  "the central store postgresql://...), and where --machine keeps the "
                  "compensation (a local file only; default: $CALDAQ_DB, else "
                  "~/.local/share/caldaq/site.sqlite)");
}

}  // namespace daq
