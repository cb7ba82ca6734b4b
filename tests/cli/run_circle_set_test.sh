#!/usr/bin/env bash
# The standard ballbar set end to end: `daq sim --test circle-set` runs the SIMULATED shop with
# squareness in all three planes, a slower Z loop, backlash and cyclic error on every axis
# (daq/src/sim/sim_shop.cpp ShopTruth::three_planes) through the ballbar twin; `daq run
# circle` acquires the six tests (XY 360 deg, ZX and YZ 220 deg, each at 1000 and 3000 mm/min)
# in one go through the real gauge driver, recognising each by its feed-in, and stores them as
# one campaign; `daq ballbar volumetric` and `daq report --campaign` give the three-plane table.
# Usage: run_circle_set_test.sh DAQ_BINARY DATA_DIR
set -u
DAQ=$1
source "$(dirname "$0")/check.sh"
scratch_dir

# The whole set in SIMULATED time: `daq sim --acquire` runs `daq run circle` on the
# configuration it writes, in its own process on simulated time (about 2 s instead of 16 s
# live at --speed 40): the same configuration, gauge driver over the same pseudo-terminal,
# run, stores and capture. The two-process wiring of `daq sim` and `daq run circle` is run live
# by run_circle_test.sh.
"$DAQ" sim --test circle-set --acquire -o "$TMP/sim.toml" --db "$TMP/run.sqlite" --capture "$TMP/set.cdq" >"$TMP/run.log" 2>&1
rc=$?
RUN=$(cat "$TMP/run.log")
[ "$rc" -eq 0 ] || { echo "FAIL run: exit $rc"; echo "$RUN" | tail -30; fails=$((fails + 1)); }
check six_tests 0 "6 tests stored as runs 1\.\.6 of campaign 'simulated'" -- echo "$RUN"
check each_test_recognised 0 "test 6 of 6: ballbar YZ R 100 mm at 3000 mm/min" -- echo "$RUN"

VOL=$("$DAQ" ballbar volumetric --db "$TMP/run.sqlite" --machine "SIMULATED VMC" 2>&1)
echo "$VOL"
# The injected truth: E_C0Y +20, E_B0Z +15 (alpha ZX -15), E_A0Z -10 urad. The tolerance
# +-0.3 um/m: the bar's 0.15 um noise moves a 220 deg arc's squareness by a few 0.01 um/m,
# backlash and cyclic errors are fitted with it (their correlation on a partial arc), and the
# first-order servo model leaves the second-order lag of the loops.
check table_xy 0 "XY +1 +1000 +\+(19\.[7-9]|20\.[0-3])[0-9]* +E_C0Y = +\+(19\.[7-9]|20\.[0-3])" -- echo "$VOL"
check table_zx 0 "ZX +3 +1000 +-(14\.[7-9]|15\.[0-3])[0-9]* +E_B0Z = +\+(14\.[7-9]|15\.[0-3])" -- echo "$VOL"
check table_yz 0 "YZ +5 +1000 +-(9\.[7-9]|10\.[0-3])[0-9]* +E_A0Z = +-(9\.[7-9]|10\.[0-3])" -- echo "$VOL"
check closure 0 "closure" -- echo "$VOL"
# Z's loop is slower than X's (1/29.4 - 1/30 s = 0.680 ms) and Y's (0.343 ms); in ZX the lag
# is named "X lags Z", so Z lagging X is negative.
A3=$("$DAQ" analyse 3 --db "$TMP/run.sqlite" 2>&1)
A5=$("$DAQ" analyse 5 --db "$TMP/run.sqlite" 2>&1)
check servo_zx 0 "Servo mismatch \(X lags Z\) +-0\.(6[4-9]|7[0-2])[0-9]* ms" -- echo "$A3"
check servo_yz 0 "Servo mismatch \(Z lags Y\) +\+0\.3[2-6][0-9]* ms" -- echo "$A5"
check backlash_z 0 "Backlash Z +\+(1\.[89]|2\.[01])[0-9]* um" -- echo "$A5"
check backlash_y 0 "Backlash Y +\+(2\.[89]|3\.[01])[0-9]* um" -- "$DAQ" analyse 1 --db "$TMP/run.sqlite"
check history 0 "ZX at 3000 mm/min, R 100 mm" -- "$DAQ" ballbar history --db "$TMP/run.sqlite" --machine "SIMULATED VMC"
"$DAQ" report --campaign simulated --db "$TMP/run.sqlite" -o "$TMP/campaign.html" >/dev/null
check report_table 0 "<h3>Three-plane table</h3>" -- cat "$TMP/campaign.html"
check report_b0z 0 "E_B0Z = \+1[45]\.[0-9]{3}" -- cat "$TMP/campaign.html"
# The runs averaged by number, said so (a bare "1" under "runs" read as a count).
check report_runs_named 0 "<td[^>]*>XY</td><td[^>]*>runs? [0-9]+(, [0-9]+)*</td>" -- cat "$TMP/campaign.html"
# The capture replayed: the whole set again, as runs 7..12, with the same squareness.
REP=$("$DAQ" replay "$TMP/set.cdq" --db "$TMP/run.sqlite" 2>&1)
check replay_all 0 "replayed .* into run 12 " -- echo "$REP"
SQ=$(grep 'Squareness ZX' <<<"$A3")
check replay_same_squareness 0 "$(sed 's/[()]/\\&/g' <<<"$SQ")" -- "$DAQ" analyse 9 --db "$TMP/run.sqlite"
[ -n "${KEEP_REPORT:-}" ] && cp "$TMP/campaign.html" "$KEEP_REPORT"
finish
