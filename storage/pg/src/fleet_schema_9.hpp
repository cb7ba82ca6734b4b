#pragma once
// Central schema 9 (issue 35, the fleet view; docs/storage.md "The fleet view's tables"): the
// verdicts and trends of straightness, angular (pitch, yaw) and roll runs beside positioning and
// circle runs, and a trend window: each series' line starts at the last change that resets it.
// Private to storage/pg (central_schema.cpp includes it). The functions of schema 8 that change
// are replaced here whole (CREATE OR REPLACE); their schema 8 text (fleet_schema.hpp) is history.
//
// - fleet_result_values gains caldaq.profile.v1 (daq's profile_verdict, verdict.cpp): a
//   straightness run's straightness about the least-squares line (key straightness_um, in um)
//   against straightness_um; an angular or roll run's angular deviation, the range of the means
//   (key range, in the document's unit, urad) against angular_urad; the limits those of the
//   measured travel (position_mm, by_length), as for a linear axis. The symbol is the run's
//   ISO 230-1 component (E_YX, E_BX, E_AX), as daq show names the check; a profile run's test is
//   that component.
// - fleet_runs.controller_compensation: the run's conditions.controller_compensation (NULL: not
//   stated).
// - fleet_series: the line is fitted over its window only: window_from_unix_ms (NULL: the whole
//   history), window_reason, window_detail; history_runs counts every current result. The window
//   starts at the latest of, up to the series' latest run:
//     a compensation table stored for the machine (caldaq.compensations, as `daq verify` pairs a
//     table with the runs started after it) that acts on an axis the test measures: a linear or
//     rotary run's axis, a circle's two axes, a straightness run's direction (a cross table's
//     axes, as daq verify pairs them); none for an angular or roll run (a table moves the tool,
//     it does not turn the carriage);
//     the run whose conditions.controller_compensation differs from the previous run's of the
//     series (the control's compensation switched on or off; not for angular and roll runs).
//   A user's "since" date is applied when a machine is opened (caldaq.fleet_fit with the later
//   of the two), not stored.

namespace cal::storage::pg {

inline constexpr const char* kFleetKindsWindowMigration = R"sql(
ALTER TABLE caldaq.fleet_runs ADD COLUMN controller_compensation boolean;
ALTER TABLE caldaq.fleet_series ADD COLUMN window_from_unix_ms bigint,
  ADD COLUMN window_reason text NOT NULL DEFAULT '', ADD COLUMN window_detail text NOT NULL DEFAULT '',
  ADD COLUMN history_runs bigint NOT NULL DEFAULT 0;
CREATE INDEX compensations_by_machine ON caldaq.compensations(machine_id, created_unix_ms);

CREATE OR REPLACE FUNCTION caldaq.fleet_run_changed() RETURNS trigger LANGUAGE plpgsql SECURITY DEFINER
  SET search_path = pg_catalog, pg_temp AS $$
DECLARE
  ctx jsonb := COALESCE(caldaq.fleet_jsonb(NEW.settings_json) -> 'context', '{}');
  site text := COALESCE(caldaq.fleet_text(ctx -> 'customer', 'site'), '');
  cc boolean;
BEGIN
  IF jsonb_typeof(ctx) <> 'object' THEN ctx := '{}'; END IF;
  IF jsonb_typeof(ctx -> 'conditions' -> 'controller_compensation') = 'boolean' THEN
    cc := (ctx -> 'conditions' ->> 'controller_compensation')::boolean;
  END IF;
  INSERT INTO caldaq.fleet_runs VALUES (NEW.uuid, NEW.machine_id, NEW.started_unix_ms, NEW.kind, site,
    CASE WHEN jsonb_typeof(ctx -> 'tolerances') = 'object' THEN ctx -> 'tolerances' END, cc)
  ON CONFLICT (run_uuid) DO UPDATE SET machine_id = EXCLUDED.machine_id,
    started_unix_ms = EXCLUDED.started_unix_ms, kind = EXCLUDED.kind, site = EXCLUDED.site,
    tolerances = EXCLUDED.tolerances, controller_compensation = EXCLUDED.controller_compensation;
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

-- An axis's limits for a measured travel (verdict.cpp limits_for_travel): the first by_length
-- entry long enough replaces the axis's own.
CREATE FUNCTION caldaq.fleet_limits_for_travel(tol jsonb, travel double precision) RETURNS jsonb
  LANGUAGE sql IMMUTABLE AS $$
  SELECT COALESCE(tol, '{}') || COALESCE((
    SELECT x - 'up_to_mm' FROM jsonb_array_elements(CASE WHEN jsonb_typeof(tol -> 'by_length') = 'array'
                                                         THEN tol -> 'by_length' ELSE '[]' END)
                           WITH ORDINALITY AS b(x, n)
    WHERE jsonb_typeof(x) = 'object' AND COALESCE(travel, 0) <= caldaq.fleet_number(x -> 'up_to_mm') + 1e-9
    ORDER BY n LIMIT 1), '{}')
$$;

-- The travel of a document's targets by a position key (verdict.cpp travel_mm: a target without
-- the key counts at 0).
CREATE FUNCTION caldaq.fleet_travel(d jsonb, position_key text) RETURNS double precision
  LANGUAGE sql IMMUTABLE AS $$
  SELECT max(COALESCE(caldaq.fleet_number(t -> position_key), 0))
       - min(COALESCE(caldaq.fleet_number(t -> position_key), 0))
  FROM jsonb_array_elements(CASE WHEN jsonb_typeof(d -> 'targets') = 'array' THEN d -> 'targets'
                                 ELSE '[]' END) AS t
