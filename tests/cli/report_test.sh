#!/usr/bin/env bash
# daq report from stored runs: the demo stores a SIMULATED linear and circle run; each report
# type is rendered and its content checked against the numbers `daq analyse --json` gives
# for the same runs (not against the report's own output), plots present, no external
# resource; then headless Chromium renders the HTML (every plot laid out, a screenshot) and
# prints a PDF.
# Usage: report_test.sh DAQ_BINARY TESTS_DIR
set -u
DAQ=$1
TESTS=$2
source "$(dirname "$0")/check.sh"
scratch_dir
cd "$TMP"

demo_runs "$TMP"  # runs 1 (linear) and 2 (circle) of `daq demo`
# A third run: the linear capture replayed (the comparison needs the same test twice).
"$DAQ" replay "$DEMO_CDQ" --db demo.sqlite >replay.log 2>&1 || { cat replay.log; exit 1; }

json_value() {  # json_value FILE PYTHON_EXPRESSION_ON_d -> the value with 3 decimals
  "$PY" -c "import json,sys; d=json.load(open('$1')); print(format($2, '.3f'))" || echo "BAD"
}
count() { grep -o -- "$2" "$1" | wc -l; }
# The texts of a report's plots, decoded (PLplot writes every character as &#x..;).
svgtext() { "$PY" -c "import html,re,sys; print('\n'.join(html.unescape(t) for t in re.findall(r'<tspan[^>]*>(.*?)</tspan>', open(sys.argv[1]).read())))" "$1"; }
# A value must be a number, or the content checks below would match anything.
number() { [[ "$1" =~ ^-?[0-9]+\.[0-9]{3}$ ]] || { echo "FAIL: not a number: '$1'"; fails=$((fails + 1)); }; }

# --- one linear run ----------------------------------------------------------------------------
"$DAQ" analyse 1 --db demo.sqlite --json >lin.json
check linear_report 0 "run report of run 1 written to r1.html" -- "$DAQ" report 1 --db demo.sqlite -o r1.html
for key in E_bi M B R_bi A_bi E_up; do
  v=$(json_value lin.json "d['axis']['$key']['value_um']")
  number "$v"
  check "linear_value_$key" 0 ">$v<" -- cat r1.html
done
check_file r1.html <<'END'
linear_standard Evaluated by <strong>ISO 230-2:2014</strong>
linear_uncertainty expanded uncertainty U = [0-9.]+ µm \(k = 2\)
linear_targets <td class="r">500.000</td>
END
# Two ISO 230-2 plots (means with bands, run by run) and three environment plots.
check linear_plots 0 "^5$" -- count r1.html "<svg class=\"plot\""
check_file r1.html <<'END'
linear_band x̄ ± 2s
simulated_said <strong>SIMULATED</strong>: this run was made on the simulated machine
environment Air temperature</td>
END
# Self-contained: nothing is loaded from elsewhere (the SVG namespaces are names, not loads).
check no_external 1 "^0$" -- grep -cE "(src|href)=\"(https?:)?//" r1.html
# Another standard on request.
"$DAQ" report 1 --db demo.sqlite -s vdi3441 -o vdi.html >/dev/null
check vdi_content 0 "Evaluated by <strong>VDI/DGQ 3441" -- cat vdi.html

# --- one circle run ----------------------------------------------------------------------------
"$DAQ" analyse 2 --db demo.sqlite --json >circ.json
check circle_report 0 "written to r2.html" -- "$DAQ" report 2 --db demo.sqlite -o r2.html
for key in G_bi_um F_max_um; do
  v=$(json_value circ.json "d['iso230_4']['$key']")
  number "$v"
  check "circle_value_$key" 0 ">$v<" -- cat r2.html
done
# H is a 1996 quantity: shown apart as informative, not as an ISO 230-4:2005 value.
v=$(json_value circ.json "d['informative']['H_um']['value']")
number "$v"
check circle_value_H_informative 0 ">$v</td><td><em>informative</em>: circular hysteresis of ISO 230-4:1996" -- cat r2.html
check circle_standard 0 "Evaluated by <strong>ISO 230-4:2005</strong>" -- cat r2.html
check circle_not_evaluated 0 "Not evaluated: mean bi-directional radial deviation" -- cat r2.html
top=$("$PY" -c "import json,re; print(re.escape(json.load(open('circ.json'))['diagnostics'][0]['name']))")
check circle_top_diagnostic 0 "<td class=\"r\">1</td><td>$top</td>" -- cat r2.html
check circle_polar 0 "Polar plot, least-squares centre removed" -- cat r2.html
check circle_directions 0 "counter-clockwise" -- cat r2.html

