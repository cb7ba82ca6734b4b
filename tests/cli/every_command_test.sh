#!/usr/bin/env bash
# Every read command survives every stored thing (issue 27): one database holding every kind of
# run the project can store, and every command that reads a run (show, show --json, export in
# each format and of each --what, report HTML (PDF for a few), analyse, recompensate, model
# build) run on each. Each must end with status 0, or refuse cleanly: status 1 or 2 with a
# message on stderr. Never a signal (status >= 128: `daq show` of a circle run was a SIGSEGV)
# and never a failure without a word.
# The runs (all SIMULATED):
#   the demo's (ctest fixture "demo"): linear positioning, circle, the "as found"/"as left" pair;
#   its capture replayed (a replayed run), run 1 recompensated (a recompensated result);
#   the standard ballbar set (`daq sim --test circle-set --acquire`: six circle runs, one campaign);
#   the volumetric shop's straightness, pitch/yaw and roll runs (`daq sim --measure`, live);
#   a run killed with kill -9 mid-way (left "running", read as incomplete);
#   a run aborted when its laser went away (the simulated shop killed mid-run);
#   Renishaw .rtx imports, linear and angular ("dynamic" runs), one with a damaged tail;
#   a five-axis ballbar run (`daq model ballbar5x-run` on the simulated trunnion, kind ballbar5x).
# Usage: every_command_test.sh DAQ_BINARY DATA_DIR
set -u
DAQ=$1
DATA=$2
source "$(dirname "$0")/check.sh"
scratch_dir RUN_PID
DB=$TMP/demo.sqlite

# survives NAME -- command...: exit 0, or 1/2 with a message on stderr; never a signal.
survived=0
refused=0
survives() {
  local name=$1
  shift 2
  local rc
  "$@" >"$TMP/out" 2>"$TMP/err"
  rc=$?
  if [ "$rc" -eq 0 ]; then
    survived=$((survived + 1))
    return
  fi
  if [ "$rc" -ge 128 ]; then
    echo "FAIL $name: killed by signal $((rc - 128)): $*"
    head -5 "$TMP/err"
    fails=$((fails + 1))
  elif [ "$rc" -gt 2 ]; then
    echo "FAIL $name: exit $rc (expected 0, 1 or 2): $*"
    head -5 "$TMP/err"
    fails=$((fails + 1))
  elif ! grep -q 'error' "$TMP/err"; then
    echo "FAIL $name: exit $rc without an error message on stderr: $*"
    fails=$((fails + 1))
  else
    refused=$((refused + 1))
    echo "refused $name: $(head -1 "$TMP/err")"
  fi
}

# wait_for FILE PATTERN SECONDS: until FILE holds PATTERN.
wait_for() {
  for _ in $(seq $(($3 * 10))); do
    grep -q "$2" "$1" 2>/dev/null && return 0
    sleep 0.1
  done
  return 1
}

# --- the runs -----------------------------------------------------------------------------------
demo_runs "$TMP"
"$DAQ" replay "$DEMO_CDQ" --db "$DB" >"$TMP/replay.log" 2>&1
REPLAYED=$(sed -nE 's/.*replayed .* into run ([0-9]+).*/\1/p' "$TMP/replay.log" | head -1)
check replay 0 "^[0-9]+$" -- echo "$REPLAYED"
check recompensate 0 "" -- "$DAQ" recompensate 1 --alpha-ppm 12.0 --db "$DB"
check circle_set 0 "6 tests stored as runs" -- "$DAQ" sim --test circle-set --acquire -o "$TMP/set.toml" --db "$DB" --capture "$TMP/set.cdq"

