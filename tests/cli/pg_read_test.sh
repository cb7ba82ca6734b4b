#!/usr/bin/env bash
# Issue 35: every read command gives the same output on the local SQLite store and on the central
# store on PostgreSQL (one RunReader interface, two implementations), for the demo's runs synced
# to a server started here (tests/cli/pg_server.sh): runs, show (text and JSON), export (readings
# CSV, JSON, targets, circle), report (HTML), analyse RUN (linear and circle, other standards),
# model build, ballbar history and calibrations, verify --list. The local store first gets what a
# visit adds: a re-compensation (a superseded result), a ballbar calibration.
# Usage: pg_read_test.sh DAQ_BINARY
set -u
DAQ=$1

source "$(dirname "$0")/check.sh"
source "$(dirname "$0")/pg_server.sh"
TMP=$(mktemp -d)
PGTMP=$(mktemp -d /tmp/caldaq-pg.XXXXXX)  # short, and reachable by nobody (pg_server.sh)
trap 'pg_stop; rm -rf "$TMP" "$PGTMP"' EXIT
mkdir "$TMP/local"
pg_start "$PGTMP"
demo_runs "$TMP/local"
DB=$TMP/local/demo.sqlite

check recompensate 0 "" -- "$DAQ" recompensate 1 --alpha-ppm 12.0 --db "$DB"
check calibrate 0 "" -- "$DAQ" ballbar calibrate --bar QC20-1 --nominal-mm 100 --calibrator-mm 100.0021 \
  --reading-mm 0.0012 --date 2026-01-05 --db "$DB"
check sync 0 "runs synced" -- "$DAQ" sync --db "$DB" --to "$PG_URL" --quiet
# Synced twice: the calibration and the tables stored once.
check sync_again 0 "0 new" -- "$DAQ" sync --db "$DB" --to "$PG_URL" --quiet
check calibration_once 0 "^1$" -- psql_value "SELECT count(*) FROM caldaq.bar_calibrations"

RUNS=$("$PY" -c "import sqlite3, sys; print(' '.join(str(r[0]) for r in sqlite3.connect(sys.argv[1]).execute('SELECT id FROM runs ORDER BY id')))" "$DB")
MACHINE=$("$PY" -c "import sqlite3, sys; print(sqlite3.connect(sys.argv[1]).execute('SELECT name FROM machines ORDER BY id').fetchone()[0])" "$DB")
check have_runs 0 "^1 2" -- echo "$RUNS"

# same NAME ARGS...: `daq ARGS --db LOCAL` and `daq ARGS --db SERVER` print the same (stdout and
# stderr, exit status); the store's own name, where printed, is replaced by STORE.
same() {
  local name=$1
  shift
  local a b
  a=$("$DAQ" "$@" --db "$DB" 2>&1; echo "exit $?")
  b=$("$DAQ" "$@" --db "$PG_URL" 2>&1; echo "exit $?")
  a=${a//"$DB"/STORE}
  b=${b//"$PG_URL"/STORE}
  if [ "$a" == "$b" ]; then
    check "$name" 0 "" -- true
  else
    check "$name" 0 "^identical$" -- diff <(echo "$a") <(echo "$b")
  fi
  # Not vacuous: each printed something beside its status.
  check "${name}_output" 0 "^[1-9]" -- bash -c "echo \"\$1\" | wc -l | awk '{ print (\$1 > 1) }'" _ "$a"
}

same runs runs
same runs_json runs --json
for r in $RUNS; do
  same "show_$r" show "$r"
  same "show_json_$r" show "$r" --json
  same "export_csv_$r" export "$r"
  same "export_json_$r" export "$r" --format json
  same "analyse_$r" analyse "$r"
  same "analyse_json_$r" analyse "$r" --json
done
same export_targets export 1 --what targets
same export_circle export 2 --what circle
same analyse_vdi analyse 1 --standard vdi3441 --json
same analyse_circle_radius analyse 2 --calibrated-radius-mm 100.002 --json
same ballbar_history ballbar history --machine "$MACHINE"
same ballbar_history_json ballbar history --machine "$MACHINE" --json
same ballbar_calibrations ballbar calibrations --json
same model_build model build --machine "$MACHINE" -o /dev/stdout
same verify_list verify --list
same no_run show 999
# Reports: the same HTML file from either store.
for r in 1 2; do
  (cd "$TMP/local" && "$DAQ" report "$r" --db "$DB" -o "local-$r.html" >/dev/null 2>&1)
  (cd "$TMP/local" && "$DAQ" report "$r" --db "$PG_URL" -o "central-$r.html" >/dev/null 2>&1)
  check "report_$r" 0 "^same [1-9]" -- bash -c "cmp '$TMP/local/local-$r.html' '$TMP/local/central-$r.html' && echo same \$(wc -c <'$TMP/local/local-$r.html')"
done
(cd "$TMP/local" && "$DAQ" report --compare 1 3 --db "$DB" -o local-cmp.html >/dev/null 2>&1)
(cd "$TMP/local" && "$DAQ" report --compare 1 3 --db "$PG_URL" -o central-cmp.html >/dev/null 2>&1)
check report_compare 0 "^same [1-9]" -- bash -c "cmp '$TMP/local/local-cmp.html' '$TMP/local/central-cmp.html' && echo same \$(wc -c <'$TMP/local/local-cmp.html')"

# A damaged chunk on the server is found by the reader as by the local one: named, not misread.
psql_value "UPDATE caldaq.reading_chunks SET data = set_byte(data, 3, (get_byte(data, 3) + 1) % 256) WHERE seq = 2 AND run_uuid = (SELECT uuid FROM caldaq.runs WHERE id = 1)" >/dev/null
check damaged_read 1 "run 1: reading chunk 2 .* is damaged: its checksum does not match its contents" -- \
  "$DAQ" export 1 --db "$PG_URL" -o "$TMP/x.csv"
# The writing commands refuse the central store with their reason.
check write_refused 2 "this command writes the local store" -- "$DAQ" analyse 1 --store --db "$PG_URL"

finish
