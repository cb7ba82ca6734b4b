// The central schema on PostgreSQL (docs/storage.md, "Central store"), versioned in
// caldaq.schema_version like the SQLite store's user_version.
#include "central_schema.hpp"

#include <iterator>
#include <optional>

#include "cal/storage/pg/sync.hpp"
#include "fleet_schema.hpp"
#include "fleet_schema_12.hpp"
#include "fleet_schema_9.hpp"

namespace cal::storage::pg {
namespace {

// Entry k migrates from version k to k + 1, in the transaction of migrate_schema.
// Runs are keyed by their UUID, and numbered in the order the server first saw them (id: what
// `daq runs --db postgresql://...` lists); the rows of a run by the run's UUID and what identifies
// them in the store they came from (a chunk's seq, a result's local id), so that sending them again
// finds them. The chunk's checksum covers the run's id in its source store (source_run_id).
// The head of caldaq.approve(run, fingerprint): made by migration 6, and made again by 7 as the
// sites' wrapper of the first (renamed approve_any_site); each adds its DECLARE list and body.
constexpr std::string_view kApproveHead =
    R"sql(CREATE FUNCTION caldaq.approve(run uuid, fp text)
  RETURNS TABLE(approved_by text, approved_unix_ms bigint, run_version integer)
  LANGUAGE plpgsql SECURITY DEFINER SET search_path = pg_catalog, pg_temp
AS $fn$
DECLARE
)sql";

const std::string kCentralMigrations[] = {
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
    // 3 (daq sync --from): a result is known by its content's fingerprint (kResultFingerprint),
    // so the same result brought to a laptop and sent back (its local id changed) is stored
    // once, and results made apart (re-analysed on two laptops) are both kept.
    R"sql(
ALTER TABLE caldaq.results ADD COLUMN fingerprint text;
UPDATE caldaq.results SET fingerprint =
  md5(concat_ws('|', standard, created_unix_ms::text, json, provenance_json));
ALTER TABLE caldaq.results ALTER COLUMN fingerprint SET NOT NULL;
ALTER TABLE caldaq.results ADD UNIQUE (run_uuid, fingerprint);
)sql",
    // 4: the same run changed in two places (re-compensated on two laptops) is kept as versions
    // of its stops, never overwritten: each with who sent it, from where and when. The readers
    // read the current version (the newest sent); `daq show` names them all.
    R"sql(
ALTER TABLE caldaq.captured_targets ADD COLUMN version integer NOT NULL DEFAULT 1;
ALTER TABLE caldaq.captured_targets DROP CONSTRAINT captured_targets_pkey;
ALTER TABLE caldaq.captured_targets
  ADD PRIMARY KEY (run_uuid, version, run_number, direction, target_index);
ALTER TABLE caldaq.runs ADD COLUMN current_version integer NOT NULL DEFAULT 1;
CREATE FUNCTION caldaq.stops_fingerprint(run uuid, v integer) RETURNS text LANGUAGE sql STABLE
AS $$
  SELECT md5(COALESCE(string_agg(concat_ws('|', run_number, direction, target_index, nominal_mm,
    time_ns, raw_m, deviation_um, refractive_index, material_temperature_degc), ';'
    ORDER BY run_number, direction COLLATE "C", target_index), ''))
  FROM caldaq.captured_targets WHERE run_uuid = run AND version = v
$$;
CREATE TABLE caldaq.run_versions(
  run_uuid uuid NOT NULL REFERENCES caldaq.runs(uuid) ON DELETE CASCADE,
  version integer NOT NULL,
  fingerprint text NOT NULL,
  status text NOT NULL,
  sent_by text NOT NULL,
  sent_from text NOT NULL,
  sent_store text NOT NULL,
  sent_unix_ms bigint NOT NULL,
  PRIMARY KEY(run_uuid, version));
INSERT INTO caldaq.run_versions
  SELECT uuid, 1, caldaq.stops_fingerprint(uuid, 1), status, '', '', '', synced_unix_ms
  FROM caldaq.runs;
)sql",
    // 5: machines known by their stable id (the local store's machines.uuid), not by name: two
    // sites' "Mill 1" stay apart. A machine sent before (uuid NULL) is adopted by the first
    // store that sends a machine of its name (daq sync --to, server_machine).
    R"sql(
