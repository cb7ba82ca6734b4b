#!/usr/bin/env bash
# Issue 26: `daq sim --measure COMPONENT --control-table FILE... --control-format F
# [--control-inverted]`, the SIMULATED control loading a cross-axis or volumetric compensation
# (a known truth), driven with each format it reads, then `daq verify` of the as-left
# straightness run: as caldaq reads the vendor it acts as predicted; read with the other sign it
# doubles the error and verify names the inverted sign. The runs are acquired in the sim's own
# process on simulated time (--acquire): the same readings on a loaded machine.
# Usage: control_table_test.sh DAQ_BINARY
set -u
DAQ=$1
source "$(dirname "$0")/check.sh"
scratch_dir
DB=$TMP/ct.sqlite
M="SIMULATED YFXZ"
sim() {  # sim COMPONENT [--control-table ...]: one run of the component, stored in $DB
  "$DAQ" sim --measure "$1" --topology YFXZ --acquire --db "$DB" -o "$TMP/m.toml" "${@:2}"
}
# verify_run ID PATTERN: daq verify of run ID
verify_run() { check "verify_$1" 0 "$2" -- "$DAQ" verify "$1" --db "$DB"; }
G=(--start-mm 0 --interval-mm 100 --points 6)

check found 0 "stored" -- sim E_YX  # run 1: E_YX as found
check truth 0 "written to" -- "$DAQ" sim --truth-out "$TMP/truth.json" --topology YFXZ
# ISG volumetric from the injected model, stored with the machine (compensation 1): its as-found
# run is the newest E_YX run before it (run 1).
check vol_written 0 "stored as compensation 1 of machine" -- "$DAQ" model compensate "$TMP/truth.json" -f isg-volumetric --interval-mm 50 50 50 --output-dir "$TMP/vol" --machine "$M" --db "$DB"
check vol_loaded 0 "the SIMULATED control applies .*volcomp.lis, .*volcomp.csv \(isg-volumetric\)" -- sim E_YX --control-table "$TMP/vol/volcomp.lis" "$TMP/vol/volcomp.csv" --control-format isg-volumetric  # run 2
verify_run 2 "compensation 1 \(isg-volumetric, .*E_YX against run 1 \(as found\): as predicted"
check vol_inverted 0 "read with the other sign" -- sim E_YX --control-table "$TMP/vol/volcomp.lis" "$TMP/vol/volcomp.csv" --control-format isg-volumetric --control-inverted  # run 3
verify_run 3 "compensation 1 \(isg-volumetric, .*: inverted sign"
# A stored file name that leaves --corrected (a store from elsewhere may hold any text) is
# refused before anything is written.
cp "$DB" "$TMP/hostile.sqlite"
"$PY" - "$TMP/hostile.sqlite" <<'PY'
import sqlite3, sys
db = sqlite3.connect(sys.argv[1])
db.execute("""UPDATE compensations SET json = replace(json, '"name":"volcomp.lis"', '"name":"../evil.lis"') WHERE id = 1""")
db.commit()
PY
check corrected_name_refused 2 'compensation 1 names a file "\.\./evil\.lis", which is not a plain file name: nothing written' -- "$DAQ" verify 3 --db "$TMP/hostile.sqlite" --corrected "$TMP/fixed-vol"
check corrected_name_nothing_written 0 "^none$" -- bash -c "ls \"$TMP/evil.lis\" \"$TMP/fixed-vol\" 2>/dev/null || echo none"

