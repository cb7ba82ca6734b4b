# Sourced by tests that need a PostgreSQL server: pg_start DIR starts a throwaway one (initdb into
# DIR/data, listening only on a unix socket in DIR, trust authentication for the user caldaq) and
# sets PG_URL (database caldaq); pg_stop stops it. Run as root (CI, a container), the server runs as
# the user nobody, which PostgreSQL requires: DIR is then made nobody's.
PG_BIN=${PG_BIN:-$(ls -d /usr/lib/postgresql/*/bin 2>/dev/null | sort -V | tail -1)}

pg_as_owner() {
  if [ "$(id -u)" -eq 0 ]; then runuser -u nobody -- "$@"; else "$@"; fi
}

pg_start() {
  PG_DIR=$1
  if [ -z "$PG_BIN" ] || [ ! -x "$PG_BIN/initdb" ]; then
    echo "FAIL: no PostgreSQL server binaries (/usr/lib/postgresql/*/bin; Debian package postgresql)"
    exit 1
  fi
  if [ "$(id -u)" -eq 0 ]; then chown nobody "$PG_DIR"; fi
  chmod 700 "$PG_DIR"
  pg_as_owner "$PG_BIN/initdb" -D "$PG_DIR/data" -U caldaq -A trust --no-sync >"$PG_DIR/initdb.log" 2>&1 ||
    { cat "$PG_DIR/initdb.log"; echo "FAIL: initdb"; exit 1; }
  # -F: no fsync (a throwaway server); no TCP at all: the socket is in PG_DIR.
  pg_as_owner "$PG_BIN/pg_ctl" -D "$PG_DIR/data" -l "$PG_DIR/server.log" -w -t 60 \
    -o "-k $PG_DIR -c listen_addresses= -F" start >/dev/null ||
    { cat "$PG_DIR/server.log"; echo "FAIL: pg_ctl start"; exit 1; }
  PG_STARTED=1
  PG_URL="postgresql:///caldaq?host=$PG_DIR&user=caldaq"
  "$PG_BIN/psql" -q -X "postgresql:///postgres?host=$PG_DIR&user=caldaq" -c "CREATE DATABASE caldaq" ||
    { echo "FAIL: CREATE DATABASE"; exit 1; }
}

# pg_with_demo (after check.sh): TMP, a scratch directory; a throwaway server in PGTMP; the
# demo's runs in DB ($TMP/local/demo.sqlite); the server stopped and both removed at exit.
pg_with_demo() {
  TMP=$(mktemp -d)
  # The server's directory in /tmp whatever TMPDIR says: the user nobody must reach it, and the
  # socket's path must stay short (107 bytes at most).
  PGTMP=$(mktemp -d /tmp/caldaq-pg.XXXXXX)
  trap 'pg_stop; rm -rf "$TMP" "$PGTMP"' EXIT
  mkdir "$TMP/local"
  pg_start "$PGTMP"
  demo_runs "$TMP/local"
  DB=$TMP/local/demo.sqlite
}

# visit_records (after pg_with_demo or demo_runs into DB): what a visit adds to the demo's store:
# a replay (run 3), a re-compensation (a superseded result), a ballbar calibration and a
# compensation table; each a check.
visit_records() {
  check replay 0 "" -- "$DAQ" replay "$DEMO_CDQ" --db "$DB"
  check recompensate 0 "" -- "$DAQ" recompensate 1 --alpha-ppm 12.0 --db "$DB"
  check calibrate 0 "" -- "$DAQ" ballbar calibrate --bar QC20-1 --nominal-mm 100 --calibrator-mm 100.0021 \
    --reading-mm 0.0012 --date 2026-01-05 --db "$DB"
  check compensate 0 "stored as compensation 1" -- "$DAQ" compensate --run 1 --db "$DB" -f siemens \
    --start-mm 0 --interval-mm 50 --points 11 --outside hold -o "$TMP/lec.mpf"
}

# pg_with_visit (after check.sh, DAQ set): pg_with_demo, visit_records, and the store sent to
# the server (the check "sync").
pg_with_visit() {
  pg_with_demo
  visit_records
  check sync 0 "runs synced" -- "$DAQ" sync --db "$DB" --to "$PG_URL" --quiet
}

pg_stop() {
  if [ -n "${PG_STARTED:-}" ]; then
    pg_as_owner "$PG_BIN/pg_ctl" -D "$PG_DIR/data" -m immediate -w stop >/dev/null 2>&1
    PG_STARTED=
  fi
}

# psql_value SQL: one value from the test's database, unaligned.
psql_value() {
  "$PG_BIN/psql" -X -At "$PG_URL" -c "$1"
}

