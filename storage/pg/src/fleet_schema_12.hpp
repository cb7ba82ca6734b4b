#pragma once
// Central schema 12 (issue 35; docs/storage.md "The fleet view's tables" and "Sign-off"): what the
// fleet view counts as a run's current results, daq's own verdict stored with each result, and
// the version an approval records. Private to storage/pg (central_schema.cpp includes it). The
// functions of schemas 7-9 that change are replaced here whole (CREATE OR REPLACE); their earlier
// text (central_schema.cpp, fleet_schema_9.hpp) is history.
//
// - Current: a result is current for the fleet (trends, latest verdicts, awaiting approval) when
//   it is an unsuperseded result of its run's current version (result_versions, schema 11:
//   caldaq.fleet_is_current), as `daq show` reads a run. Before, every result without a
//   superseder counted, so a run re-compensated on two laptops counted both laptops' results.
//   The flags follow result_versions and runs.current_version by triggers (fleet_mark_current);
//   a result of no version yet (a run of several versions synced before schema 11, until its
//   laptops sync again) is current nowhere, as `daq show` shows none.
// - Verdict: caldaq.results.verdict ('pass', 'fail', 'none': no limit applies) and
//   verdict_failed (the symbols of the values that failed, ', ' between them, in byte order),
//   computed by daq (daq/src/results/verdict.cpp, the value as printed by cal::fixed_text against
//   its limit) when `daq sync --to` sends the result, and again when the run's settings or the
//   result change there. The fleet reads them; the server no longer judges (schema 8's SQL
//   verdict was a second copy of daq's rule for five kinds of run). NULL: not judged yet (the
//   results of a schema 11 server, until the sync that migrates it judges them; see sync.cpp),
//   shown as 'none'. The limits beside the trends (fleet_values.limit_value) are still looked up
//   here (fleet_result_values): they draw the line, they decide no verdict.
// - Approval: caldaq.approve records the version of the stops the approved result was computed
//   from (the version in which it is not superseded), not the run's current version; it refuses a
//   result superseded by its own store (in every version that holds it, or in a later version sent
//   from the store that sent its own) and one of no version yet.
// Written to be run again over itself (IF NOT EXISTS, OR REPLACE, DROP ... IF EXISTS): the tests'
// pg_undo_central_12 takes a server back to 11 by dropping what it added.

namespace cal::storage::pg {

inline constexpr const char* kFleetCurrentVerdictMigration = R"sql(
ALTER TABLE caldaq.results ADD COLUMN IF NOT EXISTS verdict text
    CHECK (verdict IN ('pass', 'fail', 'none')),
  ADD COLUMN IF NOT EXISTS verdict_failed text;
CREATE INDEX IF NOT EXISTS results_without_verdict ON caldaq.results(run_uuid)
  WHERE verdict IS NULL;

-- The one rule of "current" on the server.
CREATE OR REPLACE FUNCTION caldaq.fleet_is_current(run uuid, result bigint) RETURNS boolean
  LANGUAGE sql STABLE AS $$
  SELECT EXISTS (SELECT FROM caldaq.result_versions AS m JOIN caldaq.runs AS r
                   ON r.uuid = m.run_uuid AND m.version = r.current_version
                 WHERE m.run_uuid = run AND m.source_result_id = result
                   AND m.superseded_by IS NULL)
$$;

-- A run's results marked current or not again (its current version or a result's place in a
-- version changed); the tests of the results that changed refreshed.
CREATE OR REPLACE FUNCTION caldaq.fleet_mark_current(run uuid) RETURNS void LANGUAGE plpgsql AS $$
DECLARE
  changed integer;
BEGIN
  UPDATE caldaq.fleet_results AS f SET current = NOT f.current
    WHERE f.run_uuid = run AND f.current <> caldaq.fleet_is_current(run, f.result_id);
  GET DIAGNOSTICS changed = ROW_COUNT;
  IF changed = 0 THEN
    RETURN;
  END IF;
  UPDATE caldaq.fleet_values AS v SET current = f.current FROM caldaq.fleet_results AS f
    WHERE v.run_uuid = run AND f.run_uuid = run AND f.result_id = v.result_id
      AND v.current <> f.current;
  PERFORM caldaq.fleet_refresh(s.machine_id, s.kind, s.test)
    FROM (SELECT DISTINCT x.machine_id, x.kind, x.test FROM caldaq.fleet_results AS x
          WHERE x.run_uuid = run) AS s;
END $$;

CREATE OR REPLACE FUNCTION caldaq.fleet_version_changed() RETURNS trigger LANGUAGE plpgsql
  SECURITY DEFINER SET search_path = pg_catalog, pg_temp AS $$
BEGIN
  IF TG_TABLE_NAME = 'runs' THEN
    PERFORM caldaq.fleet_mark_current(NEW.uuid);
  ELSIF TG_OP = 'DELETE' THEN
    PERFORM caldaq.fleet_mark_current(OLD.run_uuid);
  ELSE
    PERFORM caldaq.fleet_mark_current(NEW.run_uuid);
  END IF;
  RETURN NULL;
