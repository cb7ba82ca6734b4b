// The compensation loop at the machine (see compensation_check.hpp).
#include "compensation_check.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "cal/analysis/comp_meaning.hpp"
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

// The compensation the run is checked against: the one given, else the newest of the run's
// machine and axis stored before the run started.
std::optional<cal::storage::CompensationRecord> compensation_for(const cal::storage::RunReader& store,
                                                                 const cal::storage::RunRecord& run,
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
    if (c.created_unix_ms <= run.started_unix_ms && c.source_run_id != run.id) found = c;
  return found;
}

}  // namespace

std::optional<LoopCheck> check_run(const cal::storage::RunReader& store, std::int64_t run_id,
                                   std::optional<std::int64_t> compensation_id) {
  const auto run = store.run(run_id);
  if (!run) throw cal::InputError(fmt::format("{}: no run {}", store.name(), run_id));
  const auto comp = compensation_for(store, *run, compensation_id);
  if (!comp) return std::nullopt;
  const json doc = json::parse(comp->json, nullptr, false);
  if (doc.is_discarded() || !doc.is_object())
    throw cal::InputError(
        fmt::format("{}: compensation {} is not readable JSON", store.name(), comp->id));
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
    }
  }
  if (in.target_mm.size() < 2) return std::nullopt;
  std::sort(spread.begin(), spread.end());
  in.noise_um = spread[spread.size() / 2];
  return LoopCheck{*comp, ct::verify(in), in.target_mm.size()};
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
          {"text", v.text}};
}

std::string loop_text(const LoopCheck& c) {
  return fmt::format("compensation {} ({}, {} of axis {}): {}: {}", c.compensation.id,
                     c.compensation.format, c.compensation.source, c.compensation.axis,
                     ct::to_string(c.verification.finding), c.verification.text);
}

}  // namespace daq
