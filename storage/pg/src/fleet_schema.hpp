#pragma once
// Central schema 8 (issue 35, the fleet view; docs/storage.md "The fleet view"): what the fleet
// page reads, kept beside the runs by triggers on the server, so that the page's few queries
// never parse a result's document or a run's settings (120,000 of each at 1,000 machines x 10
// years) and never touch a reading. Private to storage/pg (central_schema.cpp includes it).
//
// - fleet_runs: per run, its machine, start, kind, site (context.customer.site) and the
//   tolerances it was made with (context.tolerances, as jsonb).
// - fleet_results: per result, its test (a linear or rotary run's axis; a circle's plane, feed
//   and radius, as `daq ballbar history` groups them), whether it is current, and its verdict
//   (pass, fail or none: no limit applies) with the values that failed.
// - fleet_values: per result, each value a verdict reads (ISO 230-2 E, R, B, A, M or VDI/DGQ
//   3441 P, Pa, Ps max, U max; a circle's G and each diagnostic) with its limit; `trend` marks the
//   values whose trend the page plots (E and M; G, squareness, scale and servo mismatch, and every
//   diagnostic with a limit).
// - fleet_instruments: per instrument (its driver and serial number, or its id on the machine
//   when no serial number is stated), the latest run that named it, with its certificate and
//   calibration due date (context.instruments).
//
// The verdict is computed as daq's own (daq/src/results/verdict.cpp): a value passes when its
// magnitude rounded to 0.001 of its unit is at most the limit; a linear axis's limits for its
// measured travel (by_length); the limits of the other family (ISO or VDI) not applied; ISO
// 230-4:1996's G per direction. tests/cli/pg_fleet_test.sh checks both agree on the demo's runs.
// The triggers are SECURITY DEFINER: an engineer's sync fills these tables without rights on them.