ALTER TABLE caldaq.machines ADD COLUMN uuid uuid UNIQUE;
ALTER TABLE caldaq.machines DROP CONSTRAINT machines_name_key;
CREATE INDEX machines_by_name ON caldaq.machines(name);
)sql",
    // 6 (local schema 9): users, roles and sign-off. Engineers (role caldaq_engineer) send runs;
    // reviewers (caldaq_reviewer) approve results, through caldaq.approve only, which records
    // the reviewer's login (session_user: the server authenticated it, the client cannot name
    // another) and refuses a result superseded since. Nothing for PUBLIC: a login of neither role
    // reads and writes nothing. The roles are the cluster's: made once, kept if there already.
    R"sql(
DO $roles$ BEGIN
  IF NOT EXISTS (SELECT FROM pg_roles WHERE rolname = 'caldaq_engineer') THEN
    CREATE ROLE caldaq_engineer NOLOGIN;
  END IF;
  IF NOT EXISTS (SELECT FROM pg_roles WHERE rolname = 'caldaq_reviewer') THEN
    CREATE ROLE caldaq_reviewer NOLOGIN;
  END IF;
END $roles$;
CREATE TABLE caldaq.approvals(
  run_uuid uuid NOT NULL,
  result_fingerprint text NOT NULL,
  run_version integer NOT NULL,
  approved_by text NOT NULL,
  approved_unix_ms bigint NOT NULL,
  PRIMARY KEY(run_uuid, result_fingerprint),
  FOREIGN KEY(run_uuid, result_fingerprint) REFERENCES caldaq.results(run_uuid, fingerprint)
    ON DELETE CASCADE);
)sql" + std::string(kApproveHead) +
        R"sql(  res record;
  earlier record;
  v integer;
BEGIN
  SELECT s.source_result_id AS id, s.superseded_by INTO res FROM caldaq.results AS s
    WHERE s.run_uuid = run AND s.fingerprint = fp;
  IF NOT FOUND THEN
    RAISE EXCEPTION 'no result of fingerprint % in run %', fp, run USING ERRCODE = 'no_data_found';
  END IF;
  IF res.superseded_by IS NOT NULL THEN
    RAISE EXCEPTION 'result % is superseded by result % (re-analysed or re-compensated since): it cannot be approved; approve the current one',
      res.id, res.superseded_by USING ERRCODE = 'object_not_in_prerequisite_state';
  END IF;
  SELECT a.approved_by, a.approved_unix_ms INTO earlier FROM caldaq.approvals AS a
    WHERE a.run_uuid = run AND a.result_fingerprint = fp;
  IF FOUND THEN
    RAISE EXCEPTION 'result % is approved already (by %, unix ms %)', res.id,
      earlier.approved_by, earlier.approved_unix_ms USING ERRCODE = 'unique_violation';
  END IF;
  SELECT r.current_version INTO v FROM caldaq.runs AS r WHERE r.uuid = run FOR SHARE;
  RETURN QUERY INSERT INTO caldaq.approvals AS a VALUES(run, fp, v, session_user::text,
    (extract(epoch FROM clock_timestamp()) * 1000)::bigint)
    RETURNING a.approved_by, a.approved_unix_ms, a.run_version;
