#pragma once
// A stored run as `daq show RUN --json` prints it (caldaq.run.v1: the run, its settings,
// instruments, missed stops, and every result with its provenance and verdict); the operator's
// page shows the same document (GET /api/runs/N), so the two cannot differ.
#include <cstdint>
#include <nlohmann/json.hpp>

namespace cal::storage {
class RunReader;
struct Approval;
}  // namespace cal::storage

namespace daq {

// Throws cal::InputError naming the database for a run that does not exist.
nlohmann::json run_document(const cal::storage::RunReader& store, std::int64_t run);
// A result's sign-off as the run document carries it (a result's "approval", present only when it
// is approved): the result, who approved it and when (UTC); on the central store its fingerprint
// and the run's version then.
nlohmann::json approval_json(const cal::storage::Approval& a);

}  // namespace daq
