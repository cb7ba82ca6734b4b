#pragma once
// The machine model on the operator's page (docs/web.md, "The volumetric campaign"): GET
// /api/model builds the set-up's machine's model from the store as `daq model build` does (its
// own function, model_from_runs.hpp; missing errors allowed and listed, the page says so) and
// maps it over its travel as `daq model map` does (model_map.hpp), nothing written.
#include <nlohmann/json.hpp>
#include <string>

namespace cal::storage {
class RunReader;
}

namespace daq::serve {

// caldaq.model-view.v1: `state` ("none": no run of the machine yet or no database, "refused":
// the build's own refusal in `why`, "partial": errors missing, taken as zero, "complete"),
// `machine`, `build` (caldaq.model-build.v1, `file` ""), `errors` (the 21, each `error`, `runs`
// used, `measured`, and its contribution `max_norm_um`, `rms_um` to the map), `map` (the
// grid, summary, contributions and points of `daq model map --json` over the model's travel,
// 5 x 5 x 5) or null with `map_why`. `store` may be null (no database yet).
nlohmann::json model_view(const cal::storage::RunReader* store, const std::string& machine);

}  // namespace daq::serve