# A live linear run on the volumetric shop: one per kind of measure (straightness, angular:
# pitch or yaw, roll). `daq sim --measure` waits for the run to start in the database.
# At --speed 10 a stop stands 0.3 s of wall time: a polled instrument answering 70 ms late on
# the loaded test machine still answers while it stands (at --speed 50, 60 ms, the roll run
# was rightly refused: "answers came up to 69 ms after their requests").
measure() {  # measure COMPONENT
  "$DAQ" sim --measure "$1" --topology YFXZ --speed 10 --db "$DB" -o "$TMP/m.toml" >"$TMP/sim.log" 2>&1 &
  SIM_PID=$!
  wait_for "$TMP/m.toml" "devices" 10 || { echo "FAIL: daq sim --measure $1 wrote no configuration"; cat "$TMP/sim.log"; fails=$((fails + 1)); }
  "$DAQ" run linear -c "$TMP/m.toml" --db "$DB" >"$TMP/m.log" 2>&1
  check "measure_$1" 0 "stored" -- cat "$TMP/m.log"
  cp "$TMP/m.log" "$TMP/m-$1.log"
  wait "$SIM_PID" 2>/dev/null
  SIM_PID=
  rm -f "$TMP/m.toml"
}
measure E_YX  # straightness
measure E_BX  # angular (pitch)
measure E_AX  # roll
# A stop of a straightness or roll run is told with the kind's own value in its unit; the
# laser's positioning deviation ("target 1 (0.000 mm) run 1 up: -6.112 um", what the live
# line and the page also showed) is not what such a stop measures.
check straightness_stop_event 0 "target 1 \(0\.000 mm\) run 1 up: straightness [+-][0-9]+\.[0-9]{3} um" -- cat "$TMP/m-E_YX.log"
check roll_stop_event 0 "run 1 up: roll [+-][0-9]+\.[0-9]{3} urad" -- cat "$TMP/m-E_AX.log"
check no_laser_deviation_as_value 1 "" -- grep -E "run [0-9]+ (up|down): [+-][0-9]" "$TMP/m-E_YX.log"
# A straightness run's stops export with their value in its unit (it said "no captured stops").
STRAIGHT=$("$DAQ" runs --db "$DB" | awk '$3 == "straightness" { id = $1 } END { print id }')
check export_straightness_targets 0 "^target_mm,run,direction,value_um,.*" -- "$DAQ" export "$STRAIGHT" --what targets --db "$DB"
ROLL=$("$DAQ" runs --db "$DB" | awk '$3 == "roll" { id = $1 } END { print id }')
check export_roll_targets 0 "^target_mm,run,direction,value_urad,.*" -- "$DAQ" export "$ROLL" --what targets --db "$DB"

# A linear run killed with kill -9 once it runs, and one aborted because its laser went away.
live_run() {  # live_run NAME: starts the shop and the run, returns once the run is stored running
  "$DAQ" sim --test linear --runs 2 --targets 3 --speed 5 -o "$TMP/$1.toml" >"$TMP/$1-sim.log" 2>&1 &
  SIM_PID=$!
  wait_for "$TMP/$1.toml" "devices" 10
  # Three reconnect attempts, not the default 20 (two minutes of waiting for a laser that is gone).
  "$DAQ" run linear -c "$TMP/$1.toml" --db "$DB" --give-up-after 3 >"$TMP/$1.log" 2>&1 &
  RUN_PID=$!
  wait_for "$TMP/$1.log" "run 1 of 2" 30 || { echo "FAIL $1: the run did not start"; cat "$TMP/$1.log"; fails=$((fails + 1)); }
}
live_run killed
kill -9 "$RUN_PID"
wait "$RUN_PID" 2>/dev/null
RUN_PID=
kill "$SIM_PID" 2>/dev/null
wait "$SIM_PID" 2>/dev/null
SIM_PID=
live_run aborted
kill -9 "$SIM_PID"
wait "$SIM_PID" 2>/dev/null
SIM_PID=
wait "$RUN_PID" 2>/dev/null
RUN_PID=
check run_aborted 0 "aborted|incomplete" -- cat "$TMP/aborted.log"

# Renishaw .rtx imports: linear, angular, and one whose end marker follows a partial sample.
rtx() {  # rtx FILE TYPE TAIL
  { printf 'HEADER::\r\nOwner: CARTO-Dynamic\r\nVersion no: 4.13\r\nFile Type: %s\r\nSample rate: 50000\r\nSample no: 3\r\nActual sample rate: 1000\r\nAxis: X\r\nData:\r\n' "$2"
    printf '\x00\x00\x00\x00\x00\x00\xf0\x3f\x00\x00\x00\x00\x00\x00\x04\xc0\x00\x00\x00\x00\x00\x00\x00\x00'
    printf "$3"; } >"$1"
}
rtx "$TMP/lin.rtx" Linear '\r\nEOF::\r\n'
rtx "$TMP/ang.rtx" Angular '\r\nEOF::\r\n'
rtx "$TMP/odd.rtx" Linear '\x01\x02\x03\r\nEOF::\r\n'
check rtx_linear 0 "imported" -- "$DAQ" import rtx "$TMP/lin.rtx" --db "$DB"
check rtx_angular 0 "imported" -- "$DAQ" import rtx "$TMP/ang.rtx" --db "$DB" --unit arcsec
check rtx_odd 0 "imported" -- "$DAQ" import rtx "$TMP/odd.rtx" --db "$DB"

