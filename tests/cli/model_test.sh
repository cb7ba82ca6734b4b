#!/usr/bin/env bash
# daq model show | map | compensate | testpiece on the model files of tests/data/model.
# Usage: model_test.sh DAQ_BINARY DATA_DIR
set -u
DAQ=$1
DATA=$2
source "$(dirname "$0")/check.sh"
scratch_dir
Y=$DATA/yfxz.json
S=$DATA/square50.json
check show 0 "topology +YFXZ: workpiece <- Y <- F -> X -> Z -> tool" -- "$DAQ" model show "$Y"
# E_B0Z stated as +8 um/m over 90 deg is the location error -8 urad.
check show_b0z 0 "E_B0Z .* -8\.000 urad \(\+8\.000 um/m over 90 deg\), carried by Z" -- "$DAQ" model show "$Y"
check show_json 0 '"iso230_1_urad": -8\.0' -- "$DAQ" model show "$Y" --json
# Only E_C0Y = 50 urad: e_x = -0.05 y um, so -5 um at y = 100 and 10 um at y = 200.
printf 'x_mm,y_mm,z_mm\n0,100,0\n150,0,-50\n' > "$TMP/p.csv"
check map_point 0 "^ +0\.000 +100\.000 +0\.000 +-5\.000 +0\.000 +0\.000 +5\.000$" -- "$DAQ" model map "$S" --points "$TMP/p.csv"
check map_grid 0 "largest \|e\| +10\.000 um at \([0-9]+, 200, -?[0-9]+\) mm" -- "$DAQ" model map "$S"
check map_rank 0 "1\. E_C0Y +10\.000 um" -- "$DAQ" model map "$S"
check map_json 0 '"schema": "caldaq.volumetric-map.v1"' -- "$DAQ" model map "$Y" --count 3 3 3 --json
check map_report 0 "report written to $TMP/map.html" -- "$DAQ" model map "$Y" --report "$TMP/map.html"
check map_report_svg 0 "^3$" -- grep -c "<svg class=\"plot\"" "$TMP/map.html"
check map_report_rank 0 "<td>E_YY</td>" -- cat "$TMP/map.html"
# Each error's source in words, not the model file's raw JSON object.
"$DAQ" sim --truth-out "$TMP/truth.json" >/dev/null
"$DAQ" model map "$TMP/truth.json" --count 3 3 3 --report "$TMP/truth.html" >/dev/null
check map_report_source 0 "<td>origin: simulated; what: injected</td>" -- cat "$TMP/truth.html"
check map_report_no_raw_json 0 "^0$" -- bash -c 'grep -c "{&quot;origin\|{\"origin" "$1"; true' _ "$TMP/truth.html"
check map_outside 2 "E_YY: position 450 mm is outside the error table" -- "$DAQ" model map "$Y" --min-mm 0 0 -300 --max-mm 500 450 0
# Compensation: the squareness on its carrier Y is the table X = f(Y), +0.05 um per mm of y:
# 0.0050 mm at y = 100 (point 2 of 0, 50, ...). Exact up to the rotation's second order.
check cec 0 '^\$AN_CEC\[0,2\]=0\.0050$' -- "$DAQ" model compensate "$S" -f siemens-cec --interval-mm 50 50 50
check cec_axes 0 '^\$AN_CEC_INPUT_AXIS\[0\]=\(AX2\)$' -- "$DAQ" model compensate "$S" -f siemens-cec --interval-mm 50 50 50
check cec_residual 0 "10\.000 um before, 0\.000 um with the compensation" -- "$DAQ" model compensate "$S" -f siemens-cec --interval-mm 50 50 50 -o "$TMP/cec.mpf"
check linuxcnc 0 "written $TMP/lc/matrixkins.hal" -- "$DAQ" model compensate "$S" -f linuxcnc --interval-mm 50 50 50 --output-dir "$TMP/lc"
check matrixkins 0 "^setp matrixkins\.C_xy 0\.000050000000$" -- cat "$TMP/lc/matrixkins.hal"
check isg_volumetric 0 "^chain +YXZ$" -- sh -c "'$DAQ' model compensate '$Y' -f isg-volumetric --interval-mm 50 50 50 --output-dir '$TMP/vc' 2>/dev/null && cat '$TMP/vc/volcomp.lis'"
check isg_cross_refused 2 "use -f isg-volumetric" -- "$DAQ" model compensate "$Y" -f isg-cross --interval-mm 50 50 50 --output-dir "$TMP/ic"
check no_partial 1 "" -- test -e "$TMP/ic"
# --machine with a format daq verify cannot read back is refused before anything is written
# (it wrote the files, then refused).
check fanuc_machine 2 "a FANUC compensation is not stored for daq verify: FANUC's pitch error tables correct each axis along itself.*nothing was written" -- "$DAQ" model compensate "$Y" -f fanuc --interval-mm 50 50 50 -o "$TMP/f.txt" --machine M --db "$TMP/m.sqlite"
check fanuc_machine_no_file 1 "" -- test -e "$TMP/f.txt"
check no_machine 2 "no machine 'M' .*nothing was written" -- "$DAQ" model compensate "$Y" -f siemens-cec --interval-mm 50 50 50 -o "$TMP/nm.mpf" --machine M --db "$TMP/m.sqlite"
check no_machine_no_file 1 "" -- test -e "$TMP/nm.mpf"
check several_files 2 "give --output-dir" -- "$DAQ" model compensate "$Y" -f heidenhain --interval-mm 50 50 50
check bad_interval 2 "not a whole number of 30 mm intervals" -- "$DAQ" model compensate "$Y" -f csv --interval-mm 30 50 50
check compensate_report 0 "report written" -- "$DAQ" model compensate "$Y" -f siemens-cec --interval-mm 50 50 50 -o "$TMP/y.mpf" --report "$TMP/comp.html"
check compensate_report_after 0 "After compensation: SINUMERIK CEC" -- cat "$TMP/comp.html"
# The test piece of a machine with only E_C0Y = 50 urad: the faces are out of square by 50 um/m;
# CMM points of such a part (the Y faces leaning by -50e-6 y) measure the same.
T=(--origin-mm 100 100 -50 --tool-radius-mm 5)
check testpiece 0 "face\+Y / face\+X +squareness_um_per_m +50\.000" -- "$DAQ" model testpiece "$S" "${T[@]}"
check testpiece_cmm 0 "face-Y / face-X +squareness_um_per_m +50\.000 +50\.000 +0\.000" -- "$DAQ" model testpiece "$S" "${T[@]}" --cmm "$DATA/cmm_square50.csv"
check testpiece_json 0 '"schema": "caldaq.testpiece.v1"' -- "$DAQ" model testpiece "$S" "${T[@]}" --json
printf 'feature,x_mm,y_mm\nface+Z,0,0\n' > "$TMP/bad_cmm.csv"
check testpiece_bad_cmm 2 "bad_cmm.csv: feature 'face\+Z' is unknown" -- "$DAQ" model testpiece "$S" "${T[@]}" --cmm "$TMP/bad_cmm.csv"
check bad_carrier 2 "bad_carrier.json: squareness.E_B0Z.compensated_by: Y is not an axis of the XZ plane" -- "$DAQ" model show "$DATA/bad_carrier.json"
check missing_file 2 "nope.json: cannot open the model file" -- "$DAQ" model show "$TMP/nope.json"
# Issue 26: a model from runs not measured on real instruments says so at the top of every
# controller file that has comments, and a model from a mix names the errors that came from
# where; files without comments (HEIDENHAIN *.COM) are named in the output instead. The names
# in the provenance cannot break out of the comment (a line break in them becomes '?').
with_origin() {  # with_origin MODEL OUT PROVENANCE_JSON
  "$PY" -c 'import json,sys; m=json.load(open(sys.argv[1])); m["provenance"]=json.loads(sys.argv[3]); json.dump(m,open(sys.argv[2],"w"))' "$@"
}
with_origin "$S" "$TMP/mixed.json" '{"origin": "MIXED", "origins": {"E_C0Y": "SIMULATED", "E_XX": "REPLAYED"}}'
with_origin "$S" "$TMP/sim.json" '{"origin": "SIMULATED"}'
with_origin "$S" "$TMP/evil.json" '{"origin": "MIXED", "origins": {"E_C0Y\n$AA_ENC_COMP[0,0,AX1]=1": "SIMULATED\nM30"}}'
I=(--interval-mm 50 50 50)
"$DAQ" model compensate "$TMP/mixed.json" -f siemens-cec "${I[@]}" -o "$TMP/mixed.mpf" 2>"$TMP/mixed.err"
check mixed_cec 0 "^; MIXED data: do not load into a real control: some errors were not measured on the machine$" -- cat "$TMP/mixed.mpf"
check mixed_cec_name_first 0 "^%_N_NC_CEC_INI$" -- head -1 "$TMP/mixed.mpf"
check mixed_cec_parts 0 "^;   SIMULATED: E_C0Y$" -- cat "$TMP/mixed.mpf"
check mixed_cec_replayed 0 "^;   REPLAYED: E_XX$" -- cat "$TMP/mixed.mpf"
check mixed_output 0 "^  SIMULATED: E_C0Y$" -- cat "$TMP/mixed.err"
check mixed_json 0 '"E_C0Y": "SIMULATED"' -- "$DAQ" model compensate "$TMP/mixed.json" -f csv "${I[@]}" --json
# ISG's CSV parameter file comments with "//" ("#" is a file break there).
check isg_csv_origin 0 "^//   SIMULATED: E_C0Y$" -- sh -c "'$DAQ' model compensate '$TMP/mixed.json' -f isg-volumetric ${I[*]} --output-dir '$TMP/mvc' 2>/dev/null && cat '$TMP/mvc/volcomp.csv'"
check isg_lis_origin 0 "^# MIXED data: do not load into a real control" -- cat "$TMP/mvc/volcomp.lis"
check heidenhain_silent 0 "Y.COM, config.cma: the format has no comments, so the file does not say it" -- "$DAQ" model compensate "$TMP/mixed.json" -f heidenhain "${I[@]}" --output-dir "$TMP/mhh"
check sim_fanuc 0 "^SIMULATED data: do not load into a real control$" -- sh -c "'$DAQ' model compensate '$TMP/sim.json' -f fanuc ${I[*]} 2>/dev/null"
check sim_matrixkins 0 "^# SIMULATED data: do not load into a real control$" -- sh -c "'$DAQ' model compensate '$TMP/sim.json' -f linuxcnc ${I[*]} --output-dir '$TMP/mlc' 2>/dev/null && cat '$TMP/mlc/matrixkins.hal'"
check mixed_report 0 "<strong>MIXED</strong>: some errors of this model come from runs not measured on real instruments \(REPLAYED: E_XX; SIMULATED: E_C0Y\).*Do not load its compensation into a real control" -- sh -c "'$DAQ' model compensate '$TMP/mixed.json' -f siemens-cec ${I[*]} -o '$TMP/m2.mpf' --report '$TMP/mixed.html' 2>/dev/null && cat '$TMP/mixed.html'"
"$DAQ" model compensate "$TMP/evil.json" -f siemens-cec "${I[@]}" -o "$TMP/evil.mpf" 2>/dev/null
check evil_parts 0 "^;   SIMULATEDM: E_C0YAA_ENC_COMP$" -- cat "$TMP/evil.mpf"
check evil_no_line 1 "" -- grep -qE '^(\$AA_ENC_COMP\[0,0|M30)' "$TMP/evil.mpf"
finish