END
$fn$;
REVOKE ALL ON SCHEMA caldaq FROM PUBLIC;
REVOKE ALL ON ALL TABLES IN SCHEMA caldaq FROM PUBLIC;
REVOKE ALL ON ALL FUNCTIONS IN SCHEMA caldaq FROM PUBLIC;
GRANT USAGE ON SCHEMA caldaq TO caldaq_engineer, caldaq_reviewer;
GRANT SELECT ON ALL TABLES IN SCHEMA caldaq TO caldaq_engineer, caldaq_reviewer;
GRANT INSERT, UPDATE, DELETE ON ALL TABLES IN SCHEMA caldaq TO caldaq_engineer;
REVOKE INSERT, UPDATE, DELETE ON caldaq.approvals, caldaq.schema_version FROM caldaq_engineer;
GRANT USAGE ON ALL SEQUENCES IN SCHEMA caldaq TO caldaq_engineer;
GRANT EXECUTE ON FUNCTION caldaq.stops_fingerprint(uuid, integer) TO caldaq_engineer;
GRANT EXECUTE ON FUNCTION caldaq.approve(uuid, text) TO caldaq_reviewer;
)sql",
    // 7: a site sees only its machines unless granted more (row-level security). Machines, runs
    // and compensation tables carry their site; the rows of a run (chunks, stops, results,
    // approvals, ...) are visible and writable where their run is. caldaq.site_grants says which
    // sites a login (or a role it is a member of) may read and write, '*' every site;
    // caldaq.session_sites() is the session's list, read once per statement (an InitPlan: the
    // policies wrap it in a scalar subquery). The schema's owner, superusers and BYPASSRLS roles
    // see everything (the administrator). Sites come from the runs' configuration ([customer]
    // site) for the machines already here, else 'unassigned'.
    R"sql(
CREATE FUNCTION caldaq.context_site(settings text) RETURNS text LANGUAGE plpgsql IMMUTABLE
  SET search_path = pg_catalog, pg_temp