# --- campaign and comparison -------------------------------------------------------------------
check campaign 0 "campaign report of runs 1, 2, 3" -- "$DAQ" report --campaign "demo (simulated)" --db demo.sqlite -o camp.html
check campaign_sections 0 "^3$" -- count camp.html "<h2 class=\"run\" id=\"run-"
check campaign_summary 0 "<a href=\"#run-2\">2</a>" -- cat camp.html
check compare 0 "comparison report of runs 1, 3" -- "$DAQ" report --compare 1 3 --db demo.sqlite -o cmp.html
check compare_overlay 0 "Mean bidirectional deviation, run by run" -- cat cmp.html
check compare_trend 0 "Each value over time" -- cat cmp.html
e1=$(json_value lin.json "d['axis']['E_bi']['value_um']")
number "$e1"
check compare_values 0 "^2$" -- count cmp.html ">$e1 <span"  # the replay gives the same E
check compare_multiples 0 "class=\"multiples\"" -- cat cmp.html
check compare_small_plots 0 "^([7-9]|[1-9][0-9])$" -- count cmp.html "<svg class=\"plot\""
# Limits stored that fit none of the values (P, a VDI 3441 one, on ISO 230-2 runs): the
# comparison says no tolerance applies and why, not that no limit was stored (which is false).
cp demo.sqlite p_only.sqlite
"$PY" - p_only.sqlite <<'PYEOF'
import json, sqlite3, sys
con = sqlite3.connect(sys.argv[1])
for rid in (1, 3):
    (s,) = con.execute("SELECT settings_json FROM runs WHERE id = ?", (rid,)).fetchone()
    d = json.loads(s)
    d["context"]["tolerances"] = {"P_um": 15.0, "by_length": [], "source": "tolerances.X"}
    con.execute("UPDATE runs SET settings_json = ? WHERE id = ?", (json.dumps(d), rid))
con.commit()
PYEOF
check compare_p_only 0 "comparison report of runs 1, 3" -- "$DAQ" report --compare 1 3 --db p_only.sqlite -o p_only.html
check compare_no_tolerance_applies 0 "<strong>No tolerance applies</strong> to these runs" -- cat p_only.html
check compare_no_tolerance_note 0 "class=\"note\">[^<]*P" -- cat p_only.html
check compare_no_false_hint 0 "^0$" -- count p_only.html "No limit was stored"
# Runs of one day: the date cell gives the day and the time, each unbroken, the run its own column.
check compare_dates 0 "<td>1</td><td><span class=\"nw\">[0-9]{2}-[0-9]{2}</span> <span class=\"nw\">[0-9]{2}:[0-9]{2}</span>" -- cat cmp.html
check compare_mixed 2 "compare the same test" -- "$DAQ" report --compare 1 2 --db demo.sqlite
check unknown_run 2 "no run 99" -- "$DAQ" report 99 --db demo.sqlite
check bad_format 2 "use html or pdf" -- "$DAQ" report 1 --db demo.sqlite --format docx

# --- every plot keeps its text: ids unique in the page, each plot's clip paths its own ---------
check ids_linear 0 "all unique" -- "$PY" "$TESTS/../web/report_ids_test.py" r1.html 5
check ids_circle 0 "all unique" -- "$PY" "$TESTS/../web/report_ids_test.py" r2.html 1
check ids_campaign 0 "all unique" -- "$PY" "$TESTS/../web/report_ids_test.py" camp.html 11
check ids_compare 0 "all unique" -- "$PY" "$TESTS/../web/report_ids_test.py" cmp.html 7