# A five-axis ballbar run (issue 36): radial and axial on each axis of the simulated trunnion
# (the two set-ups that separate its four location errors), the bar's stream read as it comes.
check ballbar5x 0 "five-axis ballbar, location errors" -- "$DAQ" model ballbar5x-run "$DATA/model/trunnion_truth.json" --control "$DATA/model/trunnion_nominal.json" --db "$DB" --ball-mm 150 0 -250 --setups radial axial
BB5X=$("$DAQ" runs --db "$DB" --json | "$PY" -c 'import json,sys; print([r["id"] for r in json.load(sys.stdin)["runs"] if r["kind"] == "ballbar5x"][-1])')

RUNS=$("$DAQ" runs --db "$DB" --json | "$PY" -c 'import json,sys; print(" ".join(str(r["id"]) for r in json.load(sys.stdin)["runs"]))')
"$DAQ" runs --db "$DB"
KINDS=$("$DAQ" runs --db "$DB" --json | "$PY" -c '
import json, sys
runs = json.load(sys.stdin)["runs"]
print(" ".join(sorted({r["kind"] + "/" + r["status"] for r in runs})))')
echo "kinds/statuses stored: $KINDS"
for want in linear/complete circle/complete straightness/ angular/ roll/ dynamic/ ballbar5x/complete /incomplete /aborted; do
  check "stored_$want" 0 "$want" -- echo "$KINDS"
done
check replayed_stored 0 "replay of run" -- "$DAQ" show --db "$DB" "$REPLAYED"

# --- every read command on every run ------------------------------------------------------------
PDF_RUNS=" 1 2 $BB5X "  # PDF needs Chromium: a linear, a circle and the five-axis ballbar run
for r in $RUNS; do
  survives "show_$r" -- "$DAQ" show "$r" --db "$DB"
  survives "show_json_$r" -- "$DAQ" show "$r" --db "$DB" --json
  for fmt in csv json; do
    for what in readings targets circle; do
      survives "export_${what}_${fmt}_$r" -- "$DAQ" export "$r" --db "$DB" --format "$fmt" --what "$what" -o "$TMP/x.$fmt"
    done
  done
  survives "report_$r" -- "$DAQ" report "$r" --db "$DB" -o "$TMP/r.html"
  if [[ $PDF_RUNS == *" $r "* ]] && command -v chromium >/dev/null; then
    survives "report_pdf_$r" -- "$DAQ" report "$r" --db "$DB" --format pdf -o "$TMP/r.pdf"
  fi
  survives "analyse_$r" -- "$DAQ" analyse "$r" --db "$DB"
  survives "analyse_json_$r" -- "$DAQ" analyse "$r" --db "$DB" --json
  survives "recompensate_$r" -- "$DAQ" recompensate "$r" --db "$DB" --alpha-ppm 11.0
done
# Every kind's report is written, not refused: a five-axis ballbar run's was ("its report is not
# built yet"), which `survives` let pass as a clean refusal.
check report_ballbar5x 0 "run report of run $BB5X written to" -- "$DAQ" report "$BB5X" --db "$DB" -o "$TMP/bb5x.html"
survives runs -- "$DAQ" runs --db "$DB"
survives runs_json -- "$DAQ" runs --db "$DB" --json
# One machine name per line (names hold spaces: "SIMULATED YFXZ"), read whole.
while IFS= read -r m; do
  survives "model_build_${m// /_}" -- "$DAQ" model build --machine "$m" --allow-missing -o "$TMP/model.json" --db "$DB" </dev/null
done < <("$DAQ" runs --db "$DB" --json | "$PY" -c '
import json, sys
names = {r["settings"].get("machine", {}).get("name", "") if isinstance(r["settings"], dict) and isinstance(r["settings"].get("machine"), dict) else "" for r in json.load(sys.stdin)["runs"]}
print("\n".join(sorted(names - {""})))' 2>/dev/null)
# A model of simulated runs says so, whatever its name (issue 26: stored, not inferred).
check model_origin 0 "^SIMULATED: every run of this model was measured on simulated instruments" -- "$DAQ" model build --machine "SIMULATED YFXZ" --allow-missing -o "$TMP/vol-model.json" --db "$DB"
check model_show_origin 0 "SIMULATED: not measured on a real machine" -- "$DAQ" model show "$TMP/vol-model.json"
survives ballbar_history -- "$DAQ" ballbar history --db "$DB" --machine "SIMULATED VMC"
survives ballbar_volumetric -- "$DAQ" ballbar volumetric --db "$DB" --machine "SIMULATED VMC"
echo "$survived commands ended with 0, $refused refused cleanly"
check some_ran 0 "^yes$" -- sh -c "[ $survived -gt 100 ] && echo yes"
finish
