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
// that writes and stores it. With `store_in` (a --db value: the run database, "" for the
// default) the table is also stored with the run as the command stores it (for daq verify), its
// id in "stored" (else null); the store's failure is thrown. Throws cal::InputError as the
// command refuses (a suspect run not accepted, no stops, a run that is not linear, an unknown
// format).
nlohmann::json run_compensation(const cal::storage::Store& store, std::int64_t run,
                                const std::string& format, const std::string* store_in = nullptr);

}  // namespace daq