# --- what a customer receives (the demo's configuration, cmd_demo.cpp) --------------------------
check_file r1.html <<'END'
customer <td>Customer</td><td>Demo customer \(simulated\)</td>
machine_serial <td>Serial number</td><td>SIM-0001</td>
operator <td>Operator</td><td>demo operator</td>
instrument_serial <td>SIM-IDS-0001</td><td>none \(simulated instrument\)</td><td>2099-12-31</td>
past_due 2020-01-31 &mdash; PAST DUE
past_due_warning the calibration of material \(due 2020-01-31\) was past due on the test date
conditions <td>Controller compensation</td><td>off
sign_convention <td>Sign convention</td><td>Positional deviation
provenance <td>Obtained</td><td>acquired</td>
END
# Verdicts: the demo's limits E 10, R 6, B 3, A 12, M 8 um and, in XY, G 10 um, backlash X 3 um,
# squareness 30 um/m; the injected backlash of 4 um fails B and backlash X, the rest pass.
B=$(json_value lin.json "d['axis']['B']['value_um']")
number "$B"
check verdict_linear 0 "<strong>FAIL</strong> &mdash; 1 of 5 limited values outside" -- cat r1.html
check verdict_linear_B 0 ">$B</td><td class=\"r\">≤ 3.000</td><td><span class=\"fail\">FAIL</span>" -- cat r1.html
check verdict_linear_E 0 "≤ 10.000</td><td><span class=\"pass\">pass</span>" -- cat r1.html
check verdict_circle 0 "<strong>FAIL</strong> &mdash; 1 of 3 limited values outside" -- cat r2.html
check verdict_circle_G 0 "≤ 10.000</td><td><span class=\"pass\">pass" -- cat r2.html
# VDI/DGQ 3441 judged by its own limits (the demo's P_um, Pa_um, Ps_um, U_um), not "No tolerance".
check verdict_vdi 0 "<td>P</td><td class=\"r\">[0-9.]+</td><td>position uncertainty</td><td class=\"r\">≤ 15.000</td>" -- cat vdi.html
check verdict_vdi_not_none 0 "^judged$" -- bash -c 'grep -q "No tolerance" vdi.html || echo judged'
check grid 0 "<th>↑&nbsp;up</th><th>↓&nbsp;down</th><th>bidirectional</th>" -- cat r1.html
check two_s_lines 0 "^x̄↑ ± 2s$" -- svgtext r1.html
G2=$("$PY" -c "import json; print(format(json.load(open('circ.json'))['iso230_4']['G_bi_um'], '.3f'))")
check circle_g_on_plot 0 "^G = $G2 µm$" -- svgtext r2.html
check circle_start_marked 0 "^○ start, arrow: direction of travel$" -- svgtext r2.html
# The rings' spacing under the plot, off the traces and the angle labels (in the corner it sat on
# the 120° label once the plot stood beside the values).
check circle_rings_off_traces 0 "^rings every [0-9.]+ µm, the dark one nominal$" -- svgtext r2.html
check circle_gain_explained 0 "a negative gain means the error partly cancels another" -- cat r2.html
check campaign_nowrap 0 "<span class=\"nw\">E [0-9.]+ µm</span>" -- cat camp.html
check campaign_verdict 0 "<span class=\"fail\">FAIL</span></td>" -- cat camp.html
check as_found 0 "as-found-as-left report of runs 1, 3 written to af.html" -- "$DAQ" report --as-found 1 --as-left 3 --db demo.sqlite -o af.html
check as_found_table 0 "<th>as found, run 1</th><th>as left, run 3</th>" -- cat af.html
check as_found_mixed 2 "give the same test before and after" -- "$DAQ" report --as-found 1 --as-left 2 --db demo.sqlite

# --- rendered by Chromium ------------------------------------------------------------------------
# All five in one Chromium (render_reports.py runs report_render_test.py on each, its checks
# unchanged; a browser's start-up costs about 1 s).
"$PY" "$TESTS/../cli/render_reports.py" "r1=$TMP/r1.html:$TMP/r1.png:SIMULATED — Run " "r2=$TMP/r2.html:$TMP/r2.png:SIMULATED — Run " \
  "camp=$TMP/camp.html:$TMP/camp.png:SIMULATED, REPLAYED — Campaign" "cmp=$TMP/cmp.html:$TMP/cmp.png:Comparison" \
  "af=$TMP/af.html:$TMP/af.png:SIMULATED, REPLAYED — As found" >rendered.txt 2>&1
