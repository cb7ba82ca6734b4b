// The central schema on PostgreSQL (docs/storage.md, "Central store"), versioned in
// caldaq.schema_version like the SQLite store's user_version.
#include "central_schema.hpp"

#include <iterator>

#include "cal/storage/pg/sync.hpp"

namespace cal::storage::pg {
namespace {

// Entry k migrates from version k to k + 1, in the transaction of migrate_schema.
// Runs are keyed by their UUID, and numbered in the order the server first saw them (id: what
// `daq runs --db postgresql://...` lists); the rows of a run by the run's UUID and what identifies
// them in the store they came from (a chunk's seq, a result's local id), so that sending them again
// finds them. The chunk's checksum covers the run's id in its source store (source_run_id).
constexpr const char* kCentralMigrations[] = {
    R"sql(
CREATE TABLE caldaq.machines(
  id bigserial PRIMARY KEY,
  name text NOT NULL UNIQUE,
  description text NOT NULL DEFAULT '',
  config_json text NOT NULL DEFAULT '{}');
CREATE TABLE caldaq.runs(
  uuid uuid PRIMARY KEY,
  id bigint GENERATED ALWAYS AS IDENTITY UNIQUE,
  machine_id bigint REFERENCES caldaq.machines(id),
  source_run_id bigint NOT NULL,
  campaign text NOT NULL,
  kind text NOT NULL,
  axis text NOT NULL,
  settings_json text NOT NULL,
  capture_path text NOT NULL,
  software_version text NOT NULL,
  started_unix_ms bigint NOT NULL,
  ended_unix_ms bigint,
  status text NOT NULL CHECK(status IN ('running', 'complete', 'incomplete', 'aborted')),
  note text NOT NULL,
  origin_session_ns bigint,
  origin_unix_ns bigint,
  quality_json text,
  synced_unix_ms bigint NOT NULL);
CREATE TABLE caldaq.instruments(
  run_uuid uuid NOT NULL REFERENCES caldaq.runs(uuid) ON DELETE CASCADE,
  device integer NOT NULL,
  driver text NOT NULL,
  transport text NOT NULL,
  settings_json text NOT NULL,
  origin text NOT NULL,
  origin_detail text NOT NULL,
  PRIMARY KEY(run_uuid, device));
CREATE TABLE caldaq.reading_chunks(
  run_uuid uuid NOT NULL REFERENCES caldaq.runs(uuid) ON DELETE CASCADE,
  seq bigint NOT NULL CHECK(seq >= 0),
  device integer NOT NULL,
  channel integer NOT NULL,
  quantity integer NOT NULL,
  first_ns bigint NOT NULL,
  last_ns bigint NOT NULL,
  count bigint NOT NULL,
  encoding integer NOT NULL,
  crc bigint NOT NULL,
  stored_checksum boolean NOT NULL,
  data bytea NOT NULL,
  PRIMARY KEY(run_uuid, seq));
CREATE TABLE caldaq.captured_targets(
  run_uuid uuid NOT NULL REFERENCES caldaq.runs(uuid) ON DELETE CASCADE,
  target_index integer NOT NULL,
  run_number integer NOT NULL,
  direction text NOT NULL CHECK(direction IN ('+', '-')),
  nominal_mm double precision NOT NULL,
  time_ns bigint NOT NULL,
  raw_m double precision NOT NULL,
  deviation_um double precision NOT NULL,
  refractive_index double precision NOT NULL,
  material_temperature_degc double precision NOT NULL,
  PRIMARY KEY(run_uuid, run_number, direction, target_index));
CREATE TABLE caldaq.missed_stops(
  run_uuid uuid NOT NULL REFERENCES caldaq.runs(uuid) ON DELETE CASCADE,
  run_number integer NOT NULL,
  direction text NOT NULL CHECK(direction IN ('+', '-')),
  target_index integer NOT NULL,
  nominal_mm double precision NOT NULL,
  PRIMARY KEY(run_uuid, run_number, direction, target_index));
CREATE TABLE caldaq.results(
  run_uuid uuid NOT NULL REFERENCES caldaq.runs(uuid) ON DELETE CASCADE,
  source_result_id bigint NOT NULL,
  standard text NOT NULL,
  json text NOT NULL,
  created_unix_ms bigint NOT NULL,
  provenance_json text NOT NULL,
  superseded_by bigint,
  PRIMARY KEY(run_uuid, source_result_id));
CREATE TABLE caldaq.operator_actions(
  run_uuid uuid NOT NULL REFERENCES caldaq.runs(uuid) ON DELETE CASCADE,
  ordinal integer NOT NULL,
  time_unix_ms bigint NOT NULL,
  action text NOT NULL,
  source text NOT NULL,
  operator text NOT NULL,
  run_number integer,
  direction text,
  target_index integer,
  nominal_mm double precision,
  detail text NOT NULL,
  PRIMARY KEY(run_uuid, ordinal));
)sql",
    // 2: what the read commands need beside the runs (daq show, export, report... with --db
    // postgresql://): the stop quality as rows, the compensation tables written and the ballbar
    // calibrations, each stored once (by a fingerprint of what identifies it).
    R"sql(
ALTER TABLE caldaq.runs ADD COLUMN quality_state text, ADD COLUMN quality_summary text;
CREATE TABLE caldaq.suspect_stops(
  run_uuid uuid NOT NULL REFERENCES caldaq.runs(uuid) ON DELETE CASCADE,
  ordinal integer NOT NULL,
  run_number integer NOT NULL,
  direction text NOT NULL CHECK(direction IN ('+', '-')),
  target_index integer NOT NULL,
  reason text NOT NULL,
  PRIMARY KEY(run_uuid, ordinal));
CREATE TABLE caldaq.compensations(
  id bigserial PRIMARY KEY,
  machine_id bigint REFERENCES caldaq.machines(id),
  source_run_uuid uuid,
  source text NOT NULL,
  axis text NOT NULL,
  format text NOT NULL,
  created_unix_ms bigint NOT NULL,
  json text NOT NULL,
  fingerprint text NOT NULL UNIQUE);
CREATE TABLE caldaq.bar_calibrations(
  id bigserial PRIMARY KEY,
  bar text NOT NULL,
  nominal_mm double precision NOT NULL,
  extensions text NOT NULL,
  calibrator text NOT NULL,
  calibrator_length_mm double precision NOT NULL,
  reading_mm double precision NOT NULL,
  zero_length_mm double precision NOT NULL,
  temperature_degc double precision,
  calibrated_unix_ms bigint NOT NULL,
  note text NOT NULL,
  fingerprint text NOT NULL UNIQUE);
)sql",
};
static_assert(std::size(kCentralMigrations) == central_schema_version);

}  // namespace