END $$;
DROP TRIGGER IF EXISTS fleet_result_version ON caldaq.result_versions;
CREATE TRIGGER fleet_result_version AFTER INSERT OR DELETE ON caldaq.result_versions
  FOR EACH ROW EXECUTE FUNCTION caldaq.fleet_version_changed();
-- Each sync writes every result's place again (INSERT ... ON CONFLICT DO UPDATE): only a change
-- of its superseder counts.
DROP TRIGGER IF EXISTS fleet_result_version_superseded ON caldaq.result_versions;
CREATE TRIGGER fleet_result_version_superseded AFTER UPDATE OF superseded_by
  ON caldaq.result_versions FOR EACH ROW
  WHEN (OLD.superseded_by IS DISTINCT FROM NEW.superseded_by)
  EXECUTE FUNCTION caldaq.fleet_version_changed();
DROP TRIGGER IF EXISTS fleet_current_version ON caldaq.runs;
CREATE TRIGGER fleet_current_version AFTER UPDATE OF current_version ON caldaq.runs
  FOR EACH ROW WHEN (OLD.current_version IS DISTINCT FROM NEW.current_version)
  EXECUTE FUNCTION caldaq.fleet_version_changed();

-- Schema 9's, with "current" by caldaq.fleet_is_current and the verdict as daq stored it.
CREATE OR REPLACE FUNCTION caldaq.fleet_result_changed() RETURNS trigger LANGUAGE plpgsql SECURITY DEFINER
  SET search_path = pg_catalog, pg_temp AS $$
DECLARE
  r record;
  d jsonb;
  v_test text;
  v_current boolean;
  was_machine bigint;
  was_kind text;
  was_test text;
BEGIN
  -- Without a foreign key to the results (this trigger removes their rows, then refreshes).
  IF TG_OP <> 'INSERT' THEN
    SELECT machine_id, kind, test INTO was_machine, was_kind, was_test FROM caldaq.fleet_results
      WHERE run_uuid = OLD.run_uuid AND result_id = OLD.source_result_id;
    DELETE FROM caldaq.fleet_results WHERE run_uuid = OLD.run_uuid AND result_id = OLD.source_result_id;
  END IF;
  IF TG_OP <> 'DELETE' THEN
    d := caldaq.fleet_jsonb(NEW.json);
    IF jsonb_typeof(d) IS DISTINCT FROM 'object' THEN d := '{}'; END IF;
    SELECT u.id, u.kind, u.axis, COALESCE(u.machine_id, 0) AS machine_id, u.started_unix_ms,
        f.tolerances INTO r
      FROM caldaq.runs AS u LEFT JOIN caldaq.fleet_runs AS f ON f.run_uuid = u.uuid
      WHERE u.uuid = NEW.run_uuid;
    -- A circle's test is its plane, feed and radius (as daq ballbar history groups them).
    v_test := CASE WHEN caldaq.fleet_text(d, 'schema') LIKE 'caldaq.circle.%' THEN
        concat_ws(' ', COALESCE(NULLIF(caldaq.fleet_text(d, 'plane'), ''), r.axis),
                  'F' || caldaq.fleet_number(d -> 'feed_mm_per_min')::text,
                  'R' || caldaq.fleet_number(d -> 'radius_mm')::text)
      WHEN caldaq.fleet_text(d, 'schema') = 'caldaq.profile.v1' THEN
        COALESCE(NULLIF(caldaq.fleet_text(d, 'component'), ''), r.axis)
      ELSE r.axis END;
    v_current := caldaq.fleet_is_current(NEW.run_uuid, NEW.source_result_id);
    INSERT INTO caldaq.fleet_results VALUES (NEW.run_uuid, NEW.source_result_id, r.id,
      r.machine_id, r.started_unix_ms, r.kind, v_test, NEW.standard, NEW.created_unix_ms,
      NEW.fingerprint, v_current,
      EXISTS (SELECT FROM caldaq.approvals AS a WHERE a.run_uuid = NEW.run_uuid
              AND a.result_fingerprint = NEW.fingerprint),
      COALESCE(NEW.verdict, 'none'), COALESCE(NEW.verdict_failed, ''));
    INSERT INTO caldaq.fleet_values
      SELECT NEW.run_uuid, NEW.source_result_id, r.machine_id, r.started_unix_ms, r.kind, v_test,
        p.key, p.symbol, p.unit, p.value, p.limit_value, p.trend, v_current
      FROM caldaq.fleet_result_values(d, r.tolerances) AS p;
    -- A new result of no current version yet changes no test (the sync places it in its
    -- version next: fleet_mark_current refreshes then), so one refresh per result sent.
    IF v_current OR TG_OP <> 'INSERT' THEN
      PERFORM caldaq.fleet_refresh(r.machine_id, r.kind, v_test);
    END IF;
    IF was_machine = r.machine_id AND was_kind = r.kind AND was_test = v_test THEN
      RETURN NULL;  -- refreshed already
    END IF;
  END IF;
  IF was_machine IS NOT NULL THEN
    PERFORM caldaq.fleet_refresh(was_machine, was_kind, was_test);
  END IF;
  RETURN NULL;