AS $fn$
BEGIN
  RETURN NULLIF(btrim(settings::jsonb #>> '{context,customer,site}'), '');
EXCEPTION WHEN others THEN
  RETURN NULL;  -- settings that are not JSON name no site
END
$fn$;
CREATE TABLE caldaq.site_grants(
  grantee regrole NOT NULL,
  site text NOT NULL CHECK(site <> ''),
  PRIMARY KEY(grantee, site));
-- plpgsql, not sql: its query's plan is kept for the session (an sql function's is made again at
-- every statement: 0.24 ms more per chunk inserted, against 0.03 ms, measured).
CREATE FUNCTION caldaq.session_sites() RETURNS text[] LANGUAGE plpgsql STABLE SECURITY DEFINER
  SET search_path = pg_catalog, pg_temp
AS $fn$
BEGIN
  RETURN (SELECT CASE WHEN r.rolsuper OR r.rolbypassrls OR
      pg_has_role(session_user, (SELECT c.relowner FROM pg_class AS c
                                 WHERE c.oid = 'caldaq.runs'::regclass), 'MEMBER')
    THEN ARRAY['*']
    ELSE (SELECT COALESCE(array_agg(DISTINCT g.site ORDER BY g.site), '{}')
          FROM caldaq.site_grants AS g WHERE pg_has_role(session_user, g.grantee::oid, 'MEMBER'))
  END FROM pg_roles AS r WHERE r.rolname = session_user);
END
$fn$;

ALTER TABLE caldaq.machines ADD COLUMN site text;
UPDATE caldaq.machines AS m SET site = COALESCE((SELECT s.site FROM (SELECT
    caldaq.context_site(r.settings_json) AS site, r.started_unix_ms, r.id FROM caldaq.runs AS r
    WHERE r.machine_id = m.id) AS s WHERE s.site IS NOT NULL
  ORDER BY s.started_unix_ms DESC, s.id DESC LIMIT 1), 'unassigned');
ALTER TABLE caldaq.machines ALTER COLUMN site SET NOT NULL;
CREATE INDEX machines_by_site ON caldaq.machines(site);
ALTER TABLE caldaq.runs ADD COLUMN site text;
UPDATE caldaq.runs AS r SET site = COALESCE((SELECT m.site FROM caldaq.machines AS m
  WHERE m.id = r.machine_id), caldaq.context_site(r.settings_json), 'unassigned');
ALTER TABLE caldaq.runs ALTER COLUMN site SET NOT NULL;
CREATE INDEX runs_by_site ON caldaq.runs(site);
ALTER TABLE caldaq.compensations ADD COLUMN site text;
UPDATE caldaq.compensations AS c SET site = COALESCE(
  (SELECT m.site FROM caldaq.machines AS m WHERE m.id = c.machine_id),
  (SELECT r.site FROM caldaq.runs AS r WHERE r.uuid = c.source_run_uuid), 'unassigned');
ALTER TABLE caldaq.compensations ALTER COLUMN site SET NOT NULL;

-- A machine moved to another site (by the administrator) takes its runs and tables along.
CREATE FUNCTION caldaq.machine_moved() RETURNS trigger LANGUAGE plpgsql
  SET search_path = pg_catalog, pg_temp
AS $fn$
BEGIN
  UPDATE caldaq.runs SET site = NEW.site WHERE machine_id = NEW.id;
  UPDATE caldaq.compensations SET site = NEW.site WHERE machine_id = NEW.id;
  RETURN NULL;
END
$fn$;
CREATE TRIGGER machine_moved AFTER UPDATE OF site ON caldaq.machines FOR EACH ROW
  WHEN (OLD.site IS DISTINCT FROM NEW.site) EXECUTE FUNCTION caldaq.machine_moved();

-- The policies: a row of a granted site (or of a run of one). With no WITH CHECK the USING
-- expression checks the rows inserted and updated too: an INSERT for another site is refused.
ALTER TABLE caldaq.machines ENABLE ROW LEVEL SECURITY;
CREATE POLICY by_site ON caldaq.machines
  USING (ARRAY[site, '*'] && (SELECT caldaq.session_sites()));
ALTER TABLE caldaq.runs ENABLE ROW LEVEL SECURITY;
CREATE POLICY by_site ON caldaq.runs
  USING (ARRAY[site, '*'] && (SELECT caldaq.session_sites()));
ALTER TABLE caldaq.compensations ENABLE ROW LEVEL SECURITY;
CREATE POLICY by_site ON caldaq.compensations
  USING (ARRAY[site, '*'] && (SELECT caldaq.session_sites()));
DO $policies$
DECLARE
  t text;
BEGIN
  FOREACH t IN ARRAY ARRAY['instruments', 'reading_chunks', 'captured_targets', 'missed_stops',
      'results', 'operator_actions', 'suspect_stops', 'run_versions', 'approvals'] LOOP
    EXECUTE format('ALTER TABLE caldaq.%I ENABLE ROW LEVEL SECURITY', t);
    -- The run's row is looked up by its primary key under the runs' own policy.
    EXECUTE format('CREATE POLICY by_site ON caldaq.%I USING (EXISTS (SELECT 1 FROM caldaq.runs '
                   'AS r WHERE r.uuid = run_uuid))', t);
  END LOOP;
END $policies$;

-- A reviewer approves only its sites' runs: caldaq.approve runs as the schema's owner (past the
-- policies), so it checks the site itself, first, then approves as schema 6 did.
ALTER FUNCTION caldaq.approve(uuid, text) RENAME TO approve_any_site;
REVOKE ALL ON FUNCTION caldaq.approve_any_site(uuid, text) FROM PUBLIC, caldaq_reviewer;
)sql" + std::string(kApproveHead) +
        R"sql(  s text;
BEGIN
  SELECT r.site INTO s FROM caldaq.runs AS r WHERE r.uuid = run;
  IF FOUND AND NOT ARRAY[s, '*'] && caldaq.session_sites() THEN
    RAISE EXCEPTION 'run % is not of a site login % may approve (caldaq.site_grants)', run,
      session_user USING ERRCODE = 'insufficient_privilege';
  END IF;
  RETURN QUERY SELECT * FROM caldaq.approve_any_site(run, fp);
END
$fn$;

