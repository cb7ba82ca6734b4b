#!/usr/bin/env bash
# daq run circle end to end across processes: `daq sim` runs the SIMULATED shop (machine with
# injected errors, the ballbar twin on a pseudo-terminal) and writes its devices' configuration;
# `daq run circle` acquires through the real gauge driver, stores and analyses; `daq replay`
# of its capture and `daq analyse RUN` of the stored readings give the same G.
# Usage: run_circle_test.sh DAQ_BINARY DATA_DIR
set -u
DAQ=$1
DATA=$2
TMP=$(mktemp -d)
SIM_PID=
cleanup() { [ -n "$SIM_PID" ] && kill "$SIM_PID" 2>/dev/null; rm -rf "$TMP"; }
trap cleanup EXIT
source "$(dirname "$0")/check.sh"

"$DAQ" sim --test circle --speed 20 --start-after-s 3 -o "$TMP/sim.toml" >"$TMP/sim.log" 2>&1 &
SIM_PID=$!
for _ in $(seq 100); do [ -s "$TMP/sim.toml" ] && break; sleep 0.1; done
[ -s "$TMP/sim.toml" ] || { echo "FAIL: daq sim wrote no configuration"; cat "$TMP/sim.log"; exit 1; }

# The injected truth (daq/src/runtime/sim_shop.hpp ShopTruth): squareness +20 um/m, Y lags X by
# 1/29.7 - 1/30 s = 0.337 ms, backlash X 4 um, pitch error of X 1 um over 40 mm, noise 0.15 um.
# Tolerances: the bar's noise moves the fitted terms by ~0.01 of their unit over 2 x 37,700
# samples; backlash shares its step with the reversal-spike term (~0.1 um) and the servo
# lag is read with the Kv loops' own second-order shape (~2 %), hence the ranges below.
"$DAQ" run circle -c "$TMP/sim.toml" --db "$TMP/run.sqlite" --capture "$TMP/circle.cdq" >"$TMP/run.log" 2>&1
rc=$?
RUN=$(cat "$TMP/run.log")
check run_stored 0 "^run 1: [0-9]+ readings" -- echo "$RUN"
[ "$rc" -eq 0 ] || { echo "FAIL run: exit $rc"; echo "$RUN" | tail -20; fails=$((fails + 1)); }
check squareness 0 "Squareness XY +\+(19\.9[5-9]|20\.0[0-5])[0-9]* um/m" -- echo "$RUN"
check servo 0 "Servo mismatch \(Y lags X\) +\+0\.3[3-5][0-9]* ms" -- echo "$RUN"
check backlash 0 "Backlash X +\+(3\.9[0-9]|4\.[01][0-9])[0-9]* um" -- echo "$RUN"
check cyclic 0 "Cyclic error X \(40\.00 mm period\) +\+(0\.9[7-9]|1\.0[0-3])[0-9]* um" -- echo "$RUN"
G1=$(grep -E "^  G\(b\) " <<<"$RUN")

# The capture replays into run 2 with the same G to the last printed digit; the stored raw
# readings analysed again give it too; a corrected calibrated length (+2 um) moves the radius
# error by +2 um and nothing else.
check replay 0 "replayed .* into run 2" -- "$DAQ" replay "$TMP/circle.cdq" --db "$TMP/run.sqlite"
check replay_same_g 0 "$(sed 's/[()]/\\&/g' <<<"$G1")" -- "$DAQ" analyse 2 --db "$TMP/run.sqlite"
check analyse_stored_same_g 0 "$(sed 's/[()]/\\&/g' <<<"$G1")" -- "$DAQ" analyse 1 --db "$TMP/run.sqlite"
R0=$("$DAQ" analyse 1 --db "$TMP/run.sqlite" | sed -nE 's/^ +Radius error +([+-][0-9.]+) um.*/\1/p')
R2=$("$DAQ" analyse 1 --db "$TMP/run.sqlite" --calibrated-radius-mm 100.002 | sed -nE 's/^ +Radius error +([+-][0-9.]+) um.*/\1/p')
if awk -v a="$R0" -v b="$R2" 'BEGIN { d = b - a; exit !(d > 1.999 && d < 2.001) }'; then
  passes=$((passes + 1))
else
  echo "FAIL calibrated_radius: radius error $R0 -> $R2 um, expected +2.000"; fails=$((fails + 1))
fi
check runs_listed 0 "circle +XY.*complete" -- "$DAQ" runs --db "$TMP/run.sqlite"

# Refusals name what is missing.
check no_ballbar 2 "no device with role = \"ballbar\"" -- "$DAQ" run circle -c "$DATA/run/refused.toml" --db "$TMP/x.sqlite"
check bad_sim_test 2 "--test 'spiral'" -- "$DAQ" sim --test spiral -o "$TMP/y.toml"

finish