int migrate_schema(pqxx::connection& conn, std::string_view shown_url) {
  return guarded(shown_url, "create or migrate the central schema", [&] {
    pqxx::work w(conn);
    w.exec("SELECT pg_advisory_xact_lock(1128352836)");  // "CALD", as the SQLite application id
    w.exec("CREATE SCHEMA IF NOT EXISTS caldaq");
    w.exec("CREATE TABLE IF NOT EXISTS caldaq.schema_version(version integer NOT NULL)");
    const auto rows = w.exec("SELECT version FROM caldaq.schema_version");
    if (rows.size() > 1)
      throw StoreError(fmt::format(
          "{}: caldaq.schema_version holds {} rows, not one: not a caldaq central store", shown_url,
          rows.size()));
    int version = rows.empty() ? 0 : rows[0][0].as<int>();
    if (version > central_schema_version)
      throw StoreError(fmt::format(
          "{}: central schema version {} is newer than this daq understands ({}); use a newer "
          "daq",
          shown_url, version, central_schema_version));
    if (rows.empty()) w.exec("INSERT INTO caldaq.schema_version VALUES (0)");
    for (; version < central_schema_version; ++version) w.exec(kCentralMigrations[version]);
    w.exec_params("UPDATE caldaq.schema_version SET version = $1", version);
    w.commit();
    return version;
  });
}

}  // namespace cal::storage::pg
