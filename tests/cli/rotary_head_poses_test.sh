#!/usr/bin/env bash
# Sphere probing of a head (spindle-side) rotary axis on the command line (issue 36): the
# simulated C-table / B-head machine with injected location errors (head_truth.json), its B head
# probed by the simulated touch probe (the control reports where its kinematics puts the turned
# probe tip), the fit of the B line against the injected truth, the simulated control corrected
# with the fit, probed again: the residual before and after. docs/five-axis-walkthrough.md,
# section 8.
# Usage: rotary_head_test.sh DAQ_BINARY DATA_DIR (tests/data/model)
set -u
DAQ=$1
DATA=$2
source "$(dirname "$0")/check.sh"
scratch_dir
TRUTH=$DATA/head_truth.json
NOM=$DATA/head_nominal.json
S="120 40 -300"
B="-90 -75 -60 -45 -30 -15 0 15 30 45 60 75 90"
# probe SEED CONTROL OUT: B at 13 angles, noise 1 um per coordinate, reported by CONTROL.
probe() {
  "$DAQ" model probe-sim "$TRUTH" --control "$2" --axis B --sphere-mm $S --noise-um 1 \
    --seed "$1" --angles-deg $B -o "$3" 2>/dev/null
}
check probe_sim 0 "" -- probe 1 "$NOM" "$TMP/b1.csv"
# At B = 90 the control's tip is off by the first-order Delta = (E_X0B - E_Z0B, -L (E_A0B +
# E_C0B), E_Z0B + E_X0B) = (35, -1.25, 5) um (L = 250 mm): the centre is S - Delta, within the
# noise (1 um).
check probe_sim_row 0 "^B,90,119\.96[0-9]+,(40\.00|39\.99)[0-9]+,-300\.00[0-9]+$" -- cat "$TMP/b1.csv"
check before 0 "largest deviation (3[0-9]|4[0-9])\.[0-9]+ um" -- "$DAQ" model probe-check "$TMP/b1.csv" --model "$NOM"
check fit 0 "Axis B \(spindle side\): 13 probed centres" -- "$DAQ" model probe "$TMP/b1.csv" --model "$NOM" --write "$TMP/fitted.json"
# The sphere within 2 um of where it was put (its u is 0.3 to 0.4 um).
check fit_sphere 0 "sphere at \((119\.99[89]|120\.00[01])[0-9], (39\.99[89]|40\.00[01])[0-9], -(299\.99[89]|300\.00[01])[0-9]\) mm" -- "$DAQ" model probe "$TMP/b1.csv" --model "$NOM"
# Tolerance: every fitted value within 4 u of the injected one (u from the residuals; by hand
# for sigma = 1 um: 0.34 um, 3.2 and 1.5 urad, tests/analysis/rotary_head_test.cpp).
"$DAQ" model probe "$TMP/b1.csv" --model "$NOM" --json >"$TMP/fit.json" 2>/dev/null
check fit_within_4u 0 "^ok 4$" -- "$PY" - "$TMP/fit.json" <<'PYEOF'
import json, sys
fit = json.load(open(sys.argv[1]))
truth = {"E_X0B": 20, "E_Z0B": -15, "E_A0B": 12, "E_C0B": -7}
bad, n = [], 0
for axis in fit["axes"]:
    for name, v in axis["location"].items():
        n += 1
        if abs(v["value"] - truth[name]) > 4 * v["uncertainty"]:
            bad.append(f"{name} {v['value']:.3f} +- {v['uncertainty']:.3f} vs {truth[name]}")
print(f"ok {n}" if not bad else "; ".join(bad))
PYEOF
check fit_side 0 '"side": "spindle"' -- cat "$TMP/fit.json"
check fitted_model 0 '"E_X0B": \{' -- cat "$TMP/fitted.json"
# The simulated control corrected: it holds the fitted B line (position and orientation) as its
# kinematics and reports the centres where that puts the tip. Probed again (seed 2): what is left
# is the probe's noise (each deviation holds two centres' noise, the sphere's place being the 0
# deg centre: |d| about sqrt(6) = 2.4 um, the largest of 12 up to about 5) and the fit's u.
check probe_again 0 "" -- probe 2 "$TMP/fitted.json" "$TMP/b2.csv"
check after 0 "largest deviation [0-5]\.[0-9]+ um" -- "$DAQ" model probe-check "$TMP/b2.csv" --model "$TMP/fitted.json"
# Refused: the linear axes' raw positions instead of the control's tip; a fit without a model.
"$PY" - "$TMP/b1.csv" "$TMP/raw.csv" <<'PYEOF'
import math, sys
out = open(sys.argv[2], "w")
for line in open(sys.argv[1]):
    if line.startswith("#") or line.startswith("axis"):
        out.write(line); continue
    a, deg, x, y, z = line.strip().split(",")
    t = math.radians(float(deg))  # the tip 250 mm below the pivot turned about Y, less the offset
    out.write(f"{a},{deg},{float(x) + 250 * math.sin(t):.6f},{y},{float(z) + 250 * math.cos(t) - 250:.6f}\n")
PYEOF
check raw_refused 2 "raw.csv: the B axis's 13 centres .*raw positions" -- "$DAQ" model probe "$TMP/raw.csv" --model "$NOM"
check head_needs_model 2 "give --model" -- "$DAQ" model probe "$TMP/b1.csv"
check sim_other_chain 2 "different rotary axes" -- "$DAQ" model probe-sim "$TRUTH" --control "$DATA/trunnion_nominal.json" --axis B --sphere-mm $S --angles-deg 0 90