namespace cal::storage::pg {

inline constexpr const char* kFleetMigration = R"sql(
CREATE TABLE caldaq.fleet_runs(
  run_uuid uuid PRIMARY KEY REFERENCES caldaq.runs(uuid) ON DELETE CASCADE,
  machine_id bigint,
  started_unix_ms bigint NOT NULL,
  kind text NOT NULL,
  site text NOT NULL,
  tolerances jsonb);
CREATE INDEX fleet_runs_by_machine ON caldaq.fleet_runs(machine_id, started_unix_ms DESC);
CREATE TABLE caldaq.fleet_results(
  run_uuid uuid NOT NULL,
  result_id bigint NOT NULL,
  run_id bigint NOT NULL,
  machine_id bigint NOT NULL,
  started_unix_ms bigint NOT NULL,
  kind text NOT NULL,
  test text NOT NULL,
  standard text NOT NULL,
  created_unix_ms bigint NOT NULL,
  fingerprint text NOT NULL,
  current boolean NOT NULL,
  approved boolean NOT NULL,
  verdict text NOT NULL CHECK(verdict IN ('pass', 'fail', 'none')),
  failed text NOT NULL,
  PRIMARY KEY(run_uuid, result_id));
CREATE INDEX fleet_results_of_test ON caldaq.fleet_results(machine_id, kind, test, started_unix_ms DESC)
  WHERE current;
CREATE INDEX fleet_results_awaiting ON caldaq.fleet_results(started_unix_ms DESC)
  WHERE current AND NOT approved;
CREATE INDEX fleet_results_by_fingerprint ON caldaq.fleet_results(run_uuid, fingerprint);
CREATE TABLE caldaq.fleet_values(
  run_uuid uuid NOT NULL,
  result_id bigint NOT NULL,
  machine_id bigint NOT NULL,
  started_unix_ms bigint NOT NULL,
  kind text NOT NULL,
  test text NOT NULL,
  key text NOT NULL,
  symbol text NOT NULL,
  unit text NOT NULL,
  value double precision NOT NULL,
  limit_value double precision,
  trend boolean NOT NULL,
  current boolean NOT NULL,
  PRIMARY KEY(run_uuid, result_id, key),
  FOREIGN KEY(run_uuid, result_id) REFERENCES caldaq.fleet_results ON DELETE CASCADE);
CREATE INDEX fleet_values_trend ON caldaq.fleet_values(machine_id, kind, test, key, started_unix_ms)
  WHERE current AND trend;
-- Per test of a machine, its latest current result; per trend series, its line (kept by
-- caldaq.fleet_refresh when one of their results changes: the page reads these few rows).
CREATE TABLE caldaq.fleet_tests(
  machine_id bigint NOT NULL,
  kind text NOT NULL,
  test text NOT NULL,
  run_uuid uuid NOT NULL,
  result_id bigint NOT NULL,
  run_id bigint NOT NULL,
  started_unix_ms bigint NOT NULL,
  verdict text NOT NULL,
  failed text NOT NULL,
  PRIMARY KEY(machine_id, kind, test));
CREATE TABLE caldaq.fleet_series(
  machine_id bigint NOT NULL,
  kind text NOT NULL,
  test text NOT NULL,
  key text NOT NULL,
  symbol text NOT NULL,
  unit text NOT NULL,
  runs bigint NOT NULL,
  slope_per_ms double precision,
  intercept double precision,
  first_unix_ms bigint NOT NULL,
  last_unix_ms bigint NOT NULL,
  latest double precision NOT NULL,
  limit_value double precision,
  PRIMARY KEY(machine_id, kind, test, key));
CREATE TABLE caldaq.fleet_instruments(
  instrument text PRIMARY KEY,
  id text NOT NULL,
  role text NOT NULL,
  driver text NOT NULL,
  serial_number text NOT NULL,
  certificate text NOT NULL,
  calibration_due text NOT NULL,
  machine_id bigint,
  site text NOT NULL,
  run_uuid uuid NOT NULL,
  last_used_unix_ms bigint NOT NULL);

-- A document that is not JSON (never written by daq) gives no fleet rows rather than a failed sync.
CREATE FUNCTION caldaq.fleet_jsonb(t text) RETURNS jsonb LANGUAGE plpgsql IMMUTABLE AS $$
BEGIN
  RETURN t::jsonb;
EXCEPTION WHEN others THEN
  RETURN NULL;
END $$;

CREATE FUNCTION caldaq.fleet_text(j jsonb, k text) RETURNS text LANGUAGE sql IMMUTABLE AS $$
  SELECT CASE WHEN jsonb_typeof(j -> k) = 'string' THEN j ->> k ELSE '' END
$$;

CREATE FUNCTION caldaq.fleet_number(j jsonb) RETURNS double precision LANGUAGE sql IMMUTABLE AS $$
  SELECT CASE WHEN jsonb_typeof(j) = 'number' THEN (j #>> '{}')::double precision END
$$;

CREATE FUNCTION caldaq.fleet_run_changed() RETURNS trigger LANGUAGE plpgsql SECURITY DEFINER
  SET search_path = pg_catalog, pg_temp AS $$
DECLARE
  ctx jsonb := COALESCE(caldaq.fleet_jsonb(NEW.settings_json) -> 'context', '{}');
  site text := COALESCE(caldaq.fleet_text(ctx -> 'customer', 'site'), '');
BEGIN
  IF jsonb_typeof(ctx) <> 'object' THEN ctx := '{}'; END IF;
  INSERT INTO caldaq.fleet_runs VALUES (NEW.uuid, NEW.machine_id, NEW.started_unix_ms, NEW.kind, site,
    CASE WHEN jsonb_typeof(ctx -> 'tolerances') = 'object' THEN ctx -> 'tolerances' END)
  ON CONFLICT (run_uuid) DO UPDATE SET machine_id = EXCLUDED.machine_id,
    started_unix_ms = EXCLUDED.started_unix_ms, kind = EXCLUDED.kind, site = EXCLUDED.site,
    tolerances = EXCLUDED.tolerances;
  INSERT INTO caldaq.fleet_instruments AS f
    SELECT DISTINCT ON (key) key, caldaq.fleet_text(i, 'id'), caldaq.fleet_text(i, 'role'),
      caldaq.fleet_text(i, 'driver'), caldaq.fleet_text(i, 'serial_number'),
      caldaq.fleet_text(i, 'certificate'), caldaq.fleet_text(i, 'calibration_due'),
      NEW.machine_id, site, NEW.uuid, NEW.started_unix_ms
    FROM jsonb_array_elements(CASE WHEN jsonb_typeof(ctx -> 'instruments') = 'array'
                                   THEN ctx -> 'instruments' ELSE '[]' END) AS i,
      LATERAL (SELECT CASE WHEN caldaq.fleet_text(i, 'serial_number') <> ''
        THEN 'serial ' || caldaq.fleet_text(i, 'driver') || ' ' || caldaq.fleet_text(i, 'serial_number')
        ELSE 'machine ' || COALESCE(NEW.machine_id::text, '') || ' ' || caldaq.fleet_text(i, 'id')
        END AS key) AS k
    WHERE jsonb_typeof(i) = 'object'
  ON CONFLICT (instrument) DO UPDATE SET id = EXCLUDED.id, role = EXCLUDED.role,
    driver = EXCLUDED.driver, certificate = EXCLUDED.certificate,
    calibration_due = EXCLUDED.calibration_due, machine_id = EXCLUDED.machine_id,
    site = EXCLUDED.site, run_uuid = EXCLUDED.run_uuid, last_used_unix_ms = EXCLUDED.last_used_unix_ms
    WHERE EXCLUDED.last_used_unix_ms >= f.last_used_unix_ms;
  -- The run's results were judged by the tolerances and dated by the start it had then.
  IF TG_OP = 'UPDATE' AND (OLD.settings_json IS DISTINCT FROM NEW.settings_json
      OR OLD.machine_id IS DISTINCT FROM NEW.machine_id OR OLD.started_unix_ms <> NEW.started_unix_ms
      OR OLD.kind <> NEW.kind) THEN
    UPDATE caldaq.results SET json = json WHERE run_uuid = NEW.uuid;
  END IF;
  RETURN NULL;
END $$;

-- The values of a result that a verdict reads, with their limits (as verdict.cpp applies them).
CREATE FUNCTION caldaq.fleet_result_values(d jsonb, tol jsonb)
  RETURNS TABLE(key text, symbol text, unit text, value double precision,
                limit_value double precision, trend boolean)
  LANGUAGE plpgsql IMMUTABLE AS $$
DECLARE
  schema text := caldaq.fleet_text(d, 'schema');
  lim jsonb := COALESCE(tol, '{}');
  travel double precision;
  e jsonb;
  v_bi boolean := COALESCE(d -> 'bidirectional' <> 'false'::jsonb, true);
  suffix text;
  vkey text;
  v_vdi boolean := COALESCE((d -> 'axis') ? 'P', false);
  iso jsonb := COALESCE(d -> 'iso230_4', '{}');
BEGIN
  IF schema IN ('caldaq.iso230-2.v1', 'caldaq.rotary.v1') THEN
    IF schema = 'caldaq.iso230-2.v1' THEN
      suffix := '_um'; vkey := 'value_um';
      -- The limits for the measured travel: the first by_length entry long enough.
      SELECT max(caldaq.fleet_number(t -> 'target_mm')) - min(caldaq.fleet_number(t -> 'target_mm'))
        INTO travel FROM jsonb_array_elements(CASE WHEN jsonb_typeof(d -> 'targets') = 'array'
                                                   THEN d -> 'targets' ELSE '[]' END) AS t;
      SELECT x INTO e FROM jsonb_array_elements(CASE WHEN jsonb_typeof(lim -> 'by_length') = 'array'
                                                     THEN lim -> 'by_length' ELSE '[]' END)
                           WITH ORDINALITY AS b(x, n)
        WHERE COALESCE(travel, 0) <= caldaq.fleet_number(x -> 'up_to_mm') + 1e-9 ORDER BY n LIMIT 1;
      IF e IS NOT NULL THEN lim := lim || (e - 'up_to_mm'); END IF;
    ELSE
      suffix := '_arcsec'; vkey := 'value';
    END IF;
    RETURN QUERY
      SELECT m.k, COALESCE(caldaq.fleet_text(d -> 'axis' -> vk.k, 'symbol'), m.k),
        trim(leading '_' from suffix), caldaq.fleet_number(d -> 'axis' -> vk.k -> vkey),
        caldaq.fleet_number(lim -> (m.k || suffix)), m.k IN ('E', 'M')
      FROM (VALUES ('E', 'E_bi', 'E_up', false), ('R', 'R_bi', 'R_up', false), ('B', 'B', NULL, false),
                   ('A', 'A_bi', 'A_up', false), ('M', 'M', NULL, false), ('P', 'P', NULL, true),
                   ('Pa', 'Pa', NULL, true), ('Ps', 'Ps_max', NULL, true), ('U', 'U_max', NULL, true))
             AS m(k, bi_key, up_key, vdi),
        LATERAL (SELECT CASE WHEN v_bi THEN m.bi_key ELSE m.up_key END AS k) AS vk
      WHERE m.vdi = v_vdi AND vk.k IS NOT NULL
        AND caldaq.fleet_number(d -> 'axis' -> vk.k -> vkey) IS NOT NULL;
  ELSIF schema IN ('caldaq.circle.v1', 'caldaq.circle.v2') THEN
    IF iso ? 'G_bi_um' THEN
      RETURN QUERY SELECT 'G'::text, 'G'::text, 'um'::text,
        caldaq.fleet_number(iso -> 'G_bi_um'), caldaq.fleet_number(lim -> 'G_um'), true;
    ELSE  -- ISO 230-4:1996 has no G(b): the limit applies to each direction's G
      RETURN QUERY SELECT g.k, g.s, 'um'::text, caldaq.fleet_number(iso -> g.j),
          caldaq.fleet_number(lim -> 'G_um'), true
        FROM (VALUES ('G ccw', 'G (ccw)', 'G_ccw_um'), ('G cw', 'G (cw)', 'G_cw_um')) AS g(k, s, j)
        WHERE caldaq.fleet_number(iso -> g.j) > 0;
    END IF;
    RETURN QUERY
      SELECT DISTINCT ON (caldaq.fleet_text(x, 'key')) caldaq.fleet_text(x, 'key'),
        COALESCE(NULLIF(caldaq.fleet_text(x, 'name'), ''), caldaq.fleet_text(x, 'key')),
        caldaq.fleet_text(x, 'unit'), caldaq.fleet_number(x -> 'value'),
        caldaq.fleet_number(lim -> 'diagnostics' -> caldaq.fleet_text(x, 'key')),
        caldaq.fleet_text(x, 'key') IN ('squareness', 'scale_mismatch', 'servo_mismatch')
          OR caldaq.fleet_number(lim -> 'diagnostics' -> caldaq.fleet_text(x, 'key')) IS NOT NULL
      FROM jsonb_array_elements(CASE WHEN jsonb_typeof(d -> 'diagnostics') = 'array'
                                     THEN d -> 'diagnostics' ELSE '[]' END) WITH ORDINALITY AS a(x, n)
      WHERE caldaq.fleet_text(x, 'key') <> '' AND caldaq.fleet_number(x -> 'value') IS NOT NULL
      ORDER BY caldaq.fleet_text(x, 'key'), n DESC;  -- verdict.cpp takes the last of a key
  END IF;
END $$;

-- A test's latest verdict and its series' lines, from its current results (the index
-- fleet_results_of_test, fleet_values_trend: some tens of rows).
CREATE FUNCTION caldaq.fleet_refresh(m bigint, k text, t text) RETURNS void LANGUAGE sql AS $$
  DELETE FROM caldaq.fleet_tests WHERE machine_id = m AND kind = k AND test = t;
  INSERT INTO caldaq.fleet_tests
    SELECT machine_id, kind, test, run_uuid, result_id, run_id, started_unix_ms, verdict, failed
    FROM caldaq.fleet_results WHERE machine_id = m AND kind = k AND test = t AND current
    ORDER BY started_unix_ms DESC, result_id DESC LIMIT 1;
  DELETE FROM caldaq.fleet_series WHERE machine_id = m AND kind = k AND test = t;
  INSERT INTO caldaq.fleet_series
    SELECT m, k, t, key, min(symbol), min(unit), count(*),
      regr_slope(value, started_unix_ms::float8), regr_intercept(value, started_unix_ms::float8),
      min(started_unix_ms), max(started_unix_ms),
      (array_agg(value ORDER BY started_unix_ms DESC, result_id DESC))[1],
      (array_agg(limit_value ORDER BY started_unix_ms DESC, result_id DESC))[1]
    FROM caldaq.fleet_values WHERE machine_id = m AND kind = k AND test = t AND current AND trend
    GROUP BY key;
$$;

CREATE FUNCTION caldaq.fleet_result_changed() RETURNS trigger LANGUAGE plpgsql SECURITY DEFINER
  SET search_path = pg_catalog, pg_temp AS $$
DECLARE
  r record;
  d jsonb;
  v_test text;
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
      ELSE r.axis END;
    WITH p AS (SELECT * FROM caldaq.fleet_result_values(d, r.tolerances)),
    verdict AS (
      INSERT INTO caldaq.fleet_results
        SELECT NEW.run_uuid, NEW.source_result_id, r.id, r.machine_id, r.started_unix_ms, r.kind,
          v_test, NEW.standard, NEW.created_unix_ms, NEW.fingerprint, NEW.superseded_by IS NULL,
          EXISTS (SELECT FROM caldaq.approvals AS a WHERE a.run_uuid = NEW.run_uuid
                  AND a.result_fingerprint = NEW.fingerprint),
          CASE WHEN count(p.limit_value) = 0 THEN 'none'
               WHEN bool_and(round(abs(p.value)::numeric, 3) <= p.limit_value + 1e-12)
                    FILTER (WHERE p.limit_value IS NOT NULL) THEN 'pass'
               ELSE 'fail' END,
          COALESCE(string_agg(p.symbol, ', ' ORDER BY p.symbol COLLATE "C")
                   FILTER (WHERE round(abs(p.value)::numeric, 3) > p.limit_value + 1e-12), '')
        FROM p
        RETURNING 1)
    INSERT INTO caldaq.fleet_values
      SELECT NEW.run_uuid, NEW.source_result_id, r.machine_id, r.started_unix_ms, r.kind, v_test,
        p.key, p.symbol, p.unit, p.value, p.limit_value, p.trend, NEW.superseded_by IS NULL
      FROM p, (SELECT count(*) FROM verdict) AS after_verdict;
    PERFORM caldaq.fleet_refresh(r.machine_id, r.kind, v_test);
    IF was_machine = r.machine_id AND was_kind = r.kind AND was_test = v_test THEN
      RETURN NULL;  -- refreshed already
    END IF;
  END IF;
  IF was_machine IS NOT NULL THEN
    PERFORM caldaq.fleet_refresh(was_machine, was_kind, was_test);
  END IF;
  RETURN NULL;
END $$;

-- A result approved (caldaq.approve) or its approval removed: awaiting approval or not.
CREATE FUNCTION caldaq.fleet_approval_changed() RETURNS trigger LANGUAGE plpgsql SECURITY DEFINER
  SET search_path = pg_catalog, pg_temp AS $$
BEGIN
  IF TG_OP = 'INSERT' THEN
    UPDATE caldaq.fleet_results SET approved = true
      WHERE run_uuid = NEW.run_uuid AND fingerprint = NEW.result_fingerprint;
  ELSE
    UPDATE caldaq.fleet_results SET approved = false
      WHERE run_uuid = OLD.run_uuid AND fingerprint = OLD.result_fingerprint;
  END IF;
  RETURN NULL;
END $$;

CREATE TRIGGER fleet_run AFTER INSERT OR UPDATE OF settings_json, machine_id, started_unix_ms, kind
  ON caldaq.runs FOR EACH ROW EXECUTE FUNCTION caldaq.fleet_run_changed();
CREATE TRIGGER fleet_result AFTER INSERT OR DELETE OR UPDATE OF json, superseded_by, standard,
  created_unix_ms, fingerprint ON caldaq.results FOR EACH ROW EXECUTE FUNCTION caldaq.fleet_result_changed();
CREATE TRIGGER fleet_approval AFTER INSERT OR DELETE ON caldaq.approvals
  FOR EACH ROW EXECUTE FUNCTION caldaq.fleet_approval_changed();

-- What the server held before this version, through the same functions.
UPDATE caldaq.runs SET settings_json = settings_json;
UPDATE caldaq.results SET json = json;

REVOKE ALL ON caldaq.fleet_runs, caldaq.fleet_results, caldaq.fleet_values, caldaq.fleet_tests,
  caldaq.fleet_series, caldaq.fleet_instruments FROM PUBLIC;
REVOKE ALL ON FUNCTION caldaq.fleet_jsonb(text), caldaq.fleet_text(jsonb, text),
  caldaq.fleet_number(jsonb), caldaq.fleet_run_changed(), caldaq.fleet_result_values(jsonb, jsonb),
  caldaq.fleet_result_changed(), caldaq.fleet_refresh(bigint, text, text),
  caldaq.fleet_approval_changed() FROM PUBLIC;
GRANT SELECT ON caldaq.fleet_runs, caldaq.fleet_results, caldaq.fleet_values, caldaq.fleet_tests,
  caldaq.fleet_series, caldaq.fleet_instruments TO caldaq_engineer, caldaq_reviewer;

-- Sites (schema 7): a login sees the fleet rows of its sites' machines and runs only, through
-- those tables' own policies (the subqueries below run under them). A row of no machine (an
-- instrument or run sent without one) is seen where its run is.
DO $policies$
DECLARE
  t text;
BEGIN
  FOREACH t IN ARRAY ARRAY['fleet_results', 'fleet_values', 'fleet_tests', 'fleet_series'] LOOP
    EXECUTE format('ALTER TABLE caldaq.%I ENABLE ROW LEVEL SECURITY', t);
    EXECUTE format('CREATE POLICY by_site ON caldaq.%I USING (EXISTS (SELECT 1 FROM '
                   'caldaq.machines AS m WHERE m.id = machine_id))', t);
  END LOOP;
  FOREACH t IN ARRAY ARRAY['fleet_runs', 'fleet_instruments'] LOOP
    EXECUTE format('ALTER TABLE caldaq.%I ENABLE ROW LEVEL SECURITY', t);
    EXECUTE format('CREATE POLICY by_site ON caldaq.%I USING (EXISTS (SELECT 1 FROM '
                   'caldaq.machines AS m WHERE m.id = machine_id) OR (machine_id IS NULL AND '
                   'EXISTS (SELECT 1 FROM caldaq.runs AS r WHERE r.uuid = run_uuid)))', t);
  END LOOP;
END $policies$;
)sql";

}  // namespace cal::storage::pg
