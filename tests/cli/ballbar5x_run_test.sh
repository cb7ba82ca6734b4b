#!/usr/bin/env bash
# The five-axis ballbar as a run (issue 36): the simulated trunnion (tests/data/model/
# trunnion_truth.json, injected location errors) runs the control's ISO 10791-6-style program
# for C and A in three set-ups each, the ballbar's gauge twin streams at 100 Hz with 0.5 um of
# noise per sample, the gauge driver reads it, the run is stored (kind ballbar5x) and fitted.
# Then the verification loop: the fit written as LinuxCNC pins and as the SINUMERIK record, the
# simulated control takes each, the ballbar run again shows what each left.
# Usage: ballbar5x_run_test.sh DAQ_BINARY DATA_DIR (tests/data/model)
set -u
DAQ=$1
DATA=$2
source "$(dirname "$0")/check.sh"
scratch_dir
TRUTH=$DATA/trunnion_truth.json
NOM=$DATA/trunnion_nominal.json
DB=$TMP/bb.sqlite
BALL="150 0 -250"
# Each test's bar zero (the bar's length calibration and set-up): C radial, tangential, axial,
# A radial, tangential, axial.
OFFSETS="2 -1 1.5 -2 0.5 1"
run() {  # run SEED CONTROL [options...]: the six tests as one stored run, its result as JSON
  local seed=$1 control=$2
  shift 2
  "$DAQ" model ballbar5x-run "$TRUTH" --control "$control" --db "$DB" --ball-mm $BALL \
    --noise-um 0.5 --offsets-um $OFFSETS --seed "$seed" --json "$@"
}
run 1 "$NOM" --write "$TMP/fitted.json" >"$TMP/r1.json" 2>"$TMP/r1.log"
check run 0 '"schema": "caldaq.ballbar5x.v1"' -- cat "$TMP/r1.json"
check run_events 0 "test C-axial: feed-in found, reading its 12 stops" -- cat "$TMP/r1.log"
# Tolerances (docs/five-axis-walkthrough.md, section 7): every value within 4 u (k = 1) of the
# injected one, u from the fit's residuals. A stop is the mean of 125 samples (1.25 s of its 2 s
# dwell at 100 Hz), so its noise is 0.5 / sqrt(125) = 0.045 um: the fit's sigma must come out
# near it (0.03 to 0.07 um), and u small enough that 4 u is a real check (positions <= 0.2 um,
# tilts <= 1.2 urad; by the sensitivities h (1 - cos) and h sin of kinematics.md over 100 to
# 150 mm). After a correction ("zero", "tilts") u is the two runs' combined (the correction
# carries the first fit's error, the second run adds its own).
# mode "truth": against the injected; "zero": every `left` within 4 u of 0; "tilts": positions
# left within 4 u of 0, tilts left within 4 u of the injected (LinuxCNC's pins carry no tilt).
within() {
  "$PY" - "$@" <<'PYEOF'
import json, math, sys
doc = json.load(open(sys.argv[1]))["result"]
mode = sys.argv[2]
first = {}
if len(sys.argv) > 3:
    first = {n: v["uncertainty"] for a in json.load(open(sys.argv[3]))["result"]["axes"]
             for n, v in a["location"].items()}
truth = {"E_X0C": 25, "E_Y0C": -18, "E_A0C": 10, "E_B0C": -6,
         "E_Y0A": 30, "E_Z0A": -22, "E_B0A": 8, "E_C0A": -5}
tilts = {"E_A0C", "E_B0C", "E_B0A", "E_C0A"}
bad, seen, worst = [], 0, 0.0
for a in doc["axes"]:
    if not 0.03 <= a["sigma_um"] <= 0.07:
        bad.append(f"axis {a['axis']}: sigma {a['sigma_um']:.4f} um")
    for n, v in a["location"].items():
        seen += 1
        u = math.hypot(v["uncertainty"], first.get(n, 0.0))
        if mode == "truth":
            got, want = v["value"], truth[n]
        elif mode == "zero":
            got, want = v["left"], 0.0
        else:
            got, want = v["left"], truth[n] if n in tilts else 0.0
        worst = max(worst, abs(got - want) / u)
        if abs(got - want) > 4 * u or v["uncertainty"] > (1.2 if n in tilts else 0.2):
            bad.append(f"{n} {got:.4f} +- {u:.4f} vs {want:.3f}")
print("ok" if seen == 8 and not bad else "; ".join(bad) or "errors missing")
print(f"worst {worst:.2f} u")
PYEOF
}
check fit_within_4u 0 "^ok$" -- within "$TMP/r1.json" truth
# The run is stored as a run like the others: listed, shown with its fitted values and its raw
# readings (the gauge driver's stream: at 100 Hz, over 200 s of program).
check runs_list 0 "ballbar5x +CA +complete +[0-9]{5,}" -- "$DAQ" runs --db "$DB"
check show 0 "E_X0C +\+2[45]\.[0-9]{3} um +location error of the C axis, u = 0\.[0-9]{3}" -- "$DAQ" show 1 --db "$DB"
check show_kind 0 "^run 1: ballbar5x CA \(complete\)" -- "$DAQ" show 1 --db "$DB"
# No limit: where they are given for this run, a file given to --tolerances (daq show said
# "[tolerances] in the configuration", which a run of daq model ballbar5x-run does not have).
check show_no_tolerance 0 "^ +verdict: no tolerance configured: no limit was stored with this run: location_um \(each position\) and location_urad \(each tilt\) under \[tolerances\.C\] and \[tolerances\.A\] in a file given to daq model ballbar5x-run --tolerances judge what the control's kinematics leave of each location error \(docs/config\.md\)$" -- "$DAQ" show 1 --db "$DB"
check show_device 0 "device [0-9]+: ballbar on ballbar \(serial /dev/pts/[0-9]+ 115200 8N1\)" -- "$DAQ" show 1 --db "$DB"
# The report (docs/reports.md): its numbers are daq show --json's (the stored result), each
# within 0.0005 of its unit (printed to 0.001); the tests as run (six: C then A, each radial,
# tangential, axial, the ball and bar given above, 12 and 13 stops), each test's fitted bar zero
# within 4 u of the one injected (OFFSETS: the gauge twin's, not caldaq's); a plot per test and
# one of the bar's stream; no tolerance configured, and the keys that would judge it.
"$DAQ" show 1 --db "$DB" --json >"$TMP/show1.json"
check report 0 "run report of run 1 written to" -- "$DAQ" report 1 --db "$DB" -o "$TMP/r1.html"
report_vs_show() {  # report_vs_show REPORT.html SHOW.json READINGS COLUMNS: "ok" or what differs
  "$PY" - "$1" "$2" "$3" "$OFFSETS" "$4" <<'PYEOF'
import html, json, re, sys
page = open(sys.argv[1], encoding="utf-8").read()
show = json.load(open(sys.argv[2]))
readings, offsets = int(sys.argv[3]), [float(x) for x in sys.argv[4].split()]
def rows(cls):
    t = re.search(r'<table class="' + cls + r'">(.*?)</table>', page, re.S)
    if not t:
        return []
    return [[html.unescape(re.sub(r"<[^>]+>", "", c)).strip() for c in
             re.findall(r"<td[^>]*>(.*?)</td>", r, re.S)]
            for r in re.findall(r"<tr>(.*?)</tr>", t.group(1), re.S) if "<td" in r]
bad = []
result = [r for r in show["results"] if r["current"]][0]["result"]
want = {n: v for a in result["axes"] for n, v in a["location"].items()}
got = rows("num results location")
names = [r[0] for r in got]
if names != ["E_X0C", "E_Y0C", "E_A0C", "E_B0C", "E_Y0A", "E_Z0A", "E_B0A", "E_C0A"]:
    bad.append(f"errors in the order tested: {names}")
for r in got:
    v = want.get(r[0], {})
    unit = {"um": "µm", "urad": "µrad"}.get(v.get("unit"))
    if not v or abs(float(r[1]) - v["value"]) > 0.0005 + 1e-9 or abs(
            float(r[2]) - v["uncertainty"]) > 0.0005 + 1e-9 or r[3] != unit:
        bad.append(f"{r[0]}: report {r[1:4]}, daq show {v}")
    # Against a control holding location errors: what it held and what is left, as daq show.
    if len(r) == 9 and v and (abs(float(r[5]) - v["control"]) > 0.0005 + 1e-9 or
                              abs(float(r[6]) - v["left"]) > 0.0005 + 1e-9):
        bad.append(f"{r[0]}: report control/left {r[5:7]}, daq show {v}")
if len(got) and len(got[0]) != int(sys.argv[5]):
    bad.append(f"{len(got[0])} columns")
tests = rows("num tests")
setups = [(r[0], r[1], r[2], r[3], r[4], r[6]) for r in tests]
expect = [(f"{a}-{s}", a, s, "(150, 0, -250)", "100", n)
          for a, n in (("C", "12"), ("A", "13")) for s in ("radial", "tangential", "axial")]
if setups != expect:
    bad.append(f"tests {setups}")
for r, injected in zip(tests, offsets):
    offset, u = (float(x) for x in r[7].split("±"))
    if abs(offset - injected) > 4 * u:
        bad.append(f"{r[0]}: bar offset {r[7]} against {injected} injected")
plots = re.findall(r'<figcaption>([^<]*): the bar&#39;s deviation against the ([ACB]) angle', page)
if [p[0] for p in plots] != [e[0] for e in expect]:
    bad.append(f"plots {plots}")
if f"<p>{readings} readings stored.</p>" not in page:
    bad.append(f"readings count: {readings} not stated")
print("ok" if not bad else "; ".join(bad))
PYEOF
}
READINGS=$("$PY" -c 'import json,sys; print(json.load(open(sys.argv[1]))["readings"])' "$TMP/r1.json")
check report_as_show 0 "^ok$" -- report_vs_show "$TMP/r1.html" "$TMP/show1.json" "$READINGS" 7
check report_no_tolerance 0 "<strong>No tolerance configured</strong>.*<code>location_um</code>.*<code>\[tolerances.C\]</code> and <code>\[tolerances.A\]</code>" -- cat "$TMP/r1.html"
# Its Instruments table: the bar is a simulated twin, said where its model and serial number go
# (the cell was blank, as if missing).
check report_instrument_row 0 "<h4>Instruments</h4>.*<tr><td>ballbar</td><td><span class=\"unstated\">none: a simulated twin</span></td><td>ballbar \(serial /dev/pts/" -- "$PY" -c "import sys; print(open(sys.argv[1], encoding='utf-8').read().replace(chr(10), ' '))" "$TMP/r1.html"
check report_title 0 "<h1>SIMULATED — Run 1: Five-axis ballbar test \(rotary axes&#39;? location errors\), axes C and A</h1>" -- cat "$TMP/r1.html"
check report_draft 0 "DRAFT — NOT APPROVED</strong>: result [0-9]+ has not been approved" -- cat "$TMP/r1.html"
check report_dialect 0 "Program dialect: <span class=\"unstated\">none: the simulated control ran the program" -- cat "$TMP/r1.html"
# Made without a configuration, on a simulated bar: the report says which twin measured and that
# it has no calibration to trace, on page one and under Instruments; not the advice for a
# configured run ("give serial_number ... in the configuration", a file this run never had).
TWIN="a twin of a ballbar on the simulated five-axis machine of daq model ballbar5x-run"
check report_trace_simulated 0 "<p class=\"warning\">Traceability: the ballbar is simulated \($TWIN\): a simulated instrument has no serial number, certificate or calibration due date\.</p>" -- cat "$TMP/r1.html"
check report_instruments_simulated 0 "<h3>Instruments and calibration</h3>.<p class=\"unstated\">The ballbar is simulated \($TWIN\): a simulated" -- tr '\n' ' ' <"$TMP/r1.html"
check report_origin_twin 0 "Origin of the readings</td><td>ballbar simulated \($TWIN\)</td>" -- cat "$TMP/r1.html"
check show_origin_twin 0 "^  SIMULATED: ballbar simulated \($TWIN\)$" -- "$DAQ" show 1 --db "$DB"
check report_no_config_advice 1 "^0$" -- grep -c "give serial_number" "$TMP/r1.html"
# The readings plot's legend names the bar once: "ballbar", not "ballbar ballbar" (the texts of
# an SVG figure are PLplot's tspans, one character entity each).
readings_legend() {
  "$PY" - "$1" <<'PYEOF'
import html, re, sys
page = open(sys.argv[1], encoding="utf-8").read()
svg = re.search(r'<svg class="plot"[^>]*aria-label="ballbar length \(mm\)".*?</svg>', page, re.S)
texts = [html.unescape(t) for t in re.findall(r"<tspan[^>]*>(.*?)</tspan>", svg.group(0))] if svg else []
print("ok" if texts.count("ballbar") == 1 and not any("ballbar ballbar" in t for t in texts)
      else f"legend texts {texts[-4:]}")
PYEOF
}
check report_legend_once 0 "^ok$" -- readings_legend "$TMP/r1.html"
check report_offsets_injected 0 "Bar zeros injected</td><td>2, -1, 1.5, -2, 0.5, 1 µm</td>" -- cat "$TMP/r1.html"
check fitted_model 0 '"kind": "ballbar, rotary axis"' -- cat "$TMP/fitted.json"
# The correction written for each control, taken by the simulated control, measured again.
"$DAQ" model kinematics "$TMP/fitted.json" -o "$TMP/trt.hal" >/dev/null 2>&1
"$DAQ" model kinematics "$TMP/fitted.json" -f sinumerik-cycle800 -o "$TMP/swivel.mpf" >/dev/null 2>&1
check hal_written 0 "setp xyzac-trt-kins.x-rot-point 0\.02[45]" -- cat "$TMP/trt.hal"
# A specification of what the control may leave (docs/config.md): 1 um of each position, 3 urad of
# each tilt. The LinuxCNC pins hold no tilt: the run after them fails on exactly the four tilts
# (injected 10, -6, 8, -5 urad, none corrected), the SINUMERIK record's passes.
printf '[tolerances.C]\nlocation_um = 1\nlocation_urad = 3\n[tolerances.A]\nlocation_um = 1\nlocation_urad = 3\n' >"$TMP/tol.toml"
run 2 "$NOM" --swivel "$TMP/swivel.mpf" --tolerances "$TMP/tol.toml" >"$TMP/r2s.json" 2>/dev/null
run 3 "$NOM" --hal "$TMP/trt.hal" --tolerances "$TMP/tol.toml" >"$TMP/r2h.json" 2>/dev/null
verdict() {  # verdict RUN: the summary and the failing checks of daq show --json
  "$DAQ" show "$1" --db "$DB" --json | "$PY" -c '
import json, sys
r = [x for x in json.load(sys.stdin)["results"] if x["current"]][0]["verdict"]
print(r["summary"], len(r["checks"]), " ".join(sorted(c["key"] for c in r["checks"] if not c["pass"])))'
}
check verdict_swivel_pass 0 "^PASS 8 $" -- verdict 2
check verdict_hal_tilts_fail 0 "^FAIL 8 E_A0C E_B0A E_B0C E_C0A$" -- verdict 3
# The limits' file is stored with the run and named as the verdict's basis (it said
# "tolerances.C, tolerances.A", as if from a configuration the run does not have).
check show_basis_file 0 "^ +verdict against tolerances\.C, tolerances\.A in \S*/tol\.toml \(--tolerances\): PASS$" -- "$DAQ" show 2 --db "$DB"
"$DAQ" report 3 --db "$DB" -o "$TMP/r3.html" >/dev/null 2>&1
check report_fail 0 "<strong>FAIL</strong> &mdash; 4 of 8 limited values outside their limits" -- cat "$TMP/r3.html"
check report_basis_file 0 "Verdict against the machine specification \(tolerances\.C, tolerances\.A in \S*/tol\.toml \(--tolerances\)\)" -- cat "$TMP/r3.html"
check report_failing_value 0 "<li><strong>E_B0C</strong> = -[56]\.[0-9]{3} µrad \(limit ≤ 3\.000 µrad\): correct the axis&#39;s tilt in the control&#39;s kinematics</li>" -- cat "$TMP/r3.html"
# Printed on A4 by Chromium: page one holds the failing verdict, the location errors and the
# whole table of the tests; printed at full size (the appendix's raw list of the tests, a line
# too wide, once shrank every page to fit) and no word past the right margin.
"$DAQ" report 3 --db "$DB" -f pdf -o "$TMP/r3.pdf" >/dev/null 2>&1
printed_a4() {
  "$PY" - "$1" "$(dirname "$0")" <<'PYEOF'
import sys
sys.path.insert(0, sys.argv[2])
from report_checks import MM, pdf_words
pages = pdf_words(sys.argv[1])
words, _ = pages[0]
one = " ".join(w[4] for w in words)
bad = [k for k in ("FAIL", "E_X0C", "E_C0A", "C-radial", "A-axial", "(150, 0, -250)") if k not in one]
title = words[0][3] - words[0][1]
if title < 16:  # 14 pt type: 16.3 pt at full size, 15.3 when the appendix shrank the page
    bad.append(f"title {title:.1f} pt high: the page was shrunk")
wide = [w[4] for ws, _ in pages for w in ws if w[2] > (210 - 14) * MM + 1]
if wide:
    bad.append(f"past the right margin: {wide[:5]}")
print("ok" if not bad else "; ".join(bad))
PYEOF
}
check printed_a4 0 "^ok$" -- printed_a4 "$TMP/r3.pdf"
printf '[tolerances.C]\nE_arcsec = 12\n' >"$TMP/tol-none.toml"
check tolerances_none 2 "no location_um or location_urad in \[tolerances.C\] or \[tolerances.A\]" -- "$DAQ" model ballbar5x-run "$TRUTH" --control "$NOM" --db "$DB" --ball-mm $BALL --tolerances "$TMP/tol-none.toml"
printf '[tolerances.X]\nlocation_um = 5\n' >"$TMP/tol-x.toml"
check tolerances_linear_axis 2 "tol-x.toml:2:.*arcsec and location limits are a rotary axis" -- "$DAQ" model ballbar5x-run "$TRUTH" --control "$NOM" --db "$DB" --ball-mm $BALL --tolerances "$TMP/tol-x.toml"
run 4 "$TMP/fitted.json" >"$TMP/r2f.json" 2>/dev/null
# Against the control holding the whole fitted model: the report shows what it held and what is
# left beside each value, as daq show --json.
"$DAQ" show 4 --db "$DB" --json >"$TMP/show4.json"
"$DAQ" report 4 --db "$DB" -o "$TMP/r4.html" >/dev/null 2>&1
READINGS4=$("$PY" -c 'import json,sys; print(json.load(open(sys.argv[1]))["readings"])' "$TMP/r2f.json")
check report_left_as_show 0 "^ok$" -- report_vs_show "$TMP/r4.html" "$TMP/show4.json" "$READINGS4" 9
check after_swivel_zero 0 "^ok$" -- within "$TMP/r2s.json" zero "$TMP/r1.json"
check after_hal_tilts 0 "^ok$" -- within "$TMP/r2h.json" tilts "$TMP/r1.json"
check after_model_zero 0 "^ok$" -- within "$TMP/r2f.json" zero "$TMP/r1.json"
check after_text 0 "E_A0C +\+[0-9.]+ urad +u = [0-9.]+ +left \+(9\.|10\.)" -- "$DAQ" model ballbar5x-run "$TRUTH" --control "$NOM" --hal "$TMP/trt.hal" --db "$DB" --ball-mm $BALL --seed 5
# That run (5) was given no bar zeros: its report leaves the row out, not "Bar zeros injected µm".
"$DAQ" report 5 --db "$DB" -o "$TMP/r5.html" >/dev/null 2>&1
check report_no_offsets_row 1 "^0$" -- grep -c "Bar zeros injected" "$TMP/r5.html"
check report_seed_row 0 "Noise seed</td><td>5</td>" -- cat "$TMP/r5.html"
check write_refused 2 "write against a corrected control" -- "$DAQ" model ballbar5x-run "$TRUTH" --control "$NOM" --hal "$TMP/trt.hal" --db "$DB" --ball-mm $BALL --write "$TMP/x.json"
# Bad input says what and where.
check on_the_line 2 "the table ball is 0\.000 mm from the C axis line" -- "$DAQ" model ballbar5x-run "$TRUTH" --control "$NOM" --db "$DB" --ball-mm 0 0 -250
check both 2 "give one control's kinematics" -- "$DAQ" model ballbar5x-run "$TRUTH" --control "$NOM" --hal "$TMP/trt.hal" --swivel "$TMP/swivel.mpf" --db "$DB" --ball-mm $BALL
finish
