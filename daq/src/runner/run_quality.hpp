#pragma once
// The quality gate of a stored run's stops (issue 26; the rule: docs/iso230-2.md, "Suspect
// stops"): one reading for the CLI (`daq run`, `daq show`), the JSON of a run, the reports and
// the page, and one refusal for every builder (`daq model build`, `daq compensate`,
// `daq model compensate`) of a suspect run not accepted by name (--accept-suspect RUN).
#include <cstdint>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cal/storage/store.hpp"

namespace daq {

// The stops checked against the run's own repeatability (cal::quality::assess), in the run's
// unit ("um", or "urad" for angular kinds).
cal::storage::RunQuality assess_stops(std::span<const cal::storage::CapturedTarget> stops,
                                      std::string_view unit);

// A stored run's stop quality: as stored when it was acquired, else assessed now from its
// stored stops (a run stored before schema 5, an import; nothing is written).
cal::storage::RunQuality run_quality(const cal::storage::RunReader& store, std::int64_t run_id);

// {"state", "summary", "suspect_stops": [{"run", "direction": "up"|"down", "target_index",
// "reason"}]}: the "quality" of a run's JSON.
nlohmann::json quality_json(const cal::storage::RunQuality& q);
// The quality in one line, printed after a label: "ok, every stop within ...", "suspect, 1
// stop(s) beyond ...", the state said once and followed by a comma (the summary of an
// assessment begins with "ok: "; a stored one may not).
std::string quality_text(const cal::storage::RunQuality& q);

// The builders' gate: throws cal::InputError naming every suspect run of `runs` that is not in
// `accepted`, with its suspect stops and how to accept it. Returns the suspect runs that were
// accepted, for the provenance of what is built ("accepted_suspect_runs").
std::vector<std::int64_t> refuse_suspect_runs(const cal::storage::RunReader& store,
                                              std::span<const std::int64_t> runs,
                                              std::span<const std::int64_t> accepted,
                                              std::string_view what);

}  // namespace daq
