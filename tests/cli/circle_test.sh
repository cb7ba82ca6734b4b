#!/usr/bin/env bash
# daq analyse circle on fixtures from an exact forward model, written by
# tests/data/circle/make_fixtures.py (model.csv: angles; model_time.csv: a timed program with
# overshoot arcs and absolute bar lengths). Usage: circle_test.sh DAQ_BINARY DATA_DIR
set -u
DAQ=$1
DATA=$2
source "$(dirname "$0")/check.sh"
# Injected: squareness +20 um/m, backlash X 4 um, Y lags X by 1.0 ms, centre (5, -3) um.
# Tolerances: the fixture is noise-free, the fit is first order (second-order terms < 1 nm at
# R = 50 mm); a step sampled every 0.25 degrees lets the reversal-spike term take ~2 % of the
# backlash. So: squareness and the centre to 0.01, the lag to 0.5 %, backlash to 2.5 %.
check squareness 0 "Squareness XY +\+(19\.99|20\.00)[0-9]* um/m" -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50 --cyclic-period-mm 10
check backlash 0 "Backlash X +\+(3\.9[0-9]*|4\.0[0-9]*) um" -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50 --cyclic-period-mm 10
check servo 0 "Servo mismatch \(Y lags X\) +\+(1\.00|0\.99)[0-9]* ms" -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50 --cyclic-period-mm 10
check centre 0 "Centre offset X +\+5\.00[0-9]* um" -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50 --cyclic-period-mm 10
check json 0 '"schema": "caldaq.circle.v2"' -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50 --json
# Standards (docs/circle.md, "Standards"): ISO 230-4:2005 reports G(b), G per direction and F,
# with H apart as informative (a 1996 quantity) and the mean bi-directional radial deviation
# named as not evaluated; GB/T 17421.4-2016 the same values under its own name; the 1996
# edition G per direction, H and F; the standards whose definitions are not public refused.
J=(analyse circle -i "$DATA/model.csv" -R 50 --cyclic-period-mm 10 --json)
check iso2005_keys 0 "^F_max_um,F_min_um,G_bi_um,G_ccw_um,G_cw_um,arc_deg,centre_um H_um$" -- sh -c "\"$DAQ\" ${J[*]} | python3 -c \"import json,sys; d=json.load(sys.stdin); print(','.join(sorted(d['iso230_4'])), ','.join(d['informative']))\""
check iso2005_not_evaluated 0 "not evaluated: mean bi-directional radial deviation" -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50
check iso2005_title 0 "^ISO 230-4:2005 circular test" -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50
check gbt 0 "^GB/T 17421.4-2016 circular test" -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50 -s gb/t17421.4-2016
check gbt_same_g 0 '"standard": "GB/T 17421.4-2016"' -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50 -s GB/T17421.4-2016 --json
check iso1996_h 0 "^  H +[0-9.]+ um   circular hysteresis$" -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50 -s iso230-4:1996
check iso1996_no_gb 0 "^F_max_um,F_min_um,G_ccw_um,G_cw_um,H_um,arc_deg,centre_um$" -- sh -c "\"$DAQ\" ${J[*]} -s iso230-4:1996 | python3 -c \"import json,sys; print(','.join(sorted(json.load(sys.stdin)['iso230_4'])))\""
check asme 2 "circular standard 'asme-b5.54': only the scopes of ASME B5.54-2005 and B5.57-2012 are public" -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50 -s asme-b5.54
check jis 2 "circular standard 'jis-b6190-4': no public text of JIS B 6190-4 was found" -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50 -s jis-b6190-4
check iso2022 2 "circular standard 'iso230-4:2022': its public scope renames the quantities" -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50 -s iso230-4:2022
check unknown_standard 2 "circular standard 'iso230-2' \(expected iso230-4:2005" -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50 -s iso230-2
check bad_direction 2 "bad_direction.csv:3: column direction: 'sideways'" -- "$DAQ" analyse circle -i "$DATA/bad_direction.csv" -R 50
check missing 2 "no_such.csv: cannot open" -- "$DAQ" analyse circle -i "$DATA/no_such.csv" -R 50
check too_few 2 "ccw trace has 3 samples, at least 20 needed" -- "$DAQ" analyse circle -i "$DATA/few.csv" -R 50
# The timed program (tests/data/circle/model_time.csv, from make_fixtures.py): absolute bar
# lengths at 100 Hz from the start of each arc move, 30 degree overshoot arcs that are 30 um off
# the circle (kept samples would show in the residual), cyclic period searched. Injected:
# squareness -15 um/m, Y lags X by 0.5 ms, cyclic X 1.0 um at 5 mm, centre (-2, 4) um.
# Noise-free and first order (second-order terms < 1 nm): to the printed 0.01 um/m, 0.001 ms,
# and 0.5 % of the cyclic amplitude; the period search to 0.01 mm.
T=(analyse circle -i "$DATA/model_time.csv" -R 50 --start-deg 90 --overshoot-deg 30)
check time_squareness 0 "Squareness XY +-15\.0[0-9]* um/m" -- "$DAQ" "${T[@]}"
check time_servo 0 "Servo mismatch \(Y lags X\) +\+0\.500 ms" -- "$DAQ" "${T[@]}"
check time_cyclic 0 "Cyclic error X \(5\.00 mm period\) +\+(0\.99[5-9]|1\.00[0-5]) um" -- "$DAQ" "${T[@]}"
check time_centre 0 "centre +-2\.000, 4\.000 um +least-squares centre" -- "$DAQ" "${T[@]}"
check time_trimmed 0 "residual rms 0\.00[0-9] um" -- "$DAQ" "${T[@]}"
check time_untrimmed 0 "residual rms ([1-9]|0\.[1-9])" -- "$DAQ" analyse circle -i "$DATA/model_time.csv" -R 50 --start-deg 90 --overshoot-deg 0 --arc-deg 360
check time_json 0 '"g_reduction_um"' -- "$DAQ" "${T[@]}" --json
# The bar read 0 at 50.002 mm: every deviation is 2 um more than it says (radius error +2; the
# backlash step sampled every 0.25 degrees moves the constant term by up to 0.01 um).
check calibrated 0 "Radius error +\+(1\.99|2\.00)[0-9]* um" -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50 --cyclic-period-mm 10 --calibrated-radius-mm 50.002
check no_calibration_no_radius 0 "note: uncalibrated bar: the radius error is fitted but not reported" -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50 --cyclic-period-mm 10
check lengths_are_absolute 0 "Radius error" -- "$DAQ" "${T[@]}"
check too_much_overshoot 2 "keeps 0 samples after trimming the 500 degree overshoot" -- "$DAQ" analyse circle -i "$DATA/model_time.csv" -R 50 --overshoot-deg 500
check bad_plane 2 "plane 'XZ' \(expected XY, YZ or ZX\)" -- "$DAQ" analyse circle -i "$DATA/model.csv" -R 50 --plane XZ
finish
