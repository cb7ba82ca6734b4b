// A machine's model from its stored runs (see model_from_runs.hpp).
#include "model_from_runs.hpp"

#include <fmt/format.h>

#include <set>

#include "cal/analysis/error.hpp"
#include "provenance.hpp"
#include "run_quality.hpp"

namespace daq {

namespace kin = cal::kinematics;
namespace mdl = cal::daq::model;
using nlohmann::json;

namespace {

ModelOrigin model_origin(const cal::storage::RunReader& store,
                         const std::vector<std::pair<std::string, std::vector<std::int64_t>>>& used,
                         const std::string& machine) {
  ModelOrigin o;
  std::map<std::int64_t, std::string> of_run;
  std::set<std::string> labels;
  for (const auto& [name, ids] : used) {
    std::string error_label;
    for (const auto id : ids) {
      if (!of_run.count(id)) {
        const auto run = store.run(id);
        of_run[id] = run ? run_origin(*run, store.instruments(id), machine).label() : "";
      }
      if (!of_run[id].empty()) error_label = of_run[id];
    }
    labels.insert(error_label);
    if (error_label.empty())
      ++o.real;
    else
      ++o.other, o.errors[name] = error_label;
  }
  if (o.other > 0) o.label = labels.size() == 1 ? *labels.begin() : "MIXED";
  return o;
}

}  // namespace

ModelFromRuns model_from_runs(const cal::storage::RunReader& store, const ModelFromRunsOptions& o) {
  ModelFromRuns out;
  out.stored = stored_profiles(store, o.machine);
  std::vector<std::int64_t> used_runs;
  for (const auto& p : out.stored.profiles) used_runs.push_back(p.run_id);
  out.accepted = refuse_suspect_runs(store, used_runs, o.accept_suspect, o.what);
  mdl::BuildOptions b{.machine = o.machine, .allow_missing = o.allow_missing};
  if (o.topology)
    b.topology = *o.topology;
  else if (out.stored.topology)
    b.topology = *out.stored.topology;
  else
    throw cal::InputError(fmt::format(
        "machine '{}': its runs do not say the kinematic chain ([machine] topology in the "
        "configuration): give --topology",
        o.machine));
  out.topology = b.topology;
  b.tool_offset_mm = o.tool_offset_mm.value_or(out.stored.tool_offset_mm);
  b.table_offset_mm = out.stored.table_offset_mm;
  out.report = mdl::build(out.stored.profiles, b);
  out.origin = model_origin(store, out.report.used, o.machine);
  // The model says it was built from suspect runs, knowingly, and from runs not measured for real.
  auto prov = json::parse(out.report.model.provenance.json);
  if (!out.accepted.empty()) prov["accepted_suspect_runs"] = out.accepted;
  if (!out.origin.label.empty())
    prov["origin"] = out.origin.label, prov["origins"] = out.origin.errors;
  out.report.model.provenance.json = prov.dump();
  return out;
}

json model_build_json(const ModelFromRuns& b, const std::string& machine, const std::string& file) {
  json used = json::object();
  for (const auto& [name, ids] : b.report.used) used[name] = ids;
  return {{"schema", "caldaq.model-build.v1"},
          {"machine", machine},
          {"topology", kin::to_string(b.topology)},
          {"file", file},
          {"used", used},
          {"missing", b.report.missing},
          {"skipped", b.stored.skipped},
          {"accepted_suspect_runs", b.accepted},
          {"origin", b.origin.label},
          {"origins", b.origin.errors},
          {"notes", b.report.notes}};
}

}  // namespace daq