REVOKE ALL ON caldaq.site_grants FROM PUBLIC;
REVOKE ALL ON FUNCTION caldaq.context_site(text), caldaq.session_sites(),
  caldaq.machine_moved(), caldaq.approve(uuid, text) FROM PUBLIC;
GRANT EXECUTE ON FUNCTION caldaq.approve(uuid, text) TO caldaq_reviewer;
GRANT EXECUTE ON FUNCTION caldaq.context_site(text) TO caldaq_engineer;
GRANT EXECUTE ON FUNCTION caldaq.session_sites() TO caldaq_engineer, caldaq_reviewer;
GRANT EXECUTE ON FUNCTION caldaq.machine_moved() TO caldaq_engineer;
-- An engineer's sync adopts a machine sent before it had a UUID (its uuid column); which site a
-- machine is of is the administrator's.
REVOKE UPDATE ON caldaq.machines FROM caldaq_engineer;
GRANT UPDATE (uuid) ON caldaq.machines TO caldaq_engineer;
)sql",
    // 8: the fleet view's tables, kept by triggers (fleet_schema.hpp).
    kFleetMigration,
    // 9: the fleet's straightness, angular and roll runs, and each trend's window
    // (fleet_schema_9.hpp).
    kFleetKindsWindowMigration,
    // 10 (local schema 11): machine models, known by their UUID (sent twice, stored once), each
    // of a machine of the server; never changed once stored (an engineer inserts, nobody
    // updates). A model is visible and writable where its machine is: the machines' own policy
    // decides, so a machine moved to another site takes its models along.
    R"sql(
CREATE TABLE caldaq.models(
  uuid uuid PRIMARY KEY,
  id bigint GENERATED ALWAYS AS IDENTITY UNIQUE,
  machine_id bigint NOT NULL REFERENCES caldaq.machines(id),
  name text NOT NULL,
  json text NOT NULL CHECK(json <> ''),
  provenance_json text NOT NULL,
  stored_by text NOT NULL,
  stored_from text NOT NULL,
  stored_unix_ms bigint NOT NULL,
  sent_by text NOT NULL DEFAULT session_user,
  synced_unix_ms bigint NOT NULL);
CREATE INDEX models_by_machine ON caldaq.models(machine_id, id);
ALTER TABLE caldaq.models ENABLE ROW LEVEL SECURITY;
CREATE POLICY by_site ON caldaq.models
  USING (EXISTS (SELECT 1 FROM caldaq.machines AS m WHERE m.id = machine_id));
REVOKE ALL ON caldaq.models FROM PUBLIC;
GRANT SELECT ON caldaq.models TO caldaq_engineer, caldaq_reviewer;
GRANT INSERT ON caldaq.models TO caldaq_engineer;
)sql",
    // 11: a run's results tied to the version of its stops they were computed from. Each
    // version's results are those the store that sent those stops held then (its current ones
    // were computed from them; its superseded ones are its history), with that store's
    // supersessions: what the sender's own store showed. The readers read a version's results
    // only, so a version's stops are never shown beside another version's results (before,
    // two laptops' re-compensations were both "current" beside whichever stops were read).
    // Results already here: a run of one version, every result in version 1 (each sender's
    // current results were computed from its current stops, which were version 1's); a run of
    // several versions, none placed (which laptop's stops each came from was not recorded):
    // each sender's next daq sync --to places its own.
    R"sql(
CREATE TABLE caldaq.result_versions(
  run_uuid uuid NOT NULL,
  version integer NOT NULL,
  source_result_id bigint NOT NULL,
  superseded_by bigint,
  PRIMARY KEY(run_uuid, version, source_result_id),
  FOREIGN KEY(run_uuid, version) REFERENCES caldaq.run_versions(run_uuid, version)
    ON DELETE CASCADE,
  FOREIGN KEY(run_uuid, source_result_id) REFERENCES caldaq.results(run_uuid, source_result_id)
    ON DELETE CASCADE);