# From the as-found run (daq compensate --run stores it with run 1 as its source).
table() {  # table FORMAT FILE: the table of run 1 in FORMAT, stored with it
  check "table_$1" 0 "stored as compensation" -- "$DAQ" compensate --run 1 --db "$DB" -f "$1" "${G[@]}" -o "$2"
}
table siemens-cec "$TMP/cec.mpf"  # compensation 2
check cec_loaded 0 "applies .*cec.mpf \(siemens-cec\)" -- sim E_YX --control-table "$TMP/cec.mpf" --control-format siemens-cec  # run 4
verify_run 4 "compensation 2 \(siemens-cec, run 1 of axis Y\), E_YX against run 1 \(as found\): as predicted"
check cec_inverted 0 "stored" -- sim E_YX --control-table "$TMP/cec.mpf" --control-format siemens-cec --control-inverted  # run 5
check verify_5 0 "compensation 2 \(siemens-cec.*: inverted sign" -- "$DAQ" verify 5 --db "$DB" --corrected "$TMP/cec-fixed.mpf"
# The corrected file in the control that reads the other sign: as predicted.
check cec_fixed 0 "stored" -- sim E_YX --control-table "$TMP/cec-fixed.mpf" --control-format siemens-cec --control-inverted  # run 6
verify_run 6 "compensation 2 \(siemens-cec.*: as predicted"

table isg "$TMP/cross.lis"  # compensation 3
check isg_loaded 0 "applies .*cross.lis \(isg-cross\)" -- sim E_YX --control-table "$TMP/cross.lis" --control-format isg-cross  # run 7
verify_run 7 "compensation 3 \(isg-cross.*: as predicted"
check isg_inverted 0 "stored" -- sim E_YX --control-table "$TMP/cross.lis" --control-format isg-cross --control-inverted  # run 8
verify_run 8 "compensation 3 \(isg-cross.*: inverted sign"

table csv "$TMP/cross.csv"  # compensation 4
check csv_loaded 0 "applies .*cross.csv \(csv\)" -- sim E_YX --control-table "$TMP/cross.csv" --control-format csv  # run 9
verify_run 9 "compensation 4 \(csv.*: as predicted"

# HEIDENHAIN: the *.COM and the *.CMA row the control needs (Y.COM in the column X: Y = F(X)),
# which daq compensate names and stores with the table.
check table_heidenhain 0 "enter Y.COM in the column X of the active row of the control's \*\.CMA" -- "$DAQ" compensate --run 1 --db "$DB" -f heidenhain "${G[@]}" -o "$TMP/Y.COM"  # compensation 5
printf 'ACTIVE X\n* Y.COM\n' >"$TMP/config.cma"
check hh_loaded 0 "applies .*Y.COM, .*config.cma \(heidenhain\)" -- sim E_YX --control-table "$TMP/Y.COM" "$TMP/config.cma" --control-format heidenhain  # run 10
verify_run 10 "compensation 5 \(heidenhain.*: as predicted"
check hh_inverted 0 "stored" -- sim E_YX --control-table "$TMP/Y.COM" "$TMP/config.cma" --control-format heidenhain --control-inverted  # run 11
verify_run 11 "compensation 5 \(heidenhain.*: inverted sign"
# A *.COM without its *.CMA: the input axis is unknown, the control refuses it.
check hh_no_cma 2 "no \*\.CMA among the files" -- sim E_YX --control-table "$TMP/Y.COM" --control-format heidenhain

# LinuxCNC matrixkins (E_C0Y carried by Y: X corrected over Y) is seen by E_XY.
check found_xy 0 "stored" -- sim E_XY  # run 12
check mk_written 0 "stored as compensation 6 of machine" -- "$DAQ" model compensate "$TMP/truth.json" -f linuxcnc --interval-mm 50 50 50 --output-dir "$TMP/lc" --machine "$M" --db "$DB"
check mk_loaded 0 "applies .*matrixkins.hal \(linuxcnc-matrixkins\)" -- sim E_XY --control-table "$TMP/lc/matrixkins.hal" --control-format linuxcnc-matrixkins  # run 13
verify_run 13 "compensation 6 \(linuxcnc-matrixkins.*E_XY against run 12 \(as found\): as predicted"
check mk_inverted 0 "stored" -- sim E_XY --control-table "$TMP/lc/matrixkins.hal" --control-format linuxcnc-matrixkins --control-inverted  # run 14
verify_run 14 "compensation 6 \(linuxcnc-matrixkins.*: inverted sign"
finish
