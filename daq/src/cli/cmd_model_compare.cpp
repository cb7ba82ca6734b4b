// daq model compare REFERENCE OTHER: how far each error of one model is from the other's and
// what that does to the volumetric error (model/model_compare.hpp). The walkthrough uses it to
// measure a built model against the SIMULATED shop's injected truth (`daq sim --truth-out`).
#include <fmt/format.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <nlohmann/json.hpp>

#include "cal/analysis/error.hpp"
#include "command.hpp"
#include "model/model_compare.hpp"
#include "model_cli.hpp"
#include "terminal.hpp"

namespace daq {

namespace {

struct CompareOptions {
  std::string reference, other, db;
  std::vector<std::size_t> count{11, 11, 11};
  bool json = false;
};

// The largest difference among the entries `keep` selects.
const mdl::ComponentDifference* largest(const mdl::Comparison& c, auto keep) {
  const mdl::ComponentDifference* best = nullptr;
  for (const auto& d : c.components)
    if (keep(d) && (!best || d.max_abs > best->max_abs)) best = &d;
  return best;
}

json to_json(const CompareOptions& o, const mdl::Comparison& c) {
  json errors = json::array();
  for (const auto& d : c.components) {
    json e{{"error", d.name}, {"unit", d.unit}, {"max_abs", d.max_abs}};
    if (!d.squareness) e["at_mm"] = d.at_mm;
    errors.push_back(e);
  }
  const auto& g = c.grid;
  return {{"schema", "caldaq.model-compare.v1"},
          {"reference", o.reference},
          {"other", o.other},
          {"same_topology", c.same_topology},
          {"same_offsets", c.same_offsets},
          {"range_mm", c.range_mm},
          {"errors", errors},
          {"volumetric",
           {{"max_um", c.volumetric_max_um}, {"at_mm", c.volumetric_at_mm}, {"count", g.count}}}};
}

void print_text(const CompareOptions& o, const mdl::Model& ref, const mdl::Comparison& c) {
  print_line("{} against {} (the reference)", o.other, o.reference);
  const auto& r = c.range_mm;
  print_line(
      "  compared over X {:g} .. {:g}, Y {:g} .. {:g}, Z {:g} .. {:g} mm (where both are "
      "defined): every table point and 101 even steps per axis",
      r[0][0], r[0][1], r[1][0], r[1][1], r[2][0], r[2][1]);
  if (!c.same_topology)
    print_line("  NOTE: the chains differ ({} against {}): the volumetric difference mixes them",
               describe_topology(ref.machine.topology), "the other's");
  const auto show = [&](std::string_view what, const mdl::ComponentDifference* d) {
    if (!d) return;
    if (d->squareness)
      print_line("  largest {:22} {:9.4f} {:4} ({})", what, d->max_abs, d->unit, d->name);
    else
      print_line("  largest {:22} {:9.4f} {:4} ({} at {:g} mm)", what, d->max_abs, d->unit, d->name,
                 d->at_mm);
  };
  show("translation difference", largest(c, [](const auto& d) { return d.unit == "um"; }));
  show("angle difference",
       largest(c, [](const auto& d) { return d.unit == "urad" && !d.squareness; }));
  show("squareness difference", largest(c, [](const auto& d) { return d.squareness; }));
  const auto& t = ref.machine.tool_offset_mm;
  print_line(
      "  volumetric: largest |e_other - e_reference| {:.4f} um at ({:g}, {:g}, {:g}) mm, {} x {} "
      "x {} points, the reference's tool point ({:g}, {:g}, {:g}) mm{}",
      c.volumetric_max_um, c.volumetric_at_mm[0], c.volumetric_at_mm[1], c.volumetric_at_mm[2],
      c.grid.count[0], c.grid.count[1], c.grid.count[2], t[0], t[1], t[2],
      c.same_offsets ? "" : " (the other's own offsets differ and are not used)");
  print_line("Each error (translations um, angles urad):");
  for (const auto& d : c.components)
    if (d.squareness)
      print_line("  {:6} {:9.4f}", d.name, d.max_abs);
    else
      print_line("  {:6} {:9.4f}  at {:g} mm", d.name, d.max_abs, d.at_mm);
}

void run_compare(const CompareOptions& given) {
  if (given.count.size() != 3 ||
      std::any_of(given.count.begin(), given.count.end(), [](auto n) { return n == 0 || n > 101; }))
    throw cal::InputError("--count needs three counts from 1 to 101 (X Y Z)");
  const auto ref_in = read_model_input(given.reference, given.db);
  const auto other_in = read_model_input(given.other, given.db);
  CompareOptions o = given;  // the files, or the stored models: what the output names
  o.reference = ref_in.label;
  o.other = other_in.label;
  const auto& ref = ref_in.model;
  const auto& other = other_in.model;
  mdl::require_no_rotary(ref, o.reference, "daq model compare");
  mdl::require_no_rotary(other, o.other, "daq model compare");
  const auto c = mdl::compare(ref, other, {o.count[0], o.count[1], o.count[2]});
  if (o.json) return fmt::print("{}\n", to_json(o, c).dump(2));
  print_text(o, ref, c);
}

}  // namespace

void add_model_compare_command(CLI::App& model) {
  const auto [cmd, o] = add_command<CompareOptions>(
      model, "compare", run_compare,
      "How far each error of a model is from a reference model's (e.g. a built model against "
      "the SIMULATED shop's injected truth, `daq sim --truth-out`), and the volumetric "
      "difference");
  cmd->add_option("reference", o->reference, "The reference model file")->required();
  cmd->add_option("other", o->other, "The model compared with it")->required();
  cmd->add_option("--count", o->count, "Volumetric grid points per axis X Y Z (1 to 101)")
      ->expected(3)
      ->capture_default_str();
  cmd->add_flag("--json", o->json, "Print caldaq.model-compare.v1 JSON");
  add_model_db_option(*cmd, o->db);
}

}  // namespace daq
