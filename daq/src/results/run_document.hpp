#pragma once
// A stored run as `daq show RUN --json` prints it (caldaq.run.v1: the run, its settings,
// instruments, missed stops, and every result with its provenance and verdict); the operator's
// page shows the same document (GET /api/runs/N), so the two cannot differ.
#include <cstdint>
#include <nlohmann/json.hpp>

namespace cal::storage {
class RunReader;
}

namespace daq {

// Throws cal::InputError naming the database for a run that does not exist.
nlohmann::json run_document(const cal::storage::RunReader& store, std::int64_t run);

}  // namespace daq
