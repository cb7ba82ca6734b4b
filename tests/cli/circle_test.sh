#!/usr/bin/env bash
# daq analyse circle on a fixture from an exact forward model (tests/data/circle/model.csv,
# parameters in its first line). Usage: circle_test.sh DAQ_BINARY DATA_DIR
set -u
DAQ=$1
DATA=$2
fails=0
passes=0
check() {  # check NAME EXPECTED_EXIT PATTERN -- command...
  local name=$1 want=$2 pattern=$3
  shift 4
  local out
  out=$("$@" 2>&1)
  local rc=$?
  if [ "$rc" -ne "$want" ]; then echo "FAIL $name: exit $rc, expected $want"; echo "$out" | head -20; fails=$((fails + 1)); return; fi
  if ! grep -qE -- "$pattern" <<<"$out"; then echo "FAIL $name: output lacks /$pattern/"; echo "$out" | head -30; fails=$((fails + 1)); return; fi
  passes=$((passes + 1))
}
# Injected: squareness +20 um/m, backlash X 4 um, Y lags X by 1.0 ms, centre (5, -3) um.
# Tolerances: the fixture is noise-free, the fit is first order (second-order terms < 1 nm at
# R = 50 mm); a step sampled every 0.25 degrees lets the reversal-spike term take ~2 % of the
# backlash. So: squareness and the centre to 0.01, the lag to 0.5 %, backlash to 2.5 %.
check squareness 0 "Squareness XY +\+(19\.99|20\.00)[0-9]* um/m" -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50 --cyclic-period-mm 10
check backlash 0 "Backlash X +\+(3\.9[0-9]*|4\.0[0-9]*) um" -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50 --cyclic-period-mm 10
check servo 0 "Servo mismatch \(Y lags X\) +\+(1\.00|0\.99)[0-9]* ms" -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50 --cyclic-period-mm 10
check centre 0 "Centre offset X +\+5\.00[0-9]* um" -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50 --cyclic-period-mm 10
check json 0 '"schema": "caldaq.circle.v1"' -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50 --json
check bad_direction 2 "bad_direction.csv:3: column direction: 'sideways'" -- "$DAQ" analyse circle -i "$DATA/bad_direction.csv" -R 50
check missing 2 "no_such.csv: cannot open" -- "$DAQ" analyse circle -i "$DATA/no_such.csv" -R 50
check too_few 2 "ccw trace has 3 samples, at least 20 needed" -- "$DAQ" analyse circle -i "$DATA/few.csv" -R 50
echo "$passes passed, $fails failed"
[ "$fails" -eq 0 ]