$$;

CREATE OR REPLACE FUNCTION caldaq.fleet_result_values(d jsonb, tol jsonb)
  RETURNS TABLE(key text, symbol text, unit text, value double precision,
                limit_value double precision, trend boolean)
  LANGUAGE plpgsql IMMUTABLE AS $$
DECLARE
  schema text := caldaq.fleet_text(d, 'schema');
  lim jsonb := COALESCE(tol, '{}');
  suffix text;
  vkey text;
  v_bi boolean := COALESCE(d -> 'bidirectional' <> 'false'::jsonb, true);
  v_vdi boolean := COALESCE((d -> 'axis') ? 'P', false);
  iso jsonb := COALESCE(d -> 'iso230_4', '{}');
  component text := caldaq.fleet_text(d, 'component');
BEGIN
  IF schema IN ('caldaq.iso230-2.v1', 'caldaq.rotary.v1') THEN
    IF schema = 'caldaq.iso230-2.v1' THEN
      suffix := '_um'; vkey := 'value_um';
      -- The limits for the measured travel (the targets' fleet_number, as schema 8 read them).
      lim := caldaq.fleet_limits_for_travel(lim, (
        SELECT max(caldaq.fleet_number(t -> 'target_mm')) - min(caldaq.fleet_number(t -> 'target_mm'))
        FROM jsonb_array_elements(CASE WHEN jsonb_typeof(d -> 'targets') = 'array'
                                       THEN d -> 'targets' ELSE '[]' END) AS t));
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
  ELSIF schema = 'caldaq.profile.v1' THEN
    -- verdict.cpp profile_verdict over result_rows.cpp profile_rows: a straightness run's
    -- straightness (present when the document has it) against straightness_um, an angular or roll
    -- run's range against angular_urad; a value that is not a number reads 0 (number_of).
    lim := caldaq.fleet_limits_for_travel(lim, caldaq.fleet_travel(d, 'position_mm'));
    IF caldaq.fleet_text(d, 'kind') = 'straightness' THEN
      IF d ? 'straightness_um' THEN
        RETURN QUERY SELECT 'straightness_um'::text, component, 'um'::text,
          COALESCE(caldaq.fleet_number(d -> 'straightness_um'), 0),
          caldaq.fleet_number(lim -> 'straightness_um'), true;
      END IF;
    ELSE
      RETURN QUERY SELECT 'range'::text, component, caldaq.fleet_text(d, 'unit'),
        COALESCE(caldaq.fleet_number(d -> 'range'), 0), caldaq.fleet_number(lim -> 'angular_urad'), true;
    END IF;
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

-- A series' line over its current results started at or after from_ms (NULL: all of them):
-- PostgreSQL's regr_slope and regr_intercept of the value on the run's start; the latest value and
-- limit whatever the window; history_runs counts every current result of the series.
CREATE FUNCTION caldaq.fleet_fit(m bigint, k text, t text, from_ms bigint)
  RETURNS TABLE(key text, symbol text, unit text, runs bigint, slope_per_ms double precision,
                intercept double precision, first_unix_ms bigint, last_unix_ms bigint,
                latest double precision, limit_value double precision, history_runs bigint)
  LANGUAGE sql STABLE AS $$
  SELECT v.key, min(v.symbol), min(v.unit), count(*) FILTER (WHERE w.inside),
    regr_slope(v.value, v.started_unix_ms::float8) FILTER (WHERE w.inside),
    regr_intercept(v.value, v.started_unix_ms::float8) FILTER (WHERE w.inside),
    min(v.started_unix_ms) FILTER (WHERE w.inside), max(v.started_unix_ms),
    (array_agg(v.value ORDER BY v.started_unix_ms DESC, v.result_id DESC))[1],
    (array_agg(v.limit_value ORDER BY v.started_unix_ms DESC, v.result_id DESC))[1], count(*)
  FROM caldaq.fleet_values AS v,
    LATERAL (SELECT from_ms IS NULL OR v.started_unix_ms >= from_ms AS inside) AS w
  WHERE v.machine_id = m AND v.kind = k AND v.test = t AND v.current AND v.trend
  GROUP BY v.key
$$;

-- Whether a compensation table of axes `axes` (cross: a cross or volumetric table) acts on what
-- test t of kind k measures (the header above says which).
CREATE FUNCTION caldaq.fleet_compensation_resets(k text, t text, axes text, is_cross boolean)
  RETURNS boolean LANGUAGE sql IMMUTABLE AS $$
  SELECT EXISTS (SELECT FROM regexp_split_to_table(
      CASE WHEN k IN ('linear', 'rotary') THEN t
           WHEN k = 'circle' THEN split_part(t, ' ', 1)
           WHEN k = 'straightness' AND is_cross AND t ~ '^E_[A-Z][A-Z]$' THEN substr(t, 3, 1)
           ELSE '' END, '') AS a(letter)
    WHERE a.letter <> '' AND strpos(COALESCE(axes, ''), a.letter) > 0)
$$;

-- The latest change up to last_ms that resets a series' line (no row: none).
CREATE FUNCTION caldaq.fleet_window(m bigint, k text, t text, last_ms bigint)
  RETURNS TABLE(from_unix_ms bigint, reason text, detail text) LANGUAGE sql STABLE AS $$
  SELECT w.at, w.why, w.what FROM (
    SELECT c.created_unix_ms, 'compensation'::text,
        format('table %s of axis %s (%s), stored %s', c.id, c.axis, c.format,
               to_char(to_timestamp(c.created_unix_ms / 1000.0) AT TIME ZONE 'UTC', 'YYYY-MM-DD')),
        c.id
      FROM caldaq.compensations AS c
      WHERE c.machine_id = m AND c.created_unix_ms <= last_ms
        AND caldaq.fleet_compensation_resets(k, t, c.axis,
              caldaq.fleet_text(caldaq.fleet_jsonb(c.json), 'kind') = 'cross')
    UNION ALL
    SELECT x.started_unix_ms, CASE WHEN x.cc THEN 'controller compensation switched on'
                                   ELSE 'controller compensation switched off' END,
        format('run %s', x.run_id), x.run_id
      FROM (SELECT f.started_unix_ms, f.run_id, u.controller_compensation AS cc,
                   lag(u.controller_compensation) OVER (ORDER BY f.started_unix_ms, f.result_id) AS prev
            FROM caldaq.fleet_results AS f JOIN caldaq.fleet_runs AS u ON u.run_uuid = f.run_uuid
            WHERE f.machine_id = m AND f.kind = k AND f.test = t AND f.current
              AND k NOT IN ('angular', 'roll')) AS x
      WHERE x.cc IS NOT NULL AND x.prev IS NOT NULL AND x.cc <> x.prev
        AND x.started_unix_ms <= last_ms) AS w(at, why, what, tie)
  ORDER BY w.at DESC, w.tie DESC LIMIT 1
$$;

CREATE OR REPLACE FUNCTION caldaq.fleet_refresh(m bigint, k text, t text) RETURNS void
  LANGUAGE plpgsql AS $$
DECLARE
  last_ms bigint;
  w_from bigint;
  w_reason text;
  w_detail text;
BEGIN
  DELETE FROM caldaq.fleet_tests AS x WHERE x.machine_id = m AND x.kind = k AND x.test = t;
  INSERT INTO caldaq.fleet_tests
    SELECT r.machine_id, r.kind, r.test, r.run_uuid, r.result_id, r.run_id, r.started_unix_ms,
      r.verdict, r.failed
    FROM caldaq.fleet_results AS r WHERE r.machine_id = m AND r.kind = k AND r.test = t AND r.current
    ORDER BY r.started_unix_ms DESC, r.result_id DESC LIMIT 1;
  DELETE FROM caldaq.fleet_series AS x WHERE x.machine_id = m AND x.kind = k AND x.test = t;
  SELECT max(v.started_unix_ms) INTO last_ms FROM caldaq.fleet_values AS v
    WHERE v.machine_id = m AND v.kind = k AND v.test = t AND v.current AND v.trend;
  IF last_ms IS NULL THEN
    RETURN;
  END IF;
  SELECT w.from_unix_ms, w.reason, w.detail INTO w_from, w_reason, w_detail
    FROM caldaq.fleet_window(m, k, t, last_ms) AS w;
  INSERT INTO caldaq.fleet_series(machine_id, kind, test, key, symbol, unit, runs, slope_per_ms,
      intercept, first_unix_ms, last_unix_ms, latest, limit_value, window_from_unix_ms,
      window_reason, window_detail, history_runs)
    SELECT m, k, t, f.key, f.symbol, f.unit, f.runs, f.slope_per_ms, f.intercept, f.first_unix_ms,
      f.last_unix_ms, f.latest, f.limit_value, w_from, COALESCE(w_reason, ''),
      COALESCE(w_detail, ''), f.history_runs
    FROM caldaq.fleet_fit(m, k, t, w_from) AS f;
END $$;

-- A profile run's test is its ISO 230-1 component (E_YX, E_BX, E_AX; its axis without one).
CREATE OR REPLACE FUNCTION caldaq.fleet_result_changed() RETURNS trigger LANGUAGE plpgsql SECURITY DEFINER
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
      WHEN caldaq.fleet_text(d, 'schema') = 'caldaq.profile.v1' THEN
        COALESCE(NULLIF(caldaq.fleet_text(d, 'component'), ''), r.axis)
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

-- A compensation table stored, changed or removed: its machine's lines again.
CREATE FUNCTION caldaq.fleet_compensation_changed() RETURNS trigger LANGUAGE plpgsql SECURITY DEFINER
  SET search_path = pg_catalog, pg_temp AS $$
DECLARE
  machines bigint[];
BEGIN
  IF TG_OP = 'INSERT' THEN
    machines := ARRAY[NEW.machine_id];
  ELSIF TG_OP = 'DELETE' THEN
    machines := ARRAY[OLD.machine_id];
  ELSE
    machines := ARRAY[OLD.machine_id, NEW.machine_id];
  END IF;
  PERFORM caldaq.fleet_refresh(s.machine_id, s.kind, s.test)
    FROM (SELECT DISTINCT x.machine_id, x.kind, x.test FROM caldaq.fleet_tests AS x
          WHERE x.machine_id = ANY (machines)) AS s;
  RETURN NULL;
END $$;
CREATE TRIGGER fleet_compensation AFTER INSERT OR DELETE OR UPDATE OF machine_id, axis,
  created_unix_ms, json ON caldaq.compensations
  FOR EACH ROW EXECUTE FUNCTION caldaq.fleet_compensation_changed();

-- What the server holds, through the new functions: the runs' flags, the profile results, and
-- every line in its window.
UPDATE caldaq.fleet_runs AS f SET controller_compensation = CASE WHEN jsonb_typeof(
    caldaq.fleet_jsonb(r.settings_json) -> 'context' -> 'conditions' -> 'controller_compensation') = 'boolean'
  THEN (caldaq.fleet_jsonb(r.settings_json) -> 'context' -> 'conditions' ->> 'controller_compensation')::boolean END
  FROM caldaq.runs AS r WHERE r.uuid = f.run_uuid;
UPDATE caldaq.results SET json = json WHERE json LIKE '%caldaq.profile.v1%';
DO $refresh$ BEGIN
  PERFORM caldaq.fleet_refresh(s.machine_id, s.kind, s.test)
    FROM (SELECT DISTINCT x.machine_id, x.kind, x.test FROM caldaq.fleet_tests AS x) AS s;
END $refresh$;

REVOKE ALL ON FUNCTION caldaq.fleet_limits_for_travel(jsonb, double precision),
  caldaq.fleet_travel(jsonb, text), caldaq.fleet_fit(bigint, text, text, bigint),
  caldaq.fleet_compensation_resets(text, text, text, boolean),
  caldaq.fleet_window(bigint, text, text, bigint), caldaq.fleet_compensation_changed() FROM PUBLIC;
-- A machine opened with a chosen "since" is fitted by the reader (under its sites' policies).
GRANT EXECUTE ON FUNCTION caldaq.fleet_fit(bigint, text, text, bigint) TO caldaq_engineer, caldaq_reviewer;
)sql";

}  // namespace cal::storage::pg
