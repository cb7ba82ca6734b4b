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
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
source "$(dirname "$0")/check.sh"
cd "$TMP"

"$DAQ" demo --quiet --db demo.sqlite --capture demo.cdq >demo.log 2>&1 || { cat demo.log; exit 1; }
# A third run: the linear capture replayed (the comparison needs the same test twice).
"$DAQ" replay demo.cdq --db demo.sqlite >replay.log 2>&1 || { cat replay.log; exit 1; }

json_value() {  # json_value FILE PYTHON_EXPRESSION_ON_d -> the value with 3 decimals
  python3 -c "import json,sys; d=json.load(open('$1')); print(format($2, '.3f'))" || echo "BAD"
}
count() { grep -o -- "$2" "$1" | wc -l; }
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
check linear_standard 0 "Evaluated by <strong>ISO 230-2:2014</strong>" -- cat r1.html
check linear_uncertainty 0 "expanded uncertainty U = [0-9.]+ µm \(k = 2\)" -- cat r1.html
check linear_targets 0 "<td class=\"r\">500.000</td>" -- cat r1.html
# Two ISO 230-2 plots (means with bands, run by run) and three environment plots.
check linear_plots 0 "^5$" -- count r1.html "<svg class=\"plot\""
check linear_band 0 "x̄ ± 2s" -- cat r1.html
check simulated_said 0 "made on the <strong>simulated</strong> machine" -- cat r1.html
check environment 0 "Air temperature</td>" -- cat r1.html
# Self-contained: nothing is loaded from elsewhere (the SVG namespaces are names, not loads).
check no_external 1 "^0$" -- grep -cE "(src|href)=\"(https?:)?//" r1.html
# Another standard on request.
"$DAQ" report 1 --db demo.sqlite -s vdi3441 -o vdi.html >/dev/null
check vdi_content 0 "Evaluated by <strong>VDI/DGQ 3441" -- cat vdi.html

# --- one circle run ----------------------------------------------------------------------------
"$DAQ" analyse 2 --db demo.sqlite --json >circ.json
check circle_report 0 "written to r2.html" -- "$DAQ" report 2 --db demo.sqlite -o r2.html
for key in G_bi_um H_um F_max_um; do
  v=$(json_value circ.json "d['iso230_4']['$key']")
  number "$v"
  check "circle_value_$key" 0 ">$v<" -- cat r2.html
done
top=$(python3 -c "import json,re; print(re.escape(json.load(open('circ.json'))['diagnostics'][0]['name']))")
check circle_top_diagnostic 0 "<td class=\"r\">1</td><td>$top</td>" -- cat r2.html
check circle_polar 0 "Polar plot, least-squares centre removed" -- cat r2.html
check circle_directions 0 "counter-clockwise" -- cat r2.html

# --- campaign and comparison -------------------------------------------------------------------
check campaign 0 "campaign report of runs 1, 2, 3" -- "$DAQ" report --campaign "demo (simulated)" --db demo.sqlite -o camp.html
check campaign_sections 0 "^3$" -- count camp.html "<h2 id=\"run-"
check campaign_summary 0 "<a href=\"#run-2\">2</a>" -- cat camp.html
check compare 0 "comparison report of runs 1, 3" -- "$DAQ" report --compare 1 3 --db demo.sqlite -o cmp.html
check compare_overlay 0 "Mean bidirectional deviation, run by run" -- cat cmp.html
check compare_trend 0 "Results over time" -- cat cmp.html
e1=$(json_value lin.json "d['axis']['E_bi']['value_um']")
number "$e1"
check compare_values 0 "^2$" -- count cmp.html ">$e1<"  # the replay gives the same E
check compare_mixed 2 "compare the same test" -- "$DAQ" report --compare 1 2 --db demo.sqlite
check unknown_run 2 "no run 99" -- "$DAQ" report 99 --db demo.sqlite
check bad_format 2 "use html or pdf" -- "$DAQ" report 1 --db demo.sqlite --format docx

# --- rendered by Chromium ------------------------------------------------------------------------
check rendered 0 "rendered 5 plots" -- python3 "$TESTS/../web/report_render_test.py" "$TMP/r1.html" "$TMP/r1.png"
check rendered_circle 0 "rendered 1 plots" -- python3 "$TESTS/../web/report_render_test.py" "$TMP/r2.html" "$TMP/r2.png"
check pdf 0 "written to r1.pdf" -- "$DAQ" report 1 --db demo.sqlite --format pdf -o r1.pdf
check pdf_magic 0 "^%PDF-1" -- head -c 8 r1.pdf
check pdf_pages 0 "/Type */Page($|[^s])" -- cat r1.pdf
finish
