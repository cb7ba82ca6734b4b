#!/usr/bin/env bash
# daq analyse straightness | squareness. Usage: geometry_test.sh DAQ_BINARY DATA_DIR
set -u
DAQ=$1
DATA=$2
source "$(dirname "$0")/check.sh"
scratch_dir
# The hand set: LSQ 2.7 um at 7 um/m, end point 2.75 um, minimum zone 2.5 um at 5 um/m.
check lsq 0 "straightness +2\.700 um" -- "$DAQ" analyse straightness -i "$DATA/hand.csv"
check endpoint 0 "straightness +2\.750 um" -- "$DAQ" analyse straightness -i "$DATA/hand.csv" -r endpoint
check minzone 0 '"straightness_um": 2\.5' -- "$DAQ" analyse straightness -i "$DATA/hand.csv" -r minzone --json
# Slopes -20 um/m (B per A) and -10 um/m (A per B): squareness -(-20 - 10) = +30 um/m.
check square_straightness 0 "\+30\.000 um/m" -- "$DAQ" analyse squareness -m straightness --along-a "$DATA/along_a.csv" --along-b "$DATA/along_b.csv"
# X 400, Y 300 (D0 500), d1 4.8, d2 -4.8 um: 500 x 9.6 / (2 x 120000) mm^-1 = 20 um/m.
check square_diagonal 0 '"squareness_um_per_m": 20\.0' -- "$DAQ" analyse squareness -m diagonal --x-mm 400 --y-mm 300 --d1-um 4.8 --d2-um -4.8 --json
# The same +20 um/m in the model's convention: E_C0Y = +20 in XY, E_B0Z = -20 in XZ (a positive
# rotation of Z about Y closes the angle), E_A0Z = +20 in YZ.
check square_plane_xy 0 "E_C0Y = \+20\.000 urad" -- "$DAQ" analyse squareness -m diagonal --x-mm 400 --y-mm 300 --d1-um 4.8 --d2-um -4.8 --plane XY
check square_plane_xz 0 "E_B0Z = -20\.000 urad" -- "$DAQ" analyse squareness -m diagonal --x-mm 400 --y-mm 300 --d1-um 4.8 --d2-um -4.8 --plane ZX
check square_plane_json 0 '"iso230_1_urad": 20\.0' -- "$DAQ" analyse squareness -m diagonal --x-mm 400 --y-mm 300 --d1-um 4.8 --d2-um -4.8 --plane YZ --json
check square_plane_bad 2 "plane 'XX'" -- "$DAQ" analyse squareness -m diagonal --x-mm 400 --y-mm 300 --d1-um 4.8 --d2-um -4.8 --plane XX
check bad_number 2 "bad.csv:3: column deviation_um: 'x' is not a number" -- "$DAQ" analyse straightness -i "$DATA/bad.csv"
check bad_reference 2 "unknown reference line 'best'" -- "$DAQ" analyse straightness -i "$DATA/hand.csv" -r best
# Reports: the hand values of all three reference lines, the plot with its lines.
check straightness_report 0 "report written to $TMP/s.html" -- "$DAQ" analyse straightness -i "$DATA/hand.csv" --report "$TMP/s.html"
check report_lsq 0 "<td>least squares</td><td class=\"r\">2\.700</td><td class=\"r\">\\+7\.000</td>" -- cat "$TMP/s.html"
check report_endpoint 0 "<td>end point</td><td class=\"r\">2\.750</td>" -- cat "$TMP/s.html"
check report_minzone 0 "<td>minimum zone</td><td class=\"r\">2\.500</td><td class=\"r\">\\+5\.000</td>" -- cat "$TMP/s.html"
check report_plot 0 "<svg class=\"plot\" role=\"img\" aria-label=\"Straightness deviations and reference lines\"" -- cat "$TMP/s.html"
check squareness_report 0 "\+30\.000 um/m" -- "$DAQ" analyse squareness -m straightness --along-a "$DATA/along_a.csv" --along-b "$DATA/along_b.csv" --report "$TMP/q.html"
check squareness_report_value 0 "<td class=\"r\">\+30\.000 µm/m</td>" -- cat "$TMP/q.html"
check squareness_report_plots 0 "^2$" -- grep -c "<svg class=\"plot\"" "$TMP/q.html"
check squareness_report_refused 2 "--report draws the two runs" -- "$DAQ" analyse squareness -m diagonal --x-mm 400 --y-mm 300 --d1-um 4.8 --d2-um -4.8 --report "$TMP/x.html"
check bad_method 2 "squareness method 'laser'" -- "$DAQ" analyse squareness -m laser
finish