# --- Two rotary axes at once: the trunnion's C and A turned together in one program ------------
# C at 0, 60, ..., 300 times A at -60, 0, 60 (18 poses), the sphere at (150, 100, -250) on the C
# table, 1 um of noise. Both axes' eight location errors and the offset of the A line from the C
# line fitted together (tests/analysis/rotary_poses_test.cpp checks u against the truth over 8
# seeds); here each within 4 u of the injected truth. The offset by hand: the C line at the A
# pivot's height (50 mm above its own) is at y = E_Y0C - 50 mm E_A0C = -18.5 um, the A line at
# E_Y0A = 30 um: 48.5 um (second order: below 1e-3 um).
TT=$DATA/trunnion_truth.json
TN=$DATA/trunnion_nominal.json
{ echo "c_deg,a_deg"; for c in 0 60 120 180 240 300; do for a in -60 0 60; do echo "$c,$a"; done; done; } >"$TMP/poses.csv"
check poses_sim 0 "" -- "$DAQ" model probe-poses-sim "$TT" --poses "$TMP/poses.csv" --sphere-mm 150 100 -250 --noise-um 1 --seed 1 -o "$TMP/p1.csv"
check poses_sim_row 0 "^60,60,[0-9.-]+,[0-9.-]+,[0-9.-]+$" -- cat "$TMP/p1.csv"
check poses_fit 0 "Axes C, A fitted together from 18 probed poses" -- "$DAQ" model probe-poses "$TMP/p1.csv" --model "$TN" --write "$TMP/fitted_ca.json"
"$DAQ" model probe-poses "$TMP/p1.csv" --model "$TN" --json >"$TMP/pfit.json" 2>/dev/null
check poses_within_4u 0 "^ok 8 1$" -- "$PY" - "$TMP/pfit.json" <<'PYEOF'
import json, sys
fit = json.load(open(sys.argv[1]))
truth = {"E_X0C": 25, "E_Y0C": -18, "E_A0C": 10, "E_B0C": -6,
         "E_Y0A": 30, "E_Z0A": -22, "E_B0A": 8, "E_C0A": -5}
bad, n = [], 0
for axis in fit["axes"]:
    for name, v in axis["location"].items():
        n += 1
        if abs(v["value"] - truth[name]) > 4 * v["uncertainty"]:
            bad.append(f"{name} {v['value']:.3f} +- {v['uncertainty']:.3f} vs {truth[name]}")
offs = fit["line_offsets"]
for o in offs:
    if abs(o["offset_mm"] * 1e3 - 48.5) > 4 * o["u_um"]:
        bad.append(f"offset {o['offset_mm']} +- {o['u_um']} um vs 48.5 um")
print(f"ok {n} {len(offs)}" if not bad else "; ".join(bad))
PYEOF
check poses_written 0 '"kind": *"sphere probing, axes fitted together"|sphere probing, axes fitted together' -- cat "$TMP/fitted_ca.json"
# The simulated control given the jointly fitted lines (position and orientation), probed
# again axis by axis (C at 12 angles, A at 7, seeds 2 and 102, as in cli_rotary): the centres
# against it are off by the noise only (against the nominal kinematics: 61.6 and 56.5 um).
"$DAQ" model probe-sim "$TT" --axis C --sphere-mm 150 100 -250 --noise-um 1 --seed 2 \
  --angles-deg 0 30 60 90 120 150 180 210 240 270 300 330 -o "$TMP/c2.csv" 2>/dev/null
"$DAQ" model probe-sim "$TT" --axis A --sphere-mm 150 100 -250 --noise-um 1 --seed 102 \
  --angles-deg -90 -60 -30 0 30 60 90 -o "$TMP/a2.csv" 2>/dev/null
{ cat "$TMP/c2.csv"; grep -v '^axis\|^#' "$TMP/a2.csv"; } >"$TMP/ca2.csv"
check poses_before 0 "largest deviation [4-9][0-9]\.[0-9]+ um" -- "$DAQ" model probe-check "$TMP/ca2.csv" --model "$TN"
after_ok() {  # "ok" when both axes' largest deviation is below 5 um
  "$DAQ" model probe-check "$TMP/ca2.csv" --model "$TMP/fitted_ca.json" |
    awk '/largest deviation/ { if ($3 + 0 > 5) bad = 1; n++ } END { print (n == 2 && !bad) ? "ok" : "bad" }'
}
check poses_after 0 "^ok$" -- after_ok
# A never turning: its errors cannot be fitted, but C alone can.
{ echo "c_deg,a_deg"; for c in 0 60 120 180 240 300; do echo "$c,0"; done; } >"$TMP/c_only.csv"
"$DAQ" model probe-poses-sim "$TT" --poses "$TMP/c_only.csv" --sphere-mm 150 100 -250 -o "$TMP/pc.csv" 2>/dev/null
check poses_c_only 0 "Axes C fitted together from 6 probed poses" -- "$DAQ" model probe-poses "$TMP/pc.csv" --model "$TN"
printf 'c_deg,x_mm,y_mm,z_mm\n0,1,2,3\n' >"$TMP/no_a.csv"
check poses_missing_column 2 "no_a.csv.*a_deg" -- "$DAQ" model probe-poses "$TMP/no_a.csv" --model "$TN"
{ echo "c_deg,a_deg,x_mm,y_mm,z_mm"; for c in 0 0 0 0 0; do echo "$c,0,1,2,3"; done; } >"$TMP/still.csv"
check poses_none_turns 2 "still.csv: no rotary axis turns in its 5 poses" -- "$DAQ" model probe-poses "$TMP/still.csv" --model "$TN"

finish