# value FILE SQL: one value from a SQLite store (a laptop's). as LOGIN: the test server's URI for
# that login (a role the test made). sql LOGIN SQL: SQL run as that login, unaligned.
value() {
  "$PY" -c "import sqlite3, sys; print(sqlite3.connect(sys.argv[1]).execute(sys.argv[2]).fetchone()[0])" "$1" "$2"
}
as() { echo "postgresql:///caldaq?host=$PGTMP&user=$1"; }
sql() { "$PG_BIN/psql" -X -At -v ON_ERROR_STOP=1 "$(as "$1")" -c "$2"; }

# pg_undo_central_13: the test's server taken back to central schema 12: the failing tests'
# index (13) dropped.
pg_undo_central_13() {
  psql_value "DROP INDEX IF EXISTS caldaq.fleet_tests_failing; UPDATE caldaq.schema_version SET version = 12" >/dev/null
}

# pg_undo_central_12: the test's server taken back to central schema 11 as far as its data goes:
# what 13 added, then the results' verdicts and the fleet's triggers of migration 12 dropped (the
# fleet's result trigger too: migration 12 makes it again; schema 11's text of it is not restored).
pg_undo_central_12() {
  pg_undo_central_13
  psql_value "SET client_min_messages = warning;
DROP FUNCTION IF EXISTS caldaq.fleet_version_changed, caldaq.fleet_mark_current,
  caldaq.fleet_is_current CASCADE;
DROP TRIGGER IF EXISTS fleet_result ON caldaq.results;
ALTER TABLE caldaq.results DROP COLUMN IF EXISTS verdict, DROP COLUMN IF EXISTS verdict_failed;
UPDATE caldaq.schema_version SET version = 11" >/dev/null
}

# pg_undo_central_11: the test's server taken back to central schema 10, the results' versions
# (migration 11) dropped, and what migrations 12 and 13 added.
pg_undo_central_11() {
  pg_undo_central_12
  psql_value "DROP TABLE IF EXISTS caldaq.result_versions; UPDATE caldaq.schema_version SET version = 10" >/dev/null
}

# pg_undo_central_10: the test's server taken back to central schema 9, what migrations 10 (the
# models) and 11 added dropped.
pg_undo_central_10() {
  pg_undo_central_11
  psql_value "DROP TABLE caldaq.models; UPDATE caldaq.schema_version SET version = 9" >/dev/null
}

# pg_undo_central_8: the test's server taken back to central schema 7, the fleet view's tables,
# functions and triggers (migrations 8 and 9) dropped, and what later migrations added (10 and 11).
pg_undo_central_8() {
  pg_undo_central_10
  psql_value "DROP TABLE caldaq.fleet_runs, caldaq.fleet_results, caldaq.fleet_values,
  caldaq.fleet_tests, caldaq.fleet_series, caldaq.fleet_instruments;
DROP INDEX caldaq.compensations_by_machine;
DROP FUNCTION caldaq.fleet_run_changed, caldaq.fleet_result_changed, caldaq.fleet_approval_changed,
  caldaq.fleet_refresh, caldaq.fleet_result_values, caldaq.fleet_jsonb, caldaq.fleet_text,
  caldaq.fleet_number, caldaq.fleet_limits_for_travel, caldaq.fleet_travel, caldaq.fleet_fit,
  caldaq.fleet_compensation_resets, caldaq.fleet_window, caldaq.fleet_compensation_changed CASCADE;
UPDATE caldaq.schema_version SET version = 7" >/dev/null
}

# pg_undo_central_7: the test's server taken back to central schema 6, what migration 7 (sites)
# added dropped: a server of the version before, with its data, for the migrations' tests.
pg_undo_central_7() {
  psql_value "
DO \$undo\$ DECLARE t text; BEGIN
  FOREACH t IN ARRAY ARRAY['machines', 'runs', 'compensations', 'instruments', 'reading_chunks',
      'captured_targets', 'missed_stops', 'results', 'operator_actions', 'suspect_stops',
      'run_versions', 'approvals'] LOOP
    EXECUTE format('DROP POLICY by_site ON caldaq.%I', t);
    EXECUTE format('ALTER TABLE caldaq.%I DISABLE ROW LEVEL SECURITY', t);
  END LOOP;
END \$undo\$;
DROP TRIGGER machine_moved ON caldaq.machines;
DROP FUNCTION caldaq.machine_moved();
ALTER TABLE caldaq.machines DROP COLUMN site;
ALTER TABLE caldaq.runs DROP COLUMN site;
ALTER TABLE caldaq.compensations DROP COLUMN site;
DROP TABLE caldaq.site_grants;
DROP FUNCTION caldaq.session_sites();
DROP FUNCTION caldaq.context_site(text);
GRANT UPDATE ON caldaq.machines TO caldaq_engineer;
DROP FUNCTION caldaq.approve(uuid, text);
ALTER FUNCTION caldaq.approve_any_site(uuid, text) RENAME TO approve;
GRANT EXECUTE ON FUNCTION caldaq.approve(uuid, text) TO caldaq_reviewer;
UPDATE caldaq.schema_version SET version = 6" >/dev/null
}