END $$;
DROP TRIGGER IF EXISTS fleet_result ON caldaq.results;
CREATE TRIGGER fleet_result AFTER INSERT OR DELETE OR UPDATE OF json, superseded_by, standard,
  created_unix_ms, fingerprint, verdict, verdict_failed ON caldaq.results
  FOR EACH ROW EXECUTE FUNCTION caldaq.fleet_result_changed();

-- Schema 7's approve_any_site (the sites' check is caldaq.approve's, before it), recording the
-- approved result's own version.
CREATE OR REPLACE FUNCTION caldaq.approve_any_site(run uuid, fp text)
  RETURNS TABLE(approved_by text, approved_unix_ms bigint, run_version integer)
  LANGUAGE plpgsql SECURITY DEFINER SET search_path = pg_catalog, pg_temp
AS $fn$
DECLARE
  res record;
  earlier record;
  later record;
  v integer;
BEGIN
  SELECT s.source_result_id AS id INTO res FROM caldaq.results AS s
    WHERE s.run_uuid = run AND s.fingerprint = fp;
  IF NOT FOUND THEN
    RAISE EXCEPTION 'no result of fingerprint % in run %', fp, run USING ERRCODE = 'no_data_found';
  END IF;
  -- Its version: that of the stops it was computed from, where it is not superseded (the run's
  -- current version first, should a result be so in two). The run's row is held as before.
  PERFORM FROM caldaq.runs AS r WHERE r.uuid = run FOR SHARE;
  SELECT m.version INTO v FROM caldaq.result_versions AS m JOIN caldaq.runs AS r
      ON r.uuid = m.run_uuid
    WHERE m.run_uuid = run AND m.source_result_id = res.id AND m.superseded_by IS NULL
    ORDER BY m.version = r.current_version DESC, m.version DESC LIMIT 1;
  -- Superseded by its own store: in every version that holds it, or in a later version sent
  -- from the store that sent its own (that laptop re-analysed or re-compensated it since). One
  -- superseded only in another laptop's version (which brought it and re-compensated) is still
  -- the result of its own version's stops.
  SELECT m.superseded_by AS id INTO later FROM caldaq.result_versions AS m
      JOIN caldaq.run_versions AS w ON w.run_uuid = m.run_uuid AND w.version = m.version
      LEFT JOIN caldaq.run_versions AS o ON o.run_uuid = m.run_uuid AND o.version = v
    WHERE m.run_uuid = run AND m.source_result_id = res.id AND m.superseded_by IS NOT NULL
      AND (v IS NULL OR (m.version > v AND w.sent_store = o.sent_store
                         AND w.sent_from = o.sent_from))
    ORDER BY m.version DESC LIMIT 1;
  IF FOUND THEN
    RAISE EXCEPTION 'result % is superseded by result % (re-analysed or re-compensated since): it cannot be approved; approve the current one',
      res.id, later.id USING ERRCODE = 'object_not_in_prerequisite_state';
  END IF;
  IF v IS NULL THEN
    RAISE EXCEPTION 'result % is of no version of the run''s stops yet (sent before central schema 11 to a run changed in more than one place): a daq sync --to by the laptop that computed it places it; approve it then',
      res.id USING ERRCODE = 'object_not_in_prerequisite_state';
  END IF;
  SELECT a.approved_by, a.approved_unix_ms INTO earlier FROM caldaq.approvals AS a
    WHERE a.run_uuid = run AND a.result_fingerprint = fp;
  IF FOUND THEN
    RAISE EXCEPTION 'result % is approved already (by %, unix ms %)', res.id,
      earlier.approved_by, earlier.approved_unix_ms USING ERRCODE = 'unique_violation';
  END IF;
  RETURN QUERY INSERT INTO caldaq.approvals AS a VALUES(run, fp, v, session_user::text,
    (extract(epoch FROM clock_timestamp()) * 1000)::bigint)
    RETURNING a.approved_by, a.approved_unix_ms, a.run_version;
END
$fn$;

REVOKE ALL ON FUNCTION caldaq.fleet_is_current(uuid, bigint), caldaq.fleet_mark_current(uuid),
  caldaq.fleet_version_changed() FROM PUBLIC;

-- What the server holds: every result's flag by the new rule, and the tests whose results
-- changed refreshed (their verdicts stay as schema 8 judged them until the sync that migrates
-- judges every result, sync.cpp).
DO $mark$ BEGIN
  PERFORM caldaq.fleet_mark_current(x.run_uuid)
    FROM (SELECT DISTINCT f.run_uuid FROM caldaq.fleet_results AS f) AS x;
END $mark$;
)sql";

}  // namespace cal::storage::pg
