#pragma once
// The compensation table of a stored linear run as `daq compensate --run RUN -f FORMAT` writes it
// (cmd_compensate.cpp), for the operator's page (docs/web.md, "Results").
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "cal/storage/store.hpp"

namespace daq {

// The table over the run's own grid (its first target, its spacing, its number of targets) in
// `format` (csv, linuxcnc, siemens, isg, heidenhain, fanuc), through the same code as the
// command: the file's text, its values and what they mean (the sign and its source), what it is
// predicted to leave, the run's origin ("SIMULATED"...; "" for real instruments) and the command
// that writes and stores it. Nothing is stored. Throws cal::InputError as the command refuses (a
// suspect run not accepted, no stops, a run that is not linear, an unknown format).
nlohmann::json run_compensation(const cal::storage::RunReader& store, std::int64_t run,
                                const std::string& format);

}  // namespace daq