INSERT INTO caldaq.result_versions
  SELECT s.run_uuid, 1, s.source_result_id, s.superseded_by FROM caldaq.results AS s
  WHERE (SELECT count(*) FROM caldaq.run_versions AS v WHERE v.run_uuid = s.run_uuid) = 1;
ALTER TABLE caldaq.result_versions ENABLE ROW LEVEL SECURITY;
CREATE POLICY by_site ON caldaq.result_versions
  USING (EXISTS (SELECT 1 FROM caldaq.runs AS r WHERE r.uuid = run_uuid));
GRANT SELECT ON caldaq.result_versions TO caldaq_engineer, caldaq_reviewer;
GRANT INSERT, UPDATE, DELETE ON caldaq.result_versions TO caldaq_engineer;
)sql",
    // 12: the fleet's current results those of the run's current version, daq's verdict stored
    // with each result, an approval's version the result's own (fleet_schema_12.hpp).
    kFleetCurrentVerdictMigration,
    // 13: the fleet's first view read in rows that grow with the machines, not with the results
    // synced (docs/benchmarks.md, "The fleet view at 1,000 machines"). Each result synced
    // refreshes its test's row in fleet_tests (deleted and inserted), leaving a dead row until
    // autovacuum: 1,000 machines x 10 years loaded left 4,002 rows in 1,528 pages (12 MB), which
    // the sites' count of failing machines scanned whole (125 ms warm, 365 ms from disk, at load
    // 12). The failing tests' own index: the count probes it once per machine.
    R"sql(
CREATE INDEX fleet_tests_failing ON caldaq.fleet_tests(machine_id) WHERE verdict = 'fail';
)sql",
};
static_assert(std::size(kCentralMigrations) == central_schema_version);

}  // namespace

std::string result_fingerprint(pqxx::transaction_base& t, const ResultRecord& r) {
  return t
      .exec_params1("SELECT md5(concat_ws('|', $1::text, $2::bigint::text, $3::text, $4::text))",
                    r.standard, r.created_unix_ms, r.json, r.provenance_json)[0]
      .as<std::string>();
}

namespace {

// The schema's version where it is there and readable, else nullopt: what a login that may not
// create or alter anything (an engineer's) needs to send to a server already migrated.
std::optional<int> present_version(pqxx::connection& conn) {
  pqxx::nontransaction n(conn);
  if (n.exec1("SELECT to_regclass('caldaq.schema_version') IS NULL")[0].as<bool>())
    return std::nullopt;
  const auto rows = n.exec("SELECT version FROM caldaq.schema_version");
  if (rows.size() != 1) return std::nullopt;
  return rows[0][0].as<int>();
}

}  // namespace

void check_reader_schema(pqxx::connection& conn, std::string_view shown_url) {
  pqxx::nontransaction n(conn);
  if (n.exec1("SELECT to_regclass('caldaq.schema_version') IS NULL")[0].as<bool>())
    throw StoreError(fmt::format(
        "{}: no caldaq central store in this database (daq sync --to creates it)", shown_url));
  const auto rows = n.exec("SELECT version FROM caldaq.schema_version");
  const int version = rows.size() == 1 ? rows[0][0].as<int>() : -1;
  // An older version lacks what the readers read (version 1: the stop quality, the compensation
  // tables, the ballbar calibrations; 6: the fleet view's tables): a sync by this daq migrates it.
  if (version < central_schema_version)
    throw StoreError(fmt::format(
        "{}: central schema version {} is older than this daq reads ({}): a daq sync --to by "
        "this daq migrates it",
        shown_url, version, central_schema_version));
  if (version > central_schema_version)
    throw StoreError(fmt::format(
        "{}: central schema version {} is newer than this daq reads ({}); use a newer daq",
        shown_url, version, central_schema_version));
}

int migrate_schema(pqxx::connection& conn, std::string_view shown_url) {
  // Migrating takes the schema owner's rights; sending to a migrated server does not.
  if (guarded(shown_url, "read the central schema version",
              [&] { return present_version(conn); }) == central_schema_version)
    return central_schema_version;
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