check_file rendered.txt <<'END'
rendered ^r1: rendered 5 plots
rendered_circle ^r2: rendered 1 plots
rendered_campaign ^camp: rendered 11 plots
rendered_compare ^cmp: rendered [0-9]+ plots
rendered_as_found ^af: rendered [0-9]+ plots
END
# Chromium prints once (1-2 s), to a pipe: its bytes are the PDF checked page by page below.
"$DAQ" report 1 --db demo.sqlite --format pdf -o /dev/stdout 2>pdf.status | cat >r1-pipe.pdf
check pdf_to_pipe 0 "^%PDF-1" -- head -c 8 r1-pipe.pdf
# To a named file, through a stand-in for Chromium ($CALDAQ_CHROMIUM) that checks it is given
# this report's HTML and copies the PDF printed above to where daq asks.
cat >printer.sh <<END
#!/bin/bash
for a; do case \$a in --print-to-pdf=*) out=\${a#*=} ;; file://*) html=\${a#file://} ;; esac; done
grep -q "Run 1: Positioning test" "\$html" && cp "$TMP/r1-pipe.pdf" "\$out"
END
chmod +x printer.sh
check pdf 0 "written to r1.pdf" -- env CALDAQ_CHROMIUM="$TMP/printer.sh" "$DAQ" report 1 --db demo.sqlite --format pdf -o r1.pdf
check pdf_magic 0 "^%PDF-1" -- head -c 8 r1.pdf
# To a stream: the report's bytes on stdout (the status line on stderr), HTML and PDF alike.
check html_to_stdout 0 "^<!doctype html>" -- bash -c "\"\$1\" report 1 --db demo.sqlite -o /dev/stdout 2>/dev/null | head -c 15" _ "$DAQ"
check html_to_stdout_status 0 "written to /dev/stdout \([0-9]{4,} bytes\)" -- bash -c "\"\$1\" report 1 --db demo.sqlite -o /dev/stdout 2>&1 >/dev/null" _ "$DAQ"
check pdf_pages 0 "/Type */Page($|[^s])" -- cat r1.pdf
# Printed: "page n of m" and the running header on every page; no page with only a heading or
# only the footer (each page holds at least 8 lines of text besides its header and number).
pages=$(pdfinfo r1.pdf | sed -nE 's/^Pages: +([0-9]+)/\1/p')
check pdf_page_count 0 "^[3-9]$" -- echo "$pages"
for p in $(seq 1 "${pages:-0}"); do
  text=$(pdftotext -f "$p" -l "$p" -layout r1.pdf -)
  check "pdf_page_${p}_number" 0 "page $p of $pages" -- echo "$text"
  check "pdf_page_${p}_header" 0 "Run 1: Positioning test \(ISO 230-2\), axis X +Demo customer" -- echo "$text"
  check "pdf_page_${p}_content" 0 "^([89]|[1-9][0-9]+)$" -- bash -c "grep -cvE '^\s*$|page [0-9]+ of|Run 1: Positioning' <<<\"\$1\"" _ "$text"
done

# --- a re-compensated run: its report shows both coefficients, the original and new values, and
# the budget uses the new coefficient. Material temperature term of the budget by hand:
# L alpha u(T) = 500 mm x 11.5e-6/K x 0.1 K = 0.5750 um; with 12 ppm/K 0.6000 um.
check budget_before 0 "<td>material temperature</td><td class=\"r\">0.5750</td>" -- cat r1.html
check recompensate 0 "stored as result [0-9]+, superseding result 1" -- "$DAQ" recompensate 1 --alpha-ppm 12 --db demo.sqlite
"$DAQ" report 1 --db demo.sqlite -o r1b.html >/dev/null
check_file r1b.html <<'END'
recomp_setting 11.5 ppm/K <span class="changed">\(as acquired; the current result uses 12\)</span>
recomp_coefficients Expansion coefficient \(ppm/K\)</td><td class="r">11.5</td><td class="r"><span class="changed">12</span>
recomp_values Original \(result 1\) and re-compensated \(result [0-9]+\) values
recomp_budget <td>material temperature</td><td class="r">0.6000</td>
recomp_of <td>Re-compensation of</td><td>result 1</td>
END
"$DAQ" report --compare 1 3 --db demo.sqlite -o cmp2.html >/dev/null
check compare_recompensated 0 "<td>1<br><span class=\"changed\">re-compensated</span>" -- cat cmp2.html
check show_superseded 0 "result 1: ISO 230-2:2014 \(superseded by result [0-9]+\)" -- "$DAQ" show 1 --db demo.sqlite
check show_current 0 "recompensated .* of result 1; ciddor, 12 ppm/K; expansion_ppm_per_k 11.5 -> 12" -- "$DAQ" show 1 --db demo.sqlite
check show_values 0 "^        E +[0-9]+\.[0-9]{3} um" -- "$DAQ" show 1 --db demo.sqlite
# A second correction keeps the first: the offset is added, 12 ppm/K stays.
check recomp_keeps 0 "material_offset_k: 0(\.0)? -> 0\.1" -- "$DAQ" recompensate 1 --material-offset 0.1 --db demo.sqlite
check recomp_keeps_alpha 0 "ciddor, 12 ppm/K; offsets material \+0.1 K" -- "$DAQ" show 1 --db demo.sqlite
check recomp_nan 2 "--alpha-ppm: 'nan' is not a finite decimal number" -- "$DAQ" recompensate 1 --alpha-ppm nan --db demo.sqlite
finish
