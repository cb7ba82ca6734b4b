#!/usr/bin/env bash
# daq run linear end to end across processes: `daq sim --test linear` runs the SIMULATED shop
# (laser twin on TCP, PTU300 and thermometer twins on pseudo-terminals) and writes the devices'
# configuration; `daq run linear` builds its instruments from that file, captures each stop
# with the stability trigger, stores and evaluates; its capture replays to the same result.
# Usage: run_linear_test.sh DAQ_BINARY DATA_DIR
set -u
DAQ=$1
source "$(dirname "$0")/check.sh"
scratch_dir

# Live across processes, a SHORT program for the wiring (2 runs over 3 targets, 0 .. 100 mm:
# about 6 s of wall time); the accuracy over the full ISO 230-2 program is checked below on the
# replayed capture of the same program recorded in simulated time.
# Speed 5: the program's 3 s dwells last 0.6 s of wall time, the configured trigger dwell
# 0.3 s (sim_config divides it by the speed): a loaded CI machine keeps a 2x margin.
"$DAQ" sim --test linear --runs 2 --targets 3 --speed 5 --start-after-s 2 -o "$TMP/sim.toml" >"$TMP/sim.log" 2>&1 &
SIM_PID=$!
for _ in $(seq 100); do [ -s "$TMP/sim.toml" ] && break; sleep 0.1; done
[ -s "$TMP/sim.toml" ] || { echo "FAIL: daq sim wrote no configuration"; cat "$TMP/sim.log"; exit 1; }

"$DAQ" run linear -c "$TMP/sim.toml" --db "$TMP/run.sqlite" --capture "$TMP/lin.cdq" >"$TMP/run.log" 2>&1 &
RUN_PID=$!
# Progress into a file is written as it happens: the second target's line is there while the
# run still goes on (it was held in the stdio buffer until the end).
live=no
for _ in $(seq 1200); do
  if grep -q "^run 1 of 2 up  target 2 of 3" "$TMP/run.log"; then
    kill -0 "$RUN_PID" 2>/dev/null && live=yes
    break
  fi
  sleep 0.1
done
check progress_flushed 0 "^yes$" -- echo "$live"
wait "$RUN_PID"
kill "$SIM_PID" 2>/dev/null
SIM_PID=
RUN=$(cat "$TMP/run.log")
check stored_complete 0 "^run 1 stored \(complete\)" -- echo "$RUN"
# daq sim's configuration carries the machine specification of daq demo: the injected 4 um
# backlash exceeds its B limit of 3 um, the rest is within.
check verdict 0 "^verdict against tolerances.X.*: FAIL" -- echo "$RUN"
# B (the largest of the three targets' reversal values) within 0.15 um of the injected 4 um:
# the live run's stops are means of a few noisy readings, fewer under load (3.995 um and 4.100 um
# were seen in CI; a pattern "3.9x|4.0x" failed the second). Compared as a number.
check verdict_on_b 0 "^  B +[0-9.]+ um +limit +3\.000 um +FAIL" -- echo "$RUN"
B_UM=$(sed -nE 's/^  B +([0-9.]+) um +limit.*/\1/p' <<<"$RUN")
check b_near_injected 0 "^near$" -- awk -v b="${B_UM:-999}" 'BEGIN { d = b - 4; print (d <= 0.15 && d >= -0.15) ? "near" : "B " b " um is not within 0.15 um of 4 um" }'
check verdict_e_passes 0 "^  E +[0-9.]+ um +limit +10\.000 um +pass" -- echo "$RUN"
# The machine rests on the first target while the program has not started: that is no stop.
check rest_is_no_stop 0 "stop at .* without an approach move .*: ignored" -- echo "$RUN"
check all_stops 0 "all stops captured" -- echo "$RUN"
# Injected (ShopTruth): backlash 4 um, so the mean reversal value is -4 um. Live, a stop is the
# mean of however many readings the loaded machine's trigger took (one target's reversal was
# 4.10 um in CI), so within +/-0.1 um here; +/-0.05 um on the simulated-time runs below.
check reversal 0 "B̄ +-[0-9.]+ um" -- echo "$RUN"
BMEAN_UM=$(sed -nE 's/^  B̄ +-([0-9.]+) um.*/\1/p' <<<"$RUN")
check reversal_near_injected 0 "^near$" -- awk -v b="${BMEAN_UM:-999}" 'BEGIN { d = b - 4; print (d <= 0.1 && d >= -0.1) ? "near" : "B mean -" b " um is not within 0.1 um of -4 um" }'
B1=$(sed -nE 's/^  B̄ +([-+0-9.]+) um.*/\1/p' <<<"$RUN" | sed 's/\./\\./')
check replay 0 "replayed .* into run 2" -- "$DAQ" replay "$TMP/lin.cdq" --db "$TMP/run.sqlite"
check replay_same_b 0 "^  B̄ +$B1 um" -- "$DAQ" analyse 2 --db "$TMP/run.sqlite"

# The full program (5 runs over 11 targets, 55 stops per direction), the same shop, program,
# configuration and trigger as `daq sim --test linear`: recorded in simulated time by `daq demo`
# and replayed through the same instruments and stages as `daq run linear`, so the accuracy of
# the whole program is checked on the replayed capture (it took 2 minutes of wall time live).
# (`daq demo --quiet`: the ctest fixture "demo", or run here.)
mkdir "$TMP/full"
demo_runs "$TMP/full"
check full_replay 0 "replayed .* into run 3" -- "$DAQ" replay "$DEMO_CDQ" --db "$TMP/full/demo.sqlite"
FULL=$("$DAQ" analyse 3 --db "$TMP/full/demo.sqlite")
check full_all_stops 0 "5 runs per direction" -- echo "$FULL"
check full_reversal 0 "B̄ +-(3\.9[5-9]|4\.0[0-5])[0-9]* um" -- echo "$FULL"

# The position-assisted trigger: the shop's MTConnect SHDR adapter feeds the control's
# commanded position; stops are recognised from it and the laser averaged over the dwell. In
# SIMULATED time (`daq sim --acquire` runs `daq run linear --json` on the configuration it
# writes, in one process: the same instruments over the same TCP and pseudo-terminal channels,
# run, store and capture; 1 s instead of 4 s live at --speed 10).
# --json: the result on stdout, the progress on stderr.
"$DAQ" sim --test linear --runs 2 --targets 3 --position-feed --acquire --json -o "$TMP/simp.toml" --db "$TMP/pos.sqlite" --capture "$TMP/pos.cdq" >"$TMP/pos.json" 2>"$TMP/pos.log"
POS=$(cat "$TMP/pos.log")
check position_feed_used 0 "stops are recognised from the machine position feed" -- echo "$POS"
check position_all_stops 0 "all stops captured" -- echo "$POS"
check position_json 0 "^complete 1 0 iso230-2:2014$" -- "$PY" -c "import json; d=json.load(open('$TMP/pos.json')); print(d['status'], d['run_id'], len(d['missed_stops']), d['standard']['key'])"
B2=$("$PY" -c "import json; print(format(json.load(open('$TMP/pos.json'))['axis']['B_mean']['value_um'], '.3f'))")
check position_reversal 0 "^-(3\.9[5-9]|4\.0[0-5])" -- echo "$B2"
B2=$(sed 's/\./\\./' <<<"$B2")
check position_replay_same_b 0 "^  B̄ +$B2 um" -- "$DAQ" replay "$TMP/pos.cdq" --db "$TMP/pos.sqlite"
finish
