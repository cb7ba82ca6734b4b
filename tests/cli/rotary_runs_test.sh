#!/usr/bin/env bash
# A rotary axis's angular positioning runs (ISO 230-2, kind rotary; issue 36) after they are
# stored: judged against the axis's limits in arcsec ([tolerances.C], docs/config.md) by daq run,
# show, analyse and report; compared over time (daq report --compare); and a run stored the old
# way (before a452795 its stops held the reference's angle, not the deviation) read right.
# Usage: rotary_runs_test.sh DAQ_BINARY
set -u
DAQ=$1
source "$(dirname "$0")/check.sh"
scratch_dir
DB=$TMP/rot.sqlite

# --- Limits in arcsec ----------------------------------------------------------------------
# The SIMULATED C axis has 6" of backlash (ShopTruth::Rotary): B_arcsec = 2 fails, E passes.
printf '[tolerances.C]\nE_arcsec = 30\nB_arcsec = 2\n' >"$TMP/tol.toml"
sim() {  # sim N: run N of the simulated rotary test, judged by tol.toml
  "$DAQ" sim --test rotary --runs 2 --acquire --json --tolerances "$TMP/tol.toml" \
    -o "$TMP/rot$1.toml" --db "$DB" >"$TMP/rot$1.json" 2>"$TMP/rot$1.log"
}
check sim_1 0 "" -- sim 1
check tol_in_config 0 '^\[tolerances\.C\]$' -- cat "$TMP/rot1.toml"
# daq run's verdict (it said "no tolerance configured"): E within, B outside, in arcsec.
check run_verdict 0 "^FAIL tolerances\.C E_bi pass arcsec B FAIL arcsec 2$" -- "$PY" -c "
import json; v=json.load(open('$TMP/rot1.json'))['verdict']
print(v['summary'], v['basis'], *[x for c in v['checks'] for x in (c['key'], 'pass' if c['pass'] else 'FAIL', c['unit'])], len(v['checks']))"
B=$("$PY" -c "import json; print(format(json.load(open('$TMP/rot1.json'))['axis']['B']['value'], '.3f'))")
check show_verdict 0 "verdict against tolerances\.C: FAIL" -- "$DAQ" show 1 --db "$DB"
check show_B 0 "^ +B +$B arcsec limit +2\.000 arcsec FAIL" -- "$DAQ" show 1 --db "$DB"
check analyse_B 0 "^ +B +$B arcsec limit +2\.000 arcsec FAIL" -- "$DAQ" analyse 1 --db "$DB"
check analyse_E 0 "^ +E +[0-9.]+ arcsec limit +30\.000 arcsec pass" -- "$DAQ" analyse 1 --db "$DB"
check show_json 0 '^FAIL$' -- "$PY" -c "
import json, subprocess; j=json.loads(subprocess.run(['$DAQ', 'show', '1', '--db', '$DB', '--json'], capture_output=True, text=True).stdout)
print(j['results'][0]['verdict']['summary'] if 'results' in j else j['verdict']['summary'])"
"$DAQ" report 1 --db "$DB" -o "$TMP/rot1.html" >/dev/null 2>&1
check_file "$TMP/rot1.html" <<'END'
report_verdict Verdict against the machine specification \(tolerances\.C\): <strong>FAIL</strong>
report_failing <li><strong>B</strong> = -?[0-9.]+ arcsec \(limit ≤ 2\.000 arcsec\): check the backlash compensation and the drive('|&#39;|&#x27;)s play</li>
report_limit_head limit&nbsp;\(arcsec\)
report_E_limit ≤ 30\.000
END
# Without limits, each output says where they would be given for this run: its axis's table in
# the configuration it was made with (daq show said "[tolerances] in the configuration" for
# every kind of run, daq run the same).
"$DAQ" sim --test rotary --runs 2 --acquire -o "$TMP/free.toml" --db "$TMP/free.sqlite" >"$TMP/free.out" 2>&1
FREE="verdict: no tolerance configured: no limit was stored with this run: E_arcsec, R_arcsec, A_arcsec, B_arcsec or M_arcsec under \[tolerances\.C\] in the configuration it was made with \(\S*free\.toml\) judge the runs made with it \(docs/config\.md\)$"
check free_run 0 "^$FREE" -- cat "$TMP/free.out"
check free_show 0 "^ +$FREE" -- "$DAQ" show 1 --db "$TMP/free.sqlite"
check free_analyse 0 "^$FREE" -- "$DAQ" analyse 1 --db "$TMP/free.sqlite"
"$DAQ" report 1 --db "$TMP/free.sqlite" -o "$TMP/free.html" >/dev/null 2>&1
check free_report 0 "No limit was stored with this run: <code>E_arcsec</code>, <code>R_arcsec</code>, <code>A_arcsec</code>, <code>B_arcsec</code> or <code>M_arcsec</code> under <code>\[tolerances\.C\]</code> in the configuration it was made with \(<span class=\"path\">\S*free\.toml</span>\)" -- cat "$TMP/free.html"

# A length limit on a rotary axis is refused at its line (a µm limit was never compared with
# arcsec, but it was not refused either: [tolerances.C] was not read at all).
{ cat "$TMP/rot1.toml"; printf '\n[tolerances.A]\nR_arcsec = 3\nE_um = 10\n'; } >"$TMP/bad.toml"
LINE=$(grep -n '^E_um = 10$' "$TMP/bad.toml" | cut -d: -f1)
check um_on_rotary 2 "bad\.toml:$LINE:[0-9]+: key 'tolerances\.A\.E_um': a rotary axis's limits are angles in arcsec" -- "$DAQ" run linear --config "$TMP/bad.toml" --db "$TMP/bad.sqlite"
printf '[tolerances.C]\nB_um = 3\n' >"$TMP/bad_tol.toml"
check um_in_sim_tolerances 2 "bad_tol\.toml:2:[0-9]+: key 'tolerances\.C\.B_um': a rotary axis's limits" -- "$DAQ" sim --test rotary --acquire --tolerances "$TMP/bad_tol.toml" -o "$TMP/x.toml" --db "$TMP/x.sqlite"
printf '[tolerances.X]\nE_um = 3\n' >"$TMP/linear_tol.toml"
check linear_in_sim_rotary 2 "--tolerances .*linear_tol\.toml: \[tolerances\.X\]: with --test rotary only a rotary axis's table" -- "$DAQ" sim --test rotary --acquire --tolerances "$TMP/linear_tol.toml" -o "$TMP/x.toml" --db "$TMP/x.sqlite"

# --- The report names the angular reference ------------------------------------------------
# The SIMULATED reference is an indexer's readout (reference = "encoder"): no refractive index.
check_file "$TMP/rot1.html" <<'END'
report_reference <p>Angular reference: <strong>angle</strong> \(gauge\), a reference encoder \(an indexer's readout\)\.</p>
report_reference_table <h4>Angular reference</h4>
report_index_not_applied Refractive index of the air</td><td>does not apply: a reference encoder \(an indexer's readout\) reads no wavelength in air
END
# A laser's angular optics (the run's settings say so): the laser named, the air's index given.
cp "$DB" "$TMP/laser.sqlite"
"$PY" - "$TMP/laser.sqlite" <<'PYEOF'
import json, sqlite3, sys
db = sqlite3.connect(sys.argv[1])
s = json.loads(db.execute("SELECT settings_json FROM runs WHERE id = 1").fetchone()[0])
s["measure"]["reference"] = "laser"
# A run made with a laser reference lists the laser (its angles arrive through the angle device;
# the laser, not opened, is what they are traceable to): the run here was made with the encoder.
s["context"]["instruments"].append({"calibration_due": "", "certificate": "", "driver": "ids3010",
                                    "id": "laser", "role": "laser", "serial_number": "SIM-IDS-0001",
                                    "transport": "tcp 127.0.0.1:1"})
db.execute("UPDATE runs SET settings_json = ? WHERE id = 1", (json.dumps(s),))
db.commit()
PYEOF
"$DAQ" report 1 --db "$TMP/laser.sqlite" -o "$TMP/laser.html" >/dev/null 2>&1
check_file "$TMP/laser.html" <<'END'
laser_reference <p>Angular reference: <strong>angle</strong> \(gauge\); the laser <strong>laser</strong> \(ids3010\), serial number SIM-IDS-0001, a laser's angular optics over a rotary indexer\.</p>
laser_index Refractive index of the air</td><td>1\.000[0-9]{5} \(ciddor, from the run's mean air temperature [0-9.]+ °C, pressure [0-9.]+ hPa, humidity [0-9.]+ %RH\)
END

# --- Rotary runs compared over time (it was refused) ---------------------------------------
check sim_2 0 "" -- sim 2
check compare 0 "" -- "$DAQ" report --compare 1 2 --db "$DB" -o "$TMP/cmp.html"
check_file "$TMP/cmp.html" <<'END'
cmp_title Comparison: rotary test of axis C
cmp_overlay aria-label="Mean bidirectional deviation, run by run"
cmp_small_E aria-label="E \(arcsec\)"
cmp_value_head <th>E \(arcsec\)</th>
cmp_B_trend B \(arcsec\) \(dashed: the limit\)
cmp_verdict <span class="fail">FAIL</span>
END
check cmp_no_um 1 "" -- grep -E "\((µm|mm)\)" "$TMP/cmp.html"
check cmp_json 0 '"kind": "comparison"' -- "$DAQ" report --compare 1 2 --db "$DB" -o "$TMP/cmp2.html" --json

# --- As found and as left: the SIMULATED control's correction of the C axis ---------------------
# Run 1 as found (the injected 10" per turn, 4" three times a turn, 6" of backlash, zero -3"); run
# 2 as left, with the control's backlash compensation (6") and scale correction (10"/turn) set
# from it. Expected from the injected errors alone (the deviation formula restated below, stops
# at 0 .. 360 deg every 45 deg): as found E = 19.0", B = 6.0"; as left only the cyclic error
# is left: E = 2 x 4" = 8.0" (its peaks at 90 and 270 deg), B = 0. The two runs share their noise
# seed, so the change is known closer than each value: within 0.3" (each value within 0.5": the
# stops' settling tail, tests/e2e/rotary_e2e_test.cpp).
AF=$TMP/af.sqlite
printf '[tolerances.C]\nE_arcsec = 12\nB_arcsec = 2\n' >"$TMP/af_tol.toml"
check af_found 0 "" -- "$DAQ" sim --test rotary --runs 2 --acquire --json --tolerances "$TMP/af_tol.toml" -o "$TMP/af1.toml" --db "$AF"
check af_left 0 "" -- "$DAQ" sim --test rotary --runs 2 --acquire --json --tolerances "$TMP/af_tol.toml" --control-backlash-arcsec 6 --control-scale-arcsec-per-turn 10 -o "$TMP/af2.toml" --db "$AF"
check af_report 0 "as-found-as-left report of runs 1, 2 written" -- "$DAQ" report --as-found 1 --as-left 2 --db "$AF" -o "$TMP/af.html"
check_file "$TMP/af.html" <<'END'
af_title <title>SIMULATED — As found and as left: rotary test of C</title>
af_verdict As found \(run 1\): <strong><span class="fail">FAIL</span></strong> &mdash; E = [0-9.]+ arcsec \(limit ≤ 12\.000 arcsec\); B = [0-9.]+ arcsec \(limit ≤ 2\.000 arcsec\)\.<br>As left \(run 2\): <strong><span class="pass">PASS</span></strong>
af_overlay aria-label="Mean bidirectional deviation, as found and as left"
af_as_found_body <h2 class="run" id="run-1">As found: .*Rotary positioning test
END
check af_no_um 1 "" -- grep -E "\((µm|mm)\)" "$TMP/af.html"
check af_values 0 "^ok$" -- "$PY" - "$TMP/af.html" <<'PYEOF'
import math, re, sys
h = open(sys.argv[1]).read()
def dev(t, up, scale, backlash):  # ShopTruth::Rotary: the reference's angle less the target
    half = 0.5 * backlash / 3600 * (-1 if up else 1)
    d = t + half
    return -3 + scale * d / 360 + 4 * math.sin(2 * math.pi * d / 120) + half * 3600
def expected(scale, backlash):
    up = [dev(t, True, scale, backlash) for t in range(0, 361, 45)]
    down = [dev(t, False, scale, backlash) for t in range(0, 361, 45)]
    return {"E": max(up + down) - min(up + down), "B": max(abs(a - b) for a, b in zip(up, down))}
found, left = expected(10, 6), expected(0, 0)  # 19.0, 6.0 and 8.0, 0.0
bad = []
for key, sym in (("E", "E"), ("B", "B")):
    m = re.search(r"<tr><td>%s \(arcsec\)</td><td class=\"r\">([-0-9.]+) .*?</td><td class=\"r\">([-0-9.]+) .*?</td><td class=\"r\">([-+0-9.]+)</td>" % sym, h)
    if not m:
        bad.append("no row " + sym); continue
    f, l, c = map(float, m.groups())
    if abs(f - found[key]) > 0.5 or abs(l - left[key]) > 0.5 or abs(c - (left[key] - found[key])) > 0.3:
        bad.append(f"{sym}: {f} -> {l} ({c}) vs {found[key]:.3f} -> {left[key]:.3f}")
print("ok" if not bad else bad)
PYEOF
check af_json 0 '"kind": "as-found-as-left"' -- "$DAQ" report --as-found 1 --as-left 2 --db "$AF" -o "$TMP/af2.html" --json
check af_over_compensated 2 "--control-backlash-arcsec 7: more than the SIMULATED C axis's backlash \(6\"\)" -- "$DAQ" sim --test rotary --acquire --control-backlash-arcsec 7 -o "$TMP/x.toml" --db "$TMP/x2.sqlite"
check af_correction_not_rotary 2 "--control-backlash-arcsec and --control-scale-arcsec-per-turn correct the SIMULATED rotary axis" -- "$DAQ" sim --test linear --acquire --control-scale-arcsec-per-turn 1 -o "$TMP/x.toml" --db "$TMP/x3.sqlite"
check af_other_kind 2 "run 1 is a rotary test of C, run 3 a linear test of X" -- bash -c "'$DAQ' sim --test linear --runs 2 --targets 3 --acquire -o '$TMP/lin.toml' --db '$AF' >/dev/null 2>&1; '$DAQ' report --as-found 1 --as-left 3 --db '$AF' -o '$TMP/x.html'"

# --- A run stored the old way: each stop's reference angle, not its deviation ---------------
# Before a452795 a rotary stop stored the reference's continuous angle (arcsec) where it now
# stores the angle minus the target (modulo a turn). Made here from run 1: each stop's angle,
# its deviation plus its target, as the old code stored it.
cp "$DB" "$TMP/old.sqlite"
"$PY" - "$TMP/old.sqlite" <<'PYEOF'
import sqlite3, sys
db = sqlite3.connect(sys.argv[1])
db.execute("UPDATE captured_targets SET deviation_um = deviation_um + nominal_mm * 3600 "
           "WHERE run_id = 1")
db.commit()
PYEOF
check old_is_angles 0 "^ok$" -- "$PY" -c "
import sqlite3; d=[r[0] for r in sqlite3.connect('$TMP/old.sqlite').execute('SELECT deviation_um FROM captured_targets WHERE run_id = 1 AND nominal_mm = 45')]
print('ok' if d and all(abs(x - 162000) < 30 for x in d) else d)"
# daq analyse evaluates the stops again: the numbers the run stored, with a note naming the run
# (it gave the angles modulo a turn as deviations: B of tens of thousands of arcsec).
check old_analyse_B 0 "^ +B +$B arcsec +reversal value" -- "$DAQ" analyse 1 --db "$TMP/old.sqlite"
check old_analyse_note 0 "warning: run 1 was stored before a452795 \(2026-11-28\): its stops hold the angular reference's angle, not the deviation; read as the angle minus the target" -- "$DAQ" analyse 1 --db "$TMP/old.sqlite"
"$DAQ" analyse 1 --db "$DB" --json >"$TMP/new-analyse.json" 2>/dev/null
"$DAQ" analyse 1 --db "$TMP/old.sqlite" --json >"$TMP/old-analyse.json" 2>/dev/null
check old_analyse_same 0 "^same$" -- "$PY" -c "
import json; a=json.load(open('$TMP/new-analyse.json')); b=json.load(open('$TMP/old-analyse.json'))
same = all(abs(a['axis'][k]['value'] - b['axis'][k]['value']) < 1e-6 for k in a['axis'])
print('same' if same and len(a['targets']) == len(b['targets']) else 'differ')"
check old_export_row 0 "^45,1,up,-?[0-9]{1,2}\.[0-9]+,2," -- "$DAQ" export 1 --db "$TMP/old.sqlite" --format csv --what targets
check old_export_note 0 "note: run 1 was stored before a452795" -- "$DAQ" export 1 --db "$TMP/old.sqlite" --format csv --what targets -o "$TMP/old.csv"
"$DAQ" export 1 --db "$TMP/old.sqlite" --format json -o "$TMP/old-export.json" >/dev/null 2>&1
check old_export_json 0 "^ok$" -- "$PY" -c "
import json; d=json.load(open('$TMP/old-export.json'))
print('ok' if all(abs(t['deviation_arcsec']) < 30 for t in d['targets']) and 'a452795' in d['notes'][0] else 'bad')"
"$DAQ" report 1 --db "$TMP/old.sqlite" -o "$TMP/old.html" >/dev/null 2>&1
check old_report_note 0 "Warning: run 1 was stored before a452795" -- cat "$TMP/old.html"
check old_report_B 0 "^ok$" -- "$PY" -c "
import re; h=open('$TMP/old.html').read()
print('ok' if re.search(r'reversal value, max \|B<sub>i</sub>\|</td>(<td[^>]*>.*?</td>){2}<td class=.r.>$B</td>', h) else 'no B $B')"
# Half of its stops stored as angles, half as deviations: neither reading is right, refused.
cp "$DB" "$TMP/mixed.sqlite"
"$PY" - "$TMP/mixed.sqlite" <<'PYEOF'
import math, sqlite3, sys
db = sqlite3.connect(sys.argv[1])
db.execute("UPDATE captured_targets SET deviation_um = deviation_um + nominal_mm * 3600 "
           "WHERE run_id = 1 AND run_number = 1")
db.commit()
PYEOF
check mixed_refused 2 "run 1 \(rotary\): of its stops 1 deg or more from 0 deg, [0-9]+ hold a value near their target's angle .* and [0-9]+ a value near 0 \(a deviation\): it cannot be read either way" -- "$DAQ" analyse 1 --db "$TMP/mixed.sqlite"

finish
