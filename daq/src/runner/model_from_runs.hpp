#pragma once
// A machine's model (caldaq.model.v1) from its stored runs: the latest complete run of each
// component (stored_model.hpp), through the suspect-run gate (run_quality.hpp), with where its
// runs came from in its provenance. One function for `daq model build` and the operator page's
// GET /api/model (docs/volumetric-walkthrough.md, docs/web.md).
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "cal/storage/store.hpp"
#include "model/model_build.hpp"
#include "model/stored_model.hpp"

namespace daq {

// Where the runs of a model came from (provenance.hpp): "" when every run was measured on real
// instruments, the label when all share one ("SIMULATED"), else "MIXED"; and each error whose
// run was not real, with its run's label.
struct ModelOrigin {
  std::string label;
  std::map<std::string, std::string> errors;  // E_XX -> "SIMULATED"
  std::size_t real = 0, other = 0;
};

struct ModelFromRunsOptions {
  std::string machine;
  std::optional<cal::kinematics::Topology> topology;    // else the runs' ([machine] topology)
  std::optional<cal::kinematics::Vec3> tool_offset_mm;  // else the runs'
  std::vector<std::int64_t> accept_suspect;             // suspect runs used knowingly
  bool allow_missing = false;                           // errors without a run are zero, and listed
  std::string what = "daq model build";                 // who refuses a suspect run, in its message
};

struct ModelFromRuns {
  cal::daq::model::BuildReport report;  // the model (its provenance says the origin), used, ...
  StoredProfiles stored;                // with the runs not used, and why
  std::vector<std::int64_t> accepted;   // suspect runs used as told
  ModelOrigin origin;
  cal::kinematics::Topology topology = cal::kinematics::Topology::fxyz;
};

// Throws cal::InputError: an unknown machine or one without runs, no topology known, a suspect
// run not accepted, a missing error (unless allowed), travels that do not overlap.
ModelFromRuns model_from_runs(const cal::storage::RunReader& store, const ModelFromRunsOptions& o);

// caldaq.model-build.v1: machine, topology, file, used, missing, skipped,
// accepted_suspect_runs, origin, origins, notes (docs/cli.md, `daq model build --json`).
nlohmann::json model_build_json(const ModelFromRuns& b, const std::string& machine,
                                const std::string& file);

}  // namespace daq
