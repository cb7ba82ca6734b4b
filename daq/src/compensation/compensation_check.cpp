// The compensation loop at the machine (see compensation_check.hpp).
#include "compensation_check.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "cal/analysis/comp_meaning.hpp"
#include "cal/analysis/comp_read.hpp"
#include "cal/analysis/error.hpp"
#include "cal/analysis/iso230_2.hpp"

namespace daq {

namespace ct = cal::comptable;
using nlohmann::json;

json to_json(const TableWriter& w) {
  return {{"format", w.format},
          {"axis_number", w.axis_number},
          {"fanuc",
           {{"reference_mm", w.fanuc.reference_mm},
            {"first_point", w.fanuc.first_point},
            {"detection_unit_um", w.fanuc.detection_unit_um},
            {"magnification", w.fanuc.magnification}}}};
}

TableWriter table_writer_from_json(const json& j) {
  TableWriter w;
  w.format = j.value("format", "csv");
  w.axis_number = j.value("axis_number", 1);
  const json f = j.value("fanuc", json::object());
  w.fanuc.reference_mm = f.value("reference_mm", 0.0);
  w.fanuc.first_point = f.value("first_point", 0);
  w.fanuc.detection_unit_um = f.value("detection_unit_um", 1.0);
  w.fanuc.magnification = f.value("magnification", 1);
  return w;
}

std::string write_table(const TableWriter& w, const ct::Table& t) {
  if (w.format == "csv") return ct::write_csv(t);
  if (w.format == "linuxcnc") return ct::write_linuxcnc(t);
  if (w.format == "siemens") return ct::write_siemens(t, w.axis_number);
  if (w.format == "isg") return ct::write_isg(t);
  if (w.format == "heidenhain") return ct::write_heidenhain_com(t);
  if (w.format == "fanuc") return ct::write_fanuc_pitch(t, w.fanuc);
  throw cal::InputError(fmt::format(
      "format '{}' (expected csv, linuxcnc, siemens, isg, heidenhain or fanuc; siemens-cec for "
      "--straightness)",
      w.format));
}

ct::Applied applied_of(const TableWriter& w, const ct::Table& t) {
  if (w.format == "fanuc") return ct::fanuc_applied(t, w.fanuc);
  const bool both = w.format == "linuxcnc" || w.format == "isg" ||
                    (w.format == "heidenhain" && (t.spec.bidirectional || t.backlash != 0.0));
  return ct::applied(t, both);
}

namespace {

std::vector<double> numbers(const json& j, const char* key) {
  std::vector<double> v;
  if (const auto it = j.find(key); it != j.end() && it->is_array())
    for (const auto& x : *it)
      if (x.is_number()) v.push_back(x.get<double>());
  return v;
}

// The source run's mean error at x, between its targets (nullopt outside them).
std::optional<double> before_at(const std::vector<double>& x, const std::vector<double>& v,
                                double q) {
  if (x.size() < 2 || v.size() != x.size() || q < x.front() - 1e-9 || q > x.back() + 1e-9)
    return std::nullopt;
  return ct::correction_at_um(x, v, q);
}

json document(const cal::storage::RunReader& store, const cal::storage::CompensationRecord& c) {
  const json doc = json::parse(c.json, nullptr, false);
  if (doc.is_discarded() || !doc.is_object())
    throw cal::InputError(
        fmt::format("{}: compensation {} is not readable JSON", store.name(), c.id));
  return doc;
}

// A cross-axis or volumetric compensation (store_cross_compensation), not a positioning table.
bool is_cross(const cal::storage::CompensationRecord& c) {
  const json doc = json::parse(c.json, nullptr, false);
  return doc.is_object() && doc.value("kind", "") == "cross";
}

// The compensation the run is checked against: the one given, else the newest of the run's
// machine and axis stored before the run started.
std::optional<cal::storage::CompensationRecord> compensation_for(
    const cal::storage::RunReader& store, const cal::storage::RunRecord& run,
    std::optional<std::int64_t> id) {
  if (id) {
    for (const auto& c : store.compensations())
      if (c.id == *id) {
        if (c.axis != run.axis)
          throw cal::InputError(fmt::format("compensation {} is of axis {}, run {} of axis {}",
                                            c.id, c.axis, run.id, run.axis));
        return c;
      }
    throw cal::InputError(fmt::format("{}: no compensation {} (daq verify lists them with --list)",
                                      store.name(), *id));
  }
  std::optional<cal::storage::CompensationRecord> found;
  for (const auto& c : store.compensations(run.machine_id, run.axis))
    if (c.created_unix_ms <= run.started_unix_ms && c.source_run_id != run.id && !is_cross(c))
      found = c;
  return found;
}

}  // namespace

namespace {

std::map<std::string, int> axis_numbers_of(const json& doc) {
  std::map<std::string, int> n{{"X", 1}, {"Y", 2}, {"Z", 3}};
  if (const auto it = doc.find("axis_numbers"); it != doc.end() && it->is_object())
    for (const auto& [k, v] : it->items())
      if (v.is_number_integer()) n[k] = v.get<int>();
  return n;
}

std::vector<ct::CompFile> files_of(const json& doc) {
  std::vector<ct::CompFile> t;
  for (const auto& f : doc.value("files", json::array()))
    t.push_back({f.value("name", ""), f.value("text", "")});
  return t;
}

// What the compensation's files make the control add (the vendor's reading).
ct::CrossApplied applied_cross(const json& doc) {
  return ct::read_cross_applied(doc.value("format", ""), files_of(doc), axis_numbers_of(doc));
}

json settings_of(const cal::storage::RunRecord& r) {
  const json j = json::parse(r.settings_json, nullptr, false);
  return j.is_object() ? j : json::object();
}

std::string component_of(const cal::storage::RunRecord& r) {
  return settings_of(r).value("measure", json::object()).value("component", "");
}

// Per target (nominal mm): the mean up and down of a run's stops.
std::vector<cal::iso230_2::TargetStats> stats_of(const cal::storage::RunReader& store,
                                                 std::int64_t run) {
  std::vector<cal::iso230_2::Measurement> m;
  for (const auto& t : store.targets(run))
    m.push_back({t.nominal_mm, t.run_number,
                 t.direction == '+' ? cal::iso230_2::Direction::up : cal::iso230_2::Direction::down,
                 t.deviation_um});
  if (m.empty()) return {};
  return cal::iso230_2::target_stats(m, 1);
}

// The newest cross-axis compensation of the run's machine, stored before the run, that corrects
// the axis the run reads (or the one given).
std::optional<cal::storage::CompensationRecord> cross_compensation_for(
    const cal::storage::RunReader& store, const cal::storage::RunRecord& run,
    const std::string& direction, std::optional<std::int64_t> id) {
  std::optional<cal::storage::CompensationRecord> found;
  for (const auto& c : store.compensations()) {
    if (id) {
      if (c.id != *id) continue;
      if (!is_cross(c))
        throw cal::InputError(fmt::format(
            "compensation {} is a positioning table of axis {}: a positioning run verifies it, "
            "not run {} (a straightness run)",
            c.id, c.axis, run.id));
      return c;
    }
    if (c.machine_id == run.machine_id && is_cross(c) && c.created_unix_ms <= run.started_unix_ms &&
        c.source_run_id != run.id && c.axis.find(direction) != std::string::npos)
      found = c;
  }
  if (id)
    throw cal::InputError(fmt::format("{}: no compensation {} (daq verify lists them with --list)",
                                      store.name(), *id));
  return found;
}

// The as-found run of the component: the compensation's source run when it measured the same
// component, else the newest complete run of it on the machine started before the compensation.
std::optional<cal::storage::RunRecord> as_found_for(const cal::storage::RunReader& store,
                                                    const cal::storage::RunRecord& run,
                                                    const std::string& component,
                                                    const cal::storage::CompensationRecord& c) {
  if (c.source_run_id != 0)
    if (const auto src = store.run(c.source_run_id); src && component_of(*src) == component)
      return src;
  std::optional<cal::storage::RunRecord> found;
  for (const auto& r : store.runs())
    if (r.machine_id == run.machine_id && r.id != run.id && r.kind == run.kind &&
        r.status == cal::storage::RunStatus::complete && r.started_unix_ms < c.created_unix_ms &&
        component_of(r) == component && (!found || r.started_unix_ms >= found->started_unix_ms))
      found = r;
  return found;
}

std::optional<LoopCheck> check_cross_run(const cal::storage::RunReader& store,
                                         const cal::storage::RunRecord& run,
                                         std::optional<std::int64_t> compensation_id) {
  const json settings = settings_of(run);
  const json measure = settings.value("measure", json::object());
  const std::string direction = measure.value("direction", "");
  const std::string component = component_of(run);
  const auto axis = std::string_view("XYZ").find(run.axis.empty() ? '?' : run.axis.front());
  const auto dir = std::string_view("XYZ").find(direction.empty() ? '?' : direction.front());
  if (axis > 2 || dir > 2)
    throw cal::InputError(fmt::format(
        "run {}: a straightness run without its axis and direction in its settings", run.id));
  const auto comp = cross_compensation_for(store, run, direction, compensation_id);
  if (!comp) return std::nullopt;
  const auto found = as_found_for(store, run, component, *comp);
  if (!found) return std::nullopt;
  const auto applied = applied_cross(document(store, *comp));
  // The line: the other axes where the run held them, the run's axis at each target.
  cal::kinematics::Vec3 at{};
  if (const auto s = measure.find("stationary_mm"); s != measure.end() && s->is_array())
    for (std::size_t k = 0; k < 3 && k < s->size(); ++k)
      if ((*s)[k].is_number()) at[k] = (*s)[k].get<double>();
  const auto before = stats_of(store, found->id);
  const auto after = stats_of(store, run.id);
  ct::VerifyInput in;
  // What the files add along the line at the points of their table of the read axis over the
  // moving one (linear between them, as the control interpolates): a table acting at shifted
  // positions is then found as a position shift (verify's best_shift).
  const std::string moving(1, "XYZ"[axis]);
  for (const auto& t : applied.tables)
    if (t.input == moving && t.output == direction && t.position_mm.size() >= 2 &&
        in.table_position_mm.empty() && t.position_mm.size() <= 10000)
      for (const double x : t.position_mm) {
        cal::kinematics::Vec3 p = at;
        p[axis] = x;
        in.table_position_mm.push_back(x);
        in.table_applied_um.push_back(ct::cross_correction_um(applied, p)[dir]);
      }
  std::vector<double> spread;
  std::vector<char> sense;  // of each point: '+' approached upwards, '-' downwards
  for (const auto& s : after) {
    const auto b = std::find_if(before.begin(), before.end(), [&](const auto& x) {
      return std::abs(x.target_mm - s.target_mm) < 1e-6;
    });
    if (b == before.end()) continue;  // not measured as found: nothing to compare with
    cal::kinematics::Vec3 p = at;
    p[axis] = s.target_mm;
    const double c = ct::cross_correction_um(applied, p)[dir];
    for (const bool forward : {true, false}) {
      if ((forward ? s.runs_up : s.runs_down) == 0 || (forward ? b->runs_up : b->runs_down) == 0)
        continue;
      in.target_mm.push_back(s.target_mm);
      in.before_um.push_back(forward ? b->mean_up_um : b->mean_down_um);
      in.applied_um.push_back(c);
      in.after_um.push_back(forward ? s.mean_up_um : s.mean_down_um);
      spread.push_back(forward ? s.s_up_um : s.s_down_um);
      sense.push_back(forward ? '+' : '-');
    }
  }
  if (in.target_mm.size() < 2) return std::nullopt;
  std::sort(spread.begin(), spread.end());
  in.noise_um = spread[spread.size() / 2];
  return LoopCheck{*comp, ct::verify(in), in.target_mm.size(), component, found->id, in, sense};
}

}  // namespace

std::int64_t store_cross_compensation(cal::storage::Store& store, std::int64_t machine_id,
                                      std::int64_t source_run_id, const std::string& source,
                                      const CrossCompensation& c, const json& origin) {
  json files = json::array();
  std::vector<ct::CompFile> named;
  for (const auto& [name, text] : c.files) {
    files.push_back({{"name", name}, {"text", text}});
    named.push_back({name, text});
  }
  const auto applied = ct::read_cross_applied(c.format, named, c.axis_numbers);
  // The axes the files correct: what a straightness run reads to verify them.
  std::string axes;
  for (const auto& t : applied.tables)
    if (axes.find(t.output) == std::string::npos) axes += t.output;
  if (applied.volumetric) axes = "XYZ";
  std::sort(axes.begin(), axes.end());
  const auto& m = ct::format_meaning(c.format);
  const json doc{{"schema", "caldaq.compensation.v1"},
                 {"kind", "cross"},
                 {"format", c.format},
                 {"axis_numbers", c.axis_numbers},
                 {"meaning",
                  {{"values", m.written == ct::Sign::error ? "error" : "correction"},
                   {"evidence", ct::to_string(m.evidence)},
                   {"source", m.source}}},
                 {"files", files},
                 {"file", c.file},
                 {"origin", origin}};
  return store.add_compensation({.machine_id = machine_id,
                                 .source_run_id = source_run_id,
                                 .source = source,
                                 .axis = axes,
                                 .format = c.format,
                                 .json = doc.dump()});
}

std::vector<std::pair<std::string, std::string>> corrected_files(const LoopCheck& c) {
  const json doc = json::parse(c.compensation.json, nullptr, false);
  if (doc.is_discarded() || doc.value("kind", "") != "cross") return {{"", corrected_table(c)}};
  const auto& v = c.verification;
  std::vector<std::pair<std::string, std::string>> out;
  if (v.finding == ct::Finding::constant_shift && c.component.size() == 4) {
    // The control must add -offset more to the axis the run read (component E_<axis><moving>).
    const std::string output(1, c.component[2]);
    bool any = false;
    for (const auto& f : doc.value("files", json::array())) {
      bool here = false;
      std::string text = f.value("text", "");
      if (!any)
        text = ct::shift_cross_values(c.compensation.format, text, output, -v.offset_um,
                                      axis_numbers_of(doc), here);
      any = any || here;
      out.emplace_back(f.value("name", ""), text);
    }
    if (!any)
      throw cal::InputError(fmt::format("compensation {} ({}) has no table of axis {} to shift",
                                        c.compensation.id, c.compensation.format, output));
    return out;
  }
  if (v.finding == ct::Finding::position_shift && c.component.size() == 4) {
    // The control applied the table of the read axis over the moving one at the moving axis's
    // position minus shift_mm (component E_<read><moving>): its positions move by -shift_mm.
    const std::string output(1, c.component[2]), input(1, c.component[3]);
    for (auto& f : ct::shift_cross_positions(c.compensation.format, files_of(doc), input, output,
                                             v.shift_mm, axis_numbers_of(doc)))
      out.emplace_back(std::move(f.name), std::move(f.text));
    return out;
  }
  double factor = 0;
  if (v.finding == ct::Finding::inverted_sign) factor = -1.0;
  if (v.finding == ct::Finding::unit_scale) factor = 1.0 / v.scale;
  if (factor == 0)
    throw cal::InputError(fmt::format(
        "compensation {} ({}): '{}' is not corrected in the files: {}", c.compensation.id,
        c.compensation.format, ct::to_string(v.finding), "nothing to correct"));
  for (const auto& f : doc.value("files", json::array()))
    out.emplace_back(f.value("name", ""),
                     ct::scale_cross_values(c.compensation.format, f.value("text", ""), factor));
  return out;
}

std::optional<LoopCheck> check_run(const cal::storage::RunReader& store, std::int64_t run_id,
                                   std::optional<std::int64_t> compensation_id) {
  const auto run = store.run(run_id);
  if (!run) throw cal::InputError(fmt::format("{}: no run {}", store.name(), run_id));
  if (run->kind == "straightness") return check_cross_run(store, *run, compensation_id);
  if (run->kind != "linear") return std::nullopt;  // angular, roll: no table checks them yet
  const auto comp = compensation_for(store, *run, compensation_id);
  if (!comp) return std::nullopt;
  if (is_cross(*comp))
    throw cal::InputError(fmt::format(
        "compensation {} is a cross-axis compensation ({}): a straightness run of an axis it "
        "corrects verifies it, not run {} (a positioning run)",
        comp->id, comp->format, run_id));
  const json doc = document(store, *comp);
  const json predicted = doc.value("predicted", json::object());
  const json applied = doc.value("applied", json::object());
  const auto src_x = numbers(predicted, "target_mm");
  const auto src_up = numbers(predicted, "before_up_um");
  const auto src_down = numbers(predicted, "before_down_um");
  const auto table_x = numbers(applied, "position_mm");
  const auto fwd = numbers(applied, "forward_um");
  const auto rev = numbers(applied, "reverse_um");
  if (table_x.size() < 2 || fwd.size() != table_x.size() || rev.size() != table_x.size())
    throw cal::InputError(
        fmt::format("{}: compensation {} holds no applied table", store.name(), comp->id));
  std::vector<cal::iso230_2::Measurement> m;
  for (const auto& t : store.targets(run_id))
    m.push_back({t.nominal_mm, t.run_number,
                 t.direction == '+' ? cal::iso230_2::Direction::up : cal::iso230_2::Direction::down,
                 t.deviation_um});
  if (m.empty()) return std::nullopt;
  const auto stats = cal::iso230_2::target_stats(m, 1);
  ct::VerifyInput in{.table_position_mm = table_x, .table_applied_um = fwd};
  std::vector<double> spread;
  std::vector<char> sense;  // of each point: '+' approached upwards, '-' downwards
  for (const auto& s : stats) {
    const auto up = before_at(src_x, src_up, s.target_mm);
    const auto down = before_at(src_x, src_down, s.target_mm);
    if (!up || !down) continue;  // outside the table's source: nothing was predicted there
    for (const bool forward : {true, false}) {
      if ((forward ? s.runs_up : s.runs_down) == 0) continue;
      in.target_mm.push_back(s.target_mm);
      in.before_um.push_back(forward ? *up : *down);
      in.applied_um.push_back(ct::correction_at_um(table_x, forward ? fwd : rev, s.target_mm));
      in.after_um.push_back(forward ? s.mean_up_um : s.mean_down_um);
      spread.push_back(forward ? s.s_up_um : s.s_down_um);
      sense.push_back(forward ? '+' : '-');
    }
  }
  if (in.target_mm.size() < 2) return std::nullopt;
  std::sort(spread.begin(), spread.end());
  in.noise_um = spread[spread.size() / 2];
  // The as-found run is the table's source (0: a table from a model or a file).
  return LoopCheck{*comp, ct::verify(in), in.target_mm.size(), "", comp->source_run_id, in, sense};
}

std::string corrected_table(const LoopCheck& c) {
  using ct::Finding;
  const auto& v = c.verification;
  const json doc = json::parse(c.compensation.json, nullptr, false);
  const json table = doc.value("table", json::object());
  const TableWriter w = table_writer_from_json(doc.value("writer", json::object()));
  ct::Table t;
  t.position_mm = numbers(table, "position_mm");
  t.forward = numbers(table, "forward");
  t.reverse = numbers(table, "reverse");
  t.backlash = table.value("backlash", 0.0);
  if (t.position_mm.size() < 2)
    throw cal::InputError(fmt::format("compensation {} holds no table", c.compensation.id));
  t.spec.axis = c.compensation.axis;
  t.spec.units = ct::units_from_string(table.value("units", "mm"));
  t.spec.start_mm = t.position_mm.front();
  t.spec.interval_mm = t.position_mm[1] - t.position_mm[0];
  t.spec.points = static_cast<int>(t.position_mm.size());
  t.spec.bidirectional = !t.reverse.empty();
  t.spec.sign = w.format == "csv"
                    ? (doc.value("meaning", json::object()).value("values", "") == "error"
                           ? ct::Sign::error
                           : ct::Sign::correction)
                    : ct::format_meaning(w.format).written;
  const double unit_um = ct::um_per_unit(t.spec.units);
  const auto each = [&](auto f) {
    for (auto* v2 : {&t.forward, &t.reverse})
      for (auto& x : *v2) x = f(x);
  };
  switch (v.finding) {
    case Finding::inverted_sign:
      each([](double x) { return -x; });
      break;
    case Finding::unit_scale:
      each([&](double x) { return x / v.scale; });
      break;
    case Finding::constant_shift: {
      if (w.format == "fanuc")
        throw cal::InputError(
            "a FANUC pitch table is zero at the reference position and cannot hold a constant: "
            "shift the reference position (or the workpiece datum) instead");
      // The control must add -offset more: a correction value gets -offset, an error +offset.
      const double add =
          (t.spec.sign == ct::Sign::correction ? -v.offset_um : v.offset_um) / unit_um;
      each([&](double x) { return x + add; });
      break;
    }
    case Finding::position_shift:
      for (auto& p : t.position_mm) p -= v.shift_mm;
      t.spec.start_mm = t.position_mm.front();
      if (w.format == "fanuc")
        throw cal::InputError(
            "a FANUC table's points are fixed by the reference position: move the reference "
            "position (parameter 3620 and the grid) by the shift instead");
      break;
    default:
      throw cal::InputError(
          fmt::format("nothing to correct: the finding is '{}'", ct::to_string(v.finding)));
  }
  return write_table(w, t);
}

json to_json(const LoopCheck& c) {
  const auto& v = c.verification;
  return {{"compensation", c.compensation.id},
          {"format", c.compensation.format},
          {"source", c.compensation.source},
          {"axis", c.compensation.axis},
          {"points", c.points},
          {"finding", ct::to_string(v.finding)},
          {"scale", v.scale},
          {"offset_um", v.offset_um},
          {"shift_mm", v.shift_mm},
          {"predicted_max_um", v.predicted_max_um},
          {"measured_max_um", v.measured_max_um},
          {"mismatch_rms_um", v.mismatch_rms_um},
          {"tolerance_um", v.tolerance_um},
          {"component", c.component},
          {"as_found_run", c.as_found_run},
          {"text", v.text}};
}

std::string loop_text(const LoopCheck& c) {
  if (!c.component.empty())
    return fmt::format("compensation {} ({}, {} of axis {}), {} against run {} (as found): {}: {}",
                       c.compensation.id, c.compensation.format, c.compensation.source,
                       c.compensation.axis, c.component, c.as_found_run,
                       ct::to_string(c.verification.finding), c.verification.text);
  return fmt::format("compensation {} ({}, {} of axis {}): {}: {}", c.compensation.id,
                     c.compensation.format, c.compensation.source, c.compensation.axis,
                     ct::to_string(c.verification.finding), c.verification.text);
}

}  // namespace daq
