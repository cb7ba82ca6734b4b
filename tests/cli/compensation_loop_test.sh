#!/usr/bin/env bash
# Issue 26, the compensation loop on the simulated shop (a known truth): measure X, write a
# SINUMERIK LEC table (stored with the run), let the simulated control load it as Siemens states
# ("A positive compensation value causes the corresponding machine axis to move in the negative
# direction") and measure again: daq verify finds the residual as predicted. A control that
# reads the table with the other sign doubles the error, and daq verify says so and writes the
# corrected table, which that control then applies as predicted.
# Usage: compensation_loop_test.sh DAQ_BINARY
set -u
DAQ=$1
source "$(dirname "$0")/check.sh"
T=$(mktemp -d)
trap 'rm -rf "$T"' EXIT
DB=$T/loop.sqlite
demo() { "$DAQ" demo --db "$DB" --capture "$T/c$1.cdq" --linear-only --quiet "${@:2}"; }
G=(--start-mm 0 --interval-mm 50 --points 11 --outside hold)
check measure 0 "run 1 stored" -- demo 1
check table 0 "stored as compensation 1" -- "$DAQ" compensate --run 1 --db "$DB" -f siemens "${G[@]}" -o "$T/lec.mpf"
check table_value 0 '^\$AA_ENC_COMP\[0,10,AX1\]=0\.0' -- cat "$T/lec.mpf"
# The demo's run is simulated: its table says so in its header (a comment the control skips).
check table_origin 0 '^; SIMULATED data: do not load into a real control$' -- cat "$T/lec.mpf"
check table_origin_run 0 '^; from run 1, not a measurement of a real machine \(' -- cat "$T/lec.mpf"
check as_siemens 0 "run 2 stored" -- demo 2 --control-table "$T/lec.mpf" --control-format siemens
check verify_ok 0 "compensation 1 \(siemens, run 1 of axis X\): as predicted" -- "$DAQ" verify 2 --db "$DB"
check as_inverted 0 "run 3 stored" -- demo 3 --control-table "$T/lec.mpf" --control-format siemens --control-inverted
check verify_inverted 0 "inverted sign: the error got about twice as large" -- "$DAQ" verify 3 --db "$DB" --corrected "$T/fixed.mpf"
check verify_json 0 '"finding": "inverted sign"' -- "$DAQ" verify 3 --db "$DB" --json
# The corrected table holds the values negated; the control that reads them the other way then
# removes the error as predicted.
check fixed_value 0 '^\$AA_ENC_COMP\[0,10,AX1\]=-0\.0' -- cat "$T/fixed.mpf"
check as_fixed 0 "run 4 stored" -- demo 4 --control-table "$T/fixed.mpf" --control-format siemens --control-inverted
check verify_fixed 0 ": as predicted" -- "$DAQ" verify 4 --db "$DB"
check none_before 2 "no compensation of its axis on its machine was stored before it" -- "$DAQ" verify 1 --db "$DB"
check list 0 "^compensation 1: axis X, siemens from run 1" -- "$DAQ" verify --list --db "$DB"
# A simulated run renamed to look real (machine, campaign, every instrument's transport) keeps
# its SIMULATED banner in the report, show and the export: the origin is stored, not read from
# names (before, the banner went with the word "simulated").
"$PY" - "$DB" <<'PYEOF'
import sqlite3, sys
db = sqlite3.connect(sys.argv[1])
db.execute("UPDATE machines SET name = 'Customer Mill 7'")
db.execute("UPDATE runs SET campaign = 'annual calibration'")
db.execute("UPDATE instruments SET transport = 'tcp 192.0.2.5:9090'")
db.commit()
PYEOF
# The three twins named together, their origin's detail said once.
check renamed_show 0 "^  SIMULATED: laser, air and material simulated \(a twin of the built-in simulated shop\)$" -- "$DAQ" show 1 --db "$DB"
check renamed_report 0 "report of run 1 written" -- "$DAQ" report 1 --db "$DB" -o "$T/r1.html"
check renamed_banner 0 "<strong>SIMULATED</strong>: this run was made on the simulated" -- cat "$T/r1.html"
check renamed_title 0 "<h1>SIMULATED — Run 1" -- cat "$T/r1.html"
check renamed_export 0 '"label": "SIMULATED"' -- "$DAQ" export 1 --db "$DB" --format json
check renamed_json 0 '"simulated": true' -- "$DAQ" show 1 --db "$DB" --json
# daq recompensate assesses the stops again and stores their quality (issue 26): a verdict
# planted in the database (a suspect stop that is not) is replaced by what the stops say, in
# the database, not only in the command's output.
"$PY" - "$DB" <<'PYEOF'
import sqlite3, sys
db = sqlite3.connect(sys.argv[1])
db.execute("UPDATE runs SET quality = 'suspect', quality_note = 'planted verdict' WHERE id = 2")
db.execute("UPDATE captured_targets SET suspect = 'planted stop' WHERE run_id = 2 AND target_index = 3")
db.commit()
PYEOF
check planted 0 "stop quality: suspect, planted verdict" -- "$DAQ" show 2 --db "$DB"
check recompensate_quality 0 "^  stop quality: ok" -- "$DAQ" recompensate 2 --alpha-ppm 11.6 --db "$DB"
check quality_stored 0 "^  stop quality: ok" -- "$DAQ" show 2 --db "$DB"
check planted_gone 0 '"suspect_stops": \[\]' -- "$DAQ" show 2 --db "$DB" --json
finish
