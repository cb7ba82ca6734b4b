#pragma once
// The 21-error volumetric campaign of a machine as a checklist for the page (docs/web.md, "The
// volumetric campaign"): the 18 component tests and the three squarenesses in the order of
// docs/volumetric-walkthrough.md, each with its set-up (kind, instrument, moving axis, direction
// read) and, once measured, the run `daq model build` takes for it (stored_profiles: the latest
// complete run of each component), its day and where the other axes stood; the days of the
// campaign; the runs not used and why; the commands that build the model and its map.
#include <nlohmann/json.hpp>
#include <string>

namespace cal::storage {
class Store;
}

namespace daq::serve {

// caldaq.volumetric-checklist.v1. `store` may be null (no database yet): nothing measured.
// A machine without a run of any test kind is not an error: everything is to do.
nlohmann::json volumetric_checklist(const cal::storage::Store* store, const std::string& machine,
                                    const std::string& database);

}  // namespace daq::serve
