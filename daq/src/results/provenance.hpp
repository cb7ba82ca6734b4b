#pragma once
// What makes a stored result traceable (docs/storage.md, "Provenance"): the run's context (who it
// was for, the machine, the operator, the instruments with their calibration, the test
// conditions and the tolerances that applied), kept in the run's settings as "context", and each
// result's provenance (caldaq.provenance.v1): how it was obtained, with which coefficients and
// sensor offsets, by which software, when.
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "cal/daq/config.hpp"
#include "cal/storage/store.hpp"

namespace daq {

// The context of a run of `kind` ("linear" on an axis, "circle" in a plane) from its
// configuration; `tolerances` holds only the axis' or plane's entry (null: none configured);
// `instruments` the configured devices whose role is in `roles`: the ones the run opens (a
// linear run's kinds::linear_run_roles, a circle's ballbar), so that a run never lists an
// instrument it did not read.
nlohmann::json run_context(const cal::daq::Config& c, std::string_view kind,
                           std::string_view axis_or_plane, std::span<const std::string> roles);

// The tolerances that apply to a run of `kind` on that axis or plane (run_context's
// "tolerances"; null: none configured).
nlohmann::json run_tolerances(const cal::daq::Config& c, std::string_view kind,
                              std::string_view axis_or_plane);

// The coefficients of an environmental compensation, as the provenance records them.
nlohmann::json compensation_json(const cal::daq::EnvironmentConfig& e);
// Sensor corrections added to the stored readings before compensation (all 0 when acquired).
struct SensorOffsets {
  double material_k = 0.0, air_temperature_k = 0.0, pressure_pa = 0.0, humidity_pct = 0.0;
};
nlohmann::json to_json(const SensorOffsets& o);
SensorOffsets sensor_offsets_from_json(const nlohmann::json& j);

// A provenance document: {"schema": "caldaq.provenance.v1", "how", "software", "created_utc"}
// and what the caller adds (coefficients, sensor_offsets, standard, of_result, changed,
// replay_of_run, capture, analysis).
nlohmann::json provenance(std::string_view how, std::string_view software);

// "2026-03-01T12:34:56.789Z" (UTC, milliseconds).
std::string utc_iso(std::int64_t unix_ms);
std::string utc_now_iso();

// A ballbar's calibration as every output shows it (`daq ballbar calibrations`, a circle
// result's calibration record); temperature_degc null where none was given.
nlohmann::json bar_calibration_json(const cal::storage::BarCalibration& c);

// The newest current result of a run whose document has this schema, any version
// ("caldaq.iso230-2.v1", "caldaq.circle.v2" also finds a caldaq.circle.v1 result), or nullopt.
std::optional<cal::storage::ResultRecord> current_result(
    const std::vector<cal::storage::ResultRecord>& results, std::string_view schema);

// The compensation a linear run's stored deviations were made with: the coefficients and sensor
// offsets of its current result's provenance, else (results stored before provenance) the
// run's settings with no offsets.
struct CompensationUsed {
  nlohmann::json coefficients;  // equation, expansion_ppm_per_k, co2_umol_per_mol, wavelength_nm
  SensorOffsets offsets;
  std::optional<std::int64_t> result_id;  // the result they come from
  bool recompensated = false;
  nlohmann::json changed = nlohmann::json::array();  // what the re-compensation changed
};
CompensationUsed compensation_used(const nlohmann::json& settings,
                                   const std::vector<cal::storage::ResultRecord>& results);

// Where a run's readings came from (schema 5 stores it per instrument; docs/storage.md,
// "Origin"). Everything derived from a run (results, reports, exports, models, compensation
// tables, the page) shows label() prominently when it is not empty; no name can remove it.
struct RunOrigin {
  bool simulated = false;   // an instrument was a simulated twin (live, or recorded in a replay)
  bool replayed = false;    // readings pushed again through the drivers from a capture
  bool imported = false;    // another tool's file
  bool unrecorded = false;  // stored before origins were: judged by the names (below)
  std::string text;         // one sentence saying which instruments were what
  // "SIMULATED", "REPLAYED", "SIMULATED, REPLAYED", "IMPORTED", or "" for real instruments.
  std::string label() const;
};
// From the run's instruments; for runs stored before schema 5 (origin ""), by the old rule:
// "simulated" in the machine's name, the campaign, a driver or a transport, and `unrecorded`.
RunOrigin run_origin(const cal::storage::RunRecord& run,
                     const std::vector<cal::storage::InstrumentRecord>& instruments,
                     std::string_view machine_name);
nlohmann::json to_json(const RunOrigin& o);

// The lines a controller file starts with when its data were not all measured on real
// instruments (docs/compensation-tables.md, "Origin"), without their comment marker and in
// printable ASCII only (a control reads these files; a stored text could hold a line break
// that would end the comment): "SIMULATED data: do not load into a real control", where the data
// came from (`source`), and for a model built from a mix which errors came from which origin
// (`parts`: "E_XX" -> "SIMULATED"). None when `label` is "" (real instruments).
std::vector<std::string> table_origin_lines(std::string_view label, std::string_view source,
                                            const std::map<std::string, std::string>& parts);

// The software that writes results (the same string runs record).
inline constexpr std::string_view software_version = "daq 0.1.0";

}  // namespace daq
