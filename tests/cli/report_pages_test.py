#!/usr/bin/env python3
"""Issue 30: page one of every demo report is the answer. Each report of the demo's runs (the
linear run, the circle run, the linear run by VDI/DGQ 3441, a suspect copy of the replayed run,
the campaign, the comparison, as found / as left) is printed to PDF by `daq report --format pdf`
(headless Chromium), its pages read back as text (pdftotext, poppler-utils) and checked: the
verdict, the failing values and the main table on the first page of the report (for a campaign,
on the first page of each run's section); a suspect run says so there, traceability gaps are
warned there; the campaign summary gives each value in its own unit and every failing one. The
circle's page one holds the verdict, the values, the polar plot and what to fix first; no page
runs past the right margin or is printed shrunk; as found / as left start each run on a page. Then the plots in the HTML:
no text in them prints below 9 pt at the width the page gives them.
Usage: report_pages_test.py DAQ_BINARY [OUT_DIR]  (CALDAQ_DEMO_FIXTURE: a `daq demo` to copy)"""
import glob
import html as html_mod
import os
import re
import shutil
import sqlite3
import subprocess
import sys
import tempfile
import time


DAQ = os.path.abspath(sys.argv[1])
fails = 0


def check(name, ok, detail=""):
    global fails
    print(("ok   " if ok else "FAIL ") + name + ("" if ok else ": " + detail[:400]))
    if not ok:
        fails += 1


def daq(*args):
    r = subprocess.run([DAQ, *args], capture_output=True, text=True, timeout=400)
    if r.returncode != 0:
        raise SystemExit(f"daq {' '.join(args)} failed: {r.stdout}{r.stderr}")
    return r.stdout


def pages(pdf):
    """The text of each page of a PDF."""
    out = subprocess.run(["pdftotext", pdf, "-"], capture_output=True, text=True,
                         check=True).stdout
    return out.split("\f")


def squash(text):
    return re.sub(r"\s+", " ", text)


work = sys.argv[2] if len(sys.argv) > 2 else tempfile.mkdtemp(prefix="report_pages.")
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
os.chdir(work)
fixture = os.environ.get("CALDAQ_DEMO_FIXTURE")
if fixture:
    for f in glob.glob(os.path.join(fixture, "demo.sqlite*")):
        shutil.copy(f, work)
    capture = os.path.join(fixture, "demo.cdq")
    demo_out = open(os.path.join(fixture, "demo.log"), encoding="utf-8").read()
else:
    demo_out = daq("demo", "--quiet", "--db", "demo.sqlite", "--capture", "demo.cdq")
    capture = os.path.join(work, "demo.cdq")
db = ["--db", "demo.sqlite"]
replay_out = daq("replay", capture, *db)  # run 3: the linear run again (comparison, as found...)
daq("replay", capture, *db)  # run 4: made suspect below
# Run 3 re-compensated with the coefficient it was acquired with: its terminal summary is one of
# the outputs compared below (its values are run 1's, within what a re-compensation moves).
recompensate_out = daq("recompensate", "3", "--alpha-ppm", "11.5", *db)
# Run 4 made suspect: one stop 5 um off (the others repeat to about 0.01 um), and its stored
# quality cleared so it is assessed from the stops when read.
con = sqlite3.connect("demo.sqlite")
con.execute("UPDATE captured_targets SET deviation_um = deviation_um + 5 WHERE run_id = 4 AND "
            "run_number = 2 AND direction = '+' AND target_index = 3")
con.execute("UPDATE runs SET quality = NULL, quality_note = '' WHERE id = 4")
con.commit()
con.close()

# --- one presentation of each result (same values, order, names, units, rounding) ------------
ROW = re.compile(r"^\s*(\S+(?: \S+)?)\s+(-?\d+\.\d{3})(?:, -?\d+\.\d{3})? um\s{3}(.*)$")


def value_rows(out, first_title):
    """The (symbol, value as printed) rows of the result block that begins with first_title."""
    lines = out.splitlines()
    start = next(i for i, line in enumerate(lines) if line.strip().startswith(first_title))
    rows = []
    for line in lines[start + 1:]:
        m = ROW.match(line)
        if m:
            rows.append((m.group(1), m.group(2)))
        elif rows and not line.strip().startswith(("note", "warning", "not evaluated")):
            break
    return rows


def printed(v):
    """A JSON number as every output prints it: 3 decimals, never -0.000."""
    t = f"{v:.3f}"
    return "0.000" if t == "-0.000" else t


def current(doc):
    return next(r for r in doc["results"] if r["current"])


import json  # noqa: E402

lin_title = "ISO 230-2:2014 ("
outputs = {
    "daq replay (run 3)": value_rows(replay_out, lin_title),
    "daq show 1": value_rows(daq("show", "1", *db), lin_title),
    "daq analyse 1": value_rows(daq("analyse", "1", *db), lin_title),
}
show1 = json.loads(daq("show", "1", *db, "--json"))
outputs["daq show 1 --json (values)"] = [(r["symbol"], printed(r["value"]))
                                         for r in current(show1)["result"]["values"]]
check("linear: the values in the grid's order (E↑ E↓ E R↑ ...)",
      [s for s, _ in outputs["daq show 1"]][:6] == ["E↑", "E↓", "E", "R↑", "R↓", "R"],
      str(outputs["daq show 1"]))
for name, rows in outputs.items():
    check(f"linear: {name} reads as daq show 1", rows == outputs["daq show 1"] and len(rows) >= 12,
          f"{rows} != {outputs['daq show 1']}")
check("daq recompensate 3 reads as daq show 3",
      value_rows(recompensate_out, lin_title) == value_rows(daq("show", "3", *db), lin_title)
      and len(value_rows(recompensate_out, lin_title)) >= 12, recompensate_out)
circle_title = "ISO 230-4:2005 circular test"
show2_text = daq("show", "2", *db)
show2 = json.loads(daq("show", "2", *db, "--json"))
circle_values = [(r["symbol"], printed(r["value"])) for r in current(show2)["result"]["values"]
                 if r["unit"] == "um" and r["key"].endswith("_um")]
check("circle: daq show 2 and daq analyse 2 print one block",
      value_rows(show2_text, circle_title) == value_rows(daq("analyse", "2", *db), circle_title)
      and len(value_rows(show2_text, circle_title)) >= 4, show2_text)
check("circle: daq show 2 reads as its JSON values",
      value_rows(show2_text, circle_title)[:len(circle_values)] == circle_values,
      f"{value_rows(show2_text, circle_title)} / {circle_values}")
check("no -0.000 on the terminal", "-0.000" not in show2_text + replay_out, show2_text)
# The demo's own circle summary is the same block (it printed G(b) to 2 decimals).
check("circle: daq demo prints the block of daq show 2",
      circle_title in demo_out
      and value_rows(demo_out, circle_title) == value_rows(show2_text, circle_title),
      demo_out[-3000:])
check("daq demo: 3 decimals everywhere", re.search(r"\d\.\d\d um", demo_out.split(
    "ballbar circle")[-1]) is None, demo_out[-3000:])

reports = {
    "linear": ["1"],
    "circle": ["2"],
    "vdi3441": ["1", "-s", "vdi3441"],
    "suspect": ["4"],
    "campaign": ["--campaign", "demo (simulated)"],
    "comparison": ["--compare", "1", "3"],
    # The demo's circle against itself: a circle's comparison table has the G values and every
    # diagnostic (17 columns across the page printed it shrunk to about 5 pt).
    "comparison-circle": ["--compare", "2", "2"],
    "asfound": ["--as-found", "1", "--as-left", "3"],
}
text = {}
DRAFT = "DRAFT — NOT APPROVED"
draft_marks = {}
for name, args in reports.items():
    daq("report", *args, *db, "--format", "pdf", "-o", f"{name}.pdf")
    daq("report", *args, *db, "-o", f"{name}.html")
    printed = [squash(p) for p in pages(f"{name}.pdf")]
    # The demo's results are not approved (issue 35): every printed page carries the mark in its
    # bottom margin, which pdftotext reads anywhere in the page's text; the checks below read
    # the page without it.
    draft_marks[name] = [p.count(DRAFT) for p in printed if p.strip()]
    text[name] = [p.replace(DRAFT + " ", "").replace(DRAFT, "") for p in printed]

# A draft says so at the foot of every printed page, and its on-screen box takes no room on
# page one (it pushed a report's main plot off page one).
for name in ("linear", "circle", "suspect"):
    check(f"{name}: DRAFT — NOT APPROVED on every printed page",
          draft_marks[name] and all(n == 1 for n in draft_marks[name]), str(draft_marks[name]))
    check(f"{name}: the draft box not printed", "has not been approved" not in text[name][0],
          text[name][0][:300])
    check(f"{name}: the draft box on screen",
          '<div class="approval draft"><strong>DRAFT — NOT APPROVED</strong>' in
          open(f"{name}.html", encoding="utf-8").read(), "")

# The report's tables hold the same numbers in the same order.
def cells(html, cls):
    """The text of each cell of the first table of this class, row by row."""
    t = re.search(r'<table class="' + cls + r'">.*?</table>', html, re.S).group(0)
    return [[html_mod.unescape(re.sub(r"<[^>]+>", "", c)).strip()
             for c in re.findall(r"<td[^>]*>(.*?)</td>", row, re.S)]
            for row in re.findall(r"<tr>(.*?)</tr>", t.split("<tbody>")[1], re.S)]


grid = cells(open("linear.html", encoding="utf-8").read(), "num results grid")
grid_values = [c for row in grid for c in row[1:4] if re.fullmatch(r"-?\d+\.\d{3}", c)]
check("linear report: the grid reads as daq show 1, row by row",
      grid_values == [v for _, v in outputs["daq show 1"]], f"{grid_values}")
circle_html = open("circle.html", encoding="utf-8").read()
circle_table = cells(circle_html, "num results beside")
# Page one's table gives the meaning under each symbol (it stands beside the polar plot).
check("circle report: the standard's values as daq show 2",
      [(next((s for s, _ in circle_values if r[0].startswith(s)), r[0]), r[1])
       for r in circle_table[:len(circle_values)]] == circle_values,
      f"{circle_table}")
diag_json = [(r["symbol"], r["value"], r["unit"]) for r in current(show2)["result"]["values"]
             if not r["key"].endswith("_um")]
diag_report = [row[1] for row in cells(circle_html.split("Details of the results")[1], "num diag")]
check("circle report: the diagnostics in the order of the JSON",
      diag_report == [d[0] for d in diag_json], f"{diag_report} / {diag_json}")

# --- page one of a run report ---------------------------------------------------------------
for name in ("linear", "vdi3441", "suspect", "circle"):
    p1 = text[name][0]
    check(f"{name}: SIMULATED on page one", "SIMULATED: this run was made" in p1, p1[:300])
    check(f"{name}: customer and machine on page one",
          "Demo customer (simulated)" in p1 and "SIMULATED VMC" in p1, p1[:400])
    check(f"{name}: verdict on page one", re.search(r"Verdict against the machine specification|"
                                                    r"No tolerance (configured|applies)", p1)
          is not None, p1[:600])
    if name != "circle":  # the demo's thermometer is past due; the ballbar's calibration is not
        check(f"{name}: traceability warning on page one",
              "Traceability: the calibration of material (due 2020-01-31) was past due" in p1,
              p1[:800])
# A report of several runs warns of their traceability gaps on page one too, each gap once (the
# demo's linear runs share their thermometer past due; the campaign's circle does not, so
# there the runs it concerns are named). Before, only each run's section said so, pages later.
for name in ("asfound", "comparison", "campaign"):
    p1 = text[name][0]
    check(f"{name}: traceability warning on page one, once",
          re.search(r"Traceability: the calibration of material \(due 2020-01-31(, runs? [0-9, ]+)?\) "
                    r"was past due", p1) is not None and p1.count("was past due") == 1,
          p1[:1200])
for name in ("linear", "suspect"):
    p1 = text[name][0]
    # The main table: the grid of E, R, A, M, B with up, down, bidirectional, limit, verdict.
    # Its head and rows (pdftotext may read the head's last cells after the first row).
    check(f"{name}: main table on page one",
          all(w in p1 for w in ("value (µm)", "↑ up ↓ down bidirectional", "limit (µm)", "verdict",
                                "E — systematic positional deviation", "B̄ — mean reversal value")),
          p1)
    check(f"{name}: failing values named on page one",
          re.search(r"FAIL.*limit ≤ [0-9.]+ µm\)", p1) is not None, p1)
    # What to fix first, beside the failing value (the demo's B: the reversal value of ISO
    # 230-2 is the axis' backlash; the page named only the value and its limit).
    check(f"{name}: what to check for the failing B on page one",
          re.search(r"B = [0-9.]+ µm \(limit ≤ 3\.000 µm\): check the backlash "
                    r"compensation", p1) is not None, p1)
    # The main plot on page one too (it was on page two).
    check(f"{name}: main plot on page one", "Mean positional deviation with ±2s" in p1, p1)
# Page one is full and the last page is not a line or two (the lead saw page one a third blank:
# the details began on page two; and a last page with the appendix's last ten rows, 17 % of it).
# Measured from the words' positions (pdftotext -bbox): how far down the text area between the
# margins the content reaches.
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from report_checks import page_fill, pdf_words  # noqa: E402
for name in ("linear", "vdi3441", "suspect"):
    fills = [page_fill(*p) for p in pdf_words(f"{name}.pdf")]
    check(f"{name}: page one filled to its foot (>= 90 % of the text area)", fills[0] >= 0.9,
          str(fills))
    if name != "suspect":  # (its page one is full with the SUSPECT RUN box)
        check(f"{name}: the details begin on page one", "Per target" in text[name][0],
              text[name][0])
    check(f"{name}: the last page not almost empty (>= 30 % of the text area)",
          len(fills) > 1 and fills[-1] >= 0.3, str(fills))
    # No page but the last under 80 %: the pressure plot, under the temperatures at full width,
    # fell to the next page (the demo's environment page 71 % full, the next 60 %), and the
    # appendix's page break left the suspect run's page before it 29 % full.
    check(f"{name}: no page but the last under 80 % of the text area",
          all(f >= 0.8 for f in fills[:-1]), str(fills))
    # Pressure and humidity side by side: their figure captions start on one line of one page.
    captions = [(i, w[1]) for i, (ws, _) in enumerate(pdf_words(f"{name}.pdf")) for k, w in
                enumerate(ws) if w[4] in ("Air", "Relative") and k + 2 < len(ws)
                and ws[k + 1][4] in ("pressure", "humidity") and ws[k + 2][4] == "during"]
    check(f"{name}: pressure and humidity plots side by side",
          len(captions) == 2 and captions[0][0] == captions[1][0]
          and abs(captions[0][1] - captions[1][1]) < 1.0, str(captions))

# The demo's capture replayed into a database without its original run: no limits (a capture
# does not carry them), and the report says which keys, where, and why the replay has none.
fresh_out = daq("replay", capture, "--db", "fresh.sqlite")
# The terminal says the same as the report: which limits, under which table, and why a replay
# has none (it printed no verdict; daq run's general "[tolerances] in the configuration").
check("replay without its original run: the terminal names the keys, the table and the database",
      re.search(r"verdict: no tolerance configured: E_um, R_um, A_um, B_um or M_um under "
                r"\[tolerances\.X\] would judge it .*original run is not in \S*fresh\.sqlite, "
                r"and a capture does not carry the limits", fresh_out) is not None,
      fresh_out[-800:])
# A replay into the database with its original run: judged by that run's limits, as daq run.
check("replay with its original run: the verdict by its limits",
      re.search(r"verdict against tolerances\.X[^:]*: FAIL", replay_out) is not None,
      replay_out[-800:])
daq("report", "1", "--db", "fresh.sqlite", "--format", "pdf", "-o", "fresh.pdf")
f1 = squash(pages("fresh.pdf")[0])
check("replay without its original run: which limits, where, and why none",
      "No tolerance configured" in f1
      and "E_um, R_um, A_um, B_um or M_um under [tolerances.X]" in f1
      and "this capture's original run is not in it" in f1, f1[:1500])
daq("report", "3", *db, "-o", "replay.html")
check("replay in the demo's database: judged by its original run's limits",
      "Verdict against the machine specification (tolerances.X)" in open(
          "replay.html", encoding="utf-8").read(), "")

# The VDI 3441 main table is on page one, judged by its configured limits (the demo's P_um...;
# the report said "No tolerance applies").
v1 = text["vdi3441"][0]
check("vdi3441: main table with limits on page one",
      "symbol value (µm) meaning limit (µm) verdict" in v1
      and re.search(r"position uncertainty ≤ 15\.000 (pass|FAIL)", v1) is not None, v1)
check("vdi3441: a verdict, not 'No tolerance'", "Verdict against the machine specification" in v1
      and "No tolerance" not in v1, v1)
# The failing value in the verdict as in the table: "U max = 4.023 µm", not "+4.023".
check("vdi3441: the failing value as the table prints it",
      re.search(r"U max = [0-9.]+ µm \(limit ≤", v1) is not None
      and re.search(r"[0-9.]+ largest reversal span", v1) is not None, v1)
check("vdi3441: what to check for the failing U max on page one",
      re.search(r"U max = [0-9.]+ µm \(limit ≤ [0-9.]+ µm\): check the backlash", v1)
      is not None, v1)
check("vdi3441: main plot on page one", "Mean positional deviation with ±2s" in v1, v1)
# The title names the standard the page is evaluated by (it said ISO 230-2).
check("vdi3441: the title names VDI/DGQ 3441",
      "Run 1: Positioning test (VDI/DGQ 3441:1977), axis X" in v1
      and "Positioning test (ISO 230-2)" not in " ".join(text["vdi3441"]), v1[:300])
check("run quality says its state once",
      all("ok — ok" not in p and "ok - ok" not in p for n in text for p in text[n]), "")
# One colon after the label: "Run quality: ok: every stop ..." had two in a row.
quality_lines = [m for n in text for p in text[n] for m in re.findall(r"Run quality: [^.]{0,60}", p)]
check("run quality: one colon, the state then a comma",
      quality_lines and all(re.match(r"Run quality: (ok|not checked|suspect), ", q) for q in quality_lines)
      and any(q.startswith("Run quality: ok, every stop within") for q in quality_lines),
      str(quality_lines[:4]))
check("suspect: SUSPECT RUN on page one with its stop",
      "SUSPECT RUN" in text["suspect"][0] and "run 2 ↑ target 4" in text["suspect"][0],
      text["suspect"][0])
# Each suspect stop said once: "run 2 ↑ target 4: run 2 up at 149.024 mm: ..." named it twice.
check("suspect: the stop named once, with its position",
      re.search(r"run 2 ↑ target 4 \(149\.024 mm\): \+[0-9.]+ µm from the median", text["suspect"][0])
      is not None and "run 2 up at" not in text["suspect"][0], text["suspect"][0])
check("linear (clean): no SUSPECT", all("SUSPECT RUN" not in p for p in text["linear"]), "")
c1 = text["circle"][0]
check("circle: main table on page one", "symbol and meaning" in c1
      and "G(b) bi-directional circular deviation" in c1
      and re.search(r"[0-9.]+ ≤ 10\.000 pass", c1) is not None, c1)
# Page one holds all four: the verdict, the values, the polar plot and what to fix first with its
# three rows (the plot under the values pushed what to fix first onto page two; before that the
# plot was on page two).
check("circle: the polar plot on page one", "Polar plot, least-squares centre removed" in c1
      and "G = " in c1, c1)
check("circle: all of what to fix first on page one",
      re.search(r"What to fix first .* \d+ Backlash X .* 1 \w.* 2 \w", c1) is not None, c1)
# (pdftotext may read the value and gain columns, or only the gain column, after the rest of
# the page)
check("circle: what to fix first on page one", "What to fix first" in c1
      and re.search(r"rank (by gain )?error, and what to check (by gain )?"
                    r"(value (G gain \(share of G\) )?)?\d+ \w", c1)
      is not None and re.search(r"G gain \(share of G\) .*\+[0-9.]+ µm \(\d+ %\)", c1) is not None,
      c1)
check("circle: failing value named on page one",
      re.search(r"FAIL.*= [+-]?[0-9.]+ µm \(limit ≤", c1) is not None, c1)
# The failing diagnostic (the demo's backlash X, 4.084 µm against 3 µm) heads "What to fix
# first" though correcting it alone would make G larger (it partly offsets the servo mismatch),
# and the report says so; the others follow by their gain.
check("circle: the failing error first in what to fix first",
      re.search(r"What to fix first rank (by gain )?error, and what to check (by gain )?(value "
                r"(G gain \(share of G\) )?)?\d+ Backlash X FAIL \(limit ≤ 3\.000 µm\)", c1)
      is not None, c1)
circle_all = " ".join(text["circle"])
check("circle: a failing error with a negative gain is explained",
      re.search(r"Backlash X is outside its limit, but correcting it alone would make G [0-9.]+ "
                r"µm larger: it partly offsets [^.]*Servo mismatch", circle_all) is not None,
      circle_all[:3000])
# The details' diagnostics give each limit in its unit (a squareness's µm/m beside a backlash's
# µm under one head without any).
details_diag = cells(circle_html.split("Details of the results")[1], "num diag")
limits = [r[6] for r in details_diag if r[6]]
check("circle details: each limit in its unit",
      len(limits) >= 2 and all(re.match(r"≤ [0-9.]+ (µm|µm/m|ms|µrad) (pass|FAIL)$", c)
                               for c in limits)
      and any("µm/m" in c for c in limits), str(limits))
check("circle: then the largest gain", re.search(r"1 Cyclic error X", circle_all) is not None, "")
# One ranking by gain, the same number for an error in both tables: page one numbered its own rows
# 1, 2, 3 (the failing backlash X "1"), the details ranked it 8th. The details' ranks are 1, 2, ...
# down the table, their gains never rising; each of page one's rows has the rank the details give
# the same error.
first_diag = cells(circle_html.split("Details of the results")[0], "num diag")
details_rank = {r[1]: r[0] for r in details_diag}
gains = [float(r[3]) for r in details_diag]
check("circle: the details ranked 1, 2, ... by their gain",
      [r[0] for r in details_diag] == [str(k + 1) for k in range(len(details_diag))]
      and all(a >= b for a, b in zip(gains, gains[1:])), str(details_diag))
check("circle: what to fix first ranks each error as the details do",
      len(first_diag) == 3 and all(
          any(row[1].startswith(name) and row[0] == rank for name, rank in details_rank.items())
          for row in first_diag)
      and any(row[1].startswith("Backlash X") and row[0] != "1" for row in first_diag),
      f"{[r[:2] for r in first_diag]} / {details_rank}")
check("no -0.000 anywhere", all("-0.000" not in p for n in text for p in text[n]), "")
# Documents print µm, °C (the terminal keeps um, degC): no unit word of the terminal in any
# report's text (the run quality, the uncertainty budget's models, the demo's warm-up).
for name in reports:
    body = re.sub(r"<style.*?</style>", "", open(f"{name}.html", encoding="utf-8").read(),
                  flags=re.S)
    words = html_mod.unescape(re.sub(r"<[^>]+>", " ", body))
    found = re.findall(r".{30}\b(?:um|um/m|urad|degC)\b", words)
    check(f"{name}: µm and °C, not um or degC", not found, str(found[:3]))
# The instruments' calibration by their names, once: "role | device | instrument" read
# "air | air | ptu300".
calib = open("linear.html", encoding="utf-8").read()
calib = calib[calib.index("Instruments and calibration"):]
calib = calib[:calib.index("</table>")]
check("instruments and calibration: each by its name, then model",
      [html_mod.unescape(c) for c in re.findall(r"<th>(.*?)</th>", calib)]
      == ["instrument", "model", "serial number", "certificate", "calibration due"]
      and re.findall(r"<tr><td>(.*?)</td><td>", calib) == ["air", "laser", "material"], calib)
# The settings: an appendix with labels and units, no raw keys, no empty values.
lin = " ".join(text["linear"])
# The appendix read from the HTML, label by value (pdftotext may read a two-column table's cells
# out of their rows).
def appendix(name):
    html = open(f"{name}.html", encoding="utf-8").read()
    return {row[0]: row[1] for row in cells(html.split("Appendix: settings of the run")[1], "kv")}


lin_settings = appendix("linear")
check("settings appendix with labels",
      "Appendix: settings of the run" in lin
      and lin_settings.get("Expansion coefficient") == "11.5 ppm/K", str(lin_settings))
check("no raw setting keys", "machine_model.topology" not in lin and "probe_offset_mm" not in lin,
      "")
# Values that are keys, as the reader knows them: the standard's title, the equation's name.
check("settings appendix: the standard and the equation by their names",
      lin_settings.get("Standard") == "ISO 230-2:2014"
      and lin_settings.get("Refractive index equation") == "Ciddor (1996)"
      and "iso230-2:2014" not in lin and "ciddor" not in lin, str(lin_settings))
check("circle settings appendix: the standard by its name, an angle as 360°",
      appendix("circle").get("Standard") == "ISO 230-4:2005"
      and appendix("circle").get("Arc") == "360°", str(appendix("circle")))
# The analysis's notes as sentences; the uncalibrated bar said once, by the Bar calibration section
# (its note, "uncalibrated bar: the radius error is fitted but not reported", stood above it).
circle_words = " ".join(text["circle"])
check("circle: notes as sentences, the uncalibrated bar said once",
      "uncalibrated bar:" not in circle_words and "vibration:" not in circle_words
      and "The radius error is not evaluated" in circle_words, circle_words[-3000:])
check("appendix after the results",
      lin.index("Appendix: settings") > lin.index("Measurement uncertainty"), "")

# --- campaign: the summary on page one, each run's answer on its first page --------------------
camp = text["campaign"]
# The table's head (pdftotext may read its last cell, "verdict", after the first column's rows).
check("campaign: summary on page one", "run date test axis status standard results" in camp[0]
      and re.search(r"\bverdict\b", camp[0].split("run date test axis")[1]) is not None, camp[0])
check("campaign: squareness in µm/m", re.search(r"Squareness XY [+-]?[0-9.]+ µm/m", camp[0])
      is not None, camp[0])
# Every diagnostic in the summary in its own unit: a squareness in µm/m, a servo mismatch in ms,
# never the peak-to-valley in µm under the error's name.
check("campaign: no squareness or servo mismatch in µm",
      re.search(r"(Squareness XY|Servo mismatch \(Y lags X\)) [+-]?[0-9.]+ µm;", camp[0]) is None,
      camp[0])
check("campaign: squareness and scale mismatch in µm/m",
      re.search(r"Squareness XY [+-]?[0-9.]+ µm/m;", camp[0]) is not None
      and re.search(r"Scale mismatch X - Y [+-]?[0-9.]+ µm/m;", camp[0]) is not None, camp[0])
# Every value outside its limit is in the summary, marked: the circle's failing backlash X was left
# out (the summary named the first four diagnostics by their gain in G, and it gains the least).
check("campaign: the failing diagnostic in the summary, marked",
      re.search(r"Backlash X \+[0-9.]+ µm FAIL;", camp[0]) is not None, camp[0])
check("campaign: each run's failing values marked", camp[0].count(" FAIL;") >= 3, camp[0])
for run in (1, 2):
    first = next((p for p in camp if re.search(rf"SIMULATED — Run {run}: \w+ test", p)), "")
    check(f"campaign: run {run}'s verdict and table on its first page",
          "Verdict against the machine specification" in first
          and re.search(r"(↑ up ↓ down bidirectional|symbol and meaning value \(µm\))", first)
          is not None, first[:500])

# --- nothing past the right margin ------------------------------------------------------------
# Each word of each page inside the printed area (A4 less the 14 mm margin on the right): the
# campaign summary's table ran past it (it took the page summary's column widths).
def words_beyond_margin(pdf):
    out = subprocess.run(["pdftotext", "-bbox", pdf, "-"], capture_output=True, text=True,
                         check=True).stdout
    right_pt = (210 - 14) / 25.4 * 72 + 1.0
    return [w for x, w in re.findall(r'<word xMin="[0-9.]+" yMin="[0-9.]+" xMax="([0-9.]+)"'
                                     r'[^>]*>([^<]*)</word>', out) if float(x) > right_pt]


def title_height_pt(pdf):
    """The height of the first word of page one under the running header (which is in the 18 mm
    top margin): the title, 14 pt, about 16 pt from its font's ascent to its descent."""
    out = subprocess.run(["pdftotext", "-bbox", "-f", "1", "-l", "1", pdf, "-"],
                         capture_output=True, text=True, check=True).stdout
    return next(float(y1) - float(y0) for y0, y1 in re.findall(
        r'<word xMin="[0-9.]+" yMin="([0-9.]+)" xMax="[0-9.]+" yMax="([0-9.]+)"', out)
        if float(y0) > 18 / 25.4 * 72)


for name in reports:
    beyond = words_beyond_margin(f"{name}.pdf")
    check(f"{name}: nothing past the right margin", not beyond, str(beyond[:10]))
    # A page too wide is printed shrunk to fit (a circle comparison's table of 17 columns put
    # the whole page at about 5 pt).
    check(f"{name}: printed at full size", title_height_pt(f"{name}.pdf") > 15,
          f"{title_height_pt(name + '.pdf'):.1f} pt")
# --- every plot's legend inside its canvas ---------------------------------------------------
def edge_lines(html):
    """(plot, x) of each line drawn at the left or right edge of a plot's canvas, other than the
    canvas's own background: the legend's box, wider than the plot, ran past the canvas, which
    cut it there (three columns of "x̄↑ ± 2s" under the main plot lost the box's right side;
    "counter-clockwise", "clockwise" under the polar plot both sides)."""
    found = []
    for m in re.finditer(r'<svg[^>]*aria-label="([^"]*)"(.*?)</svg>', html, re.S):
        width = float(re.search(r'viewBox="0 0 ([0-9.]+) ', m.group(0)).group(1))
        for pts in re.findall(r'points="([^"]*)"', m.group(2)):
            xy = [tuple(float(c) for c in p.split(",")) for p in pts.split()]
            xs, ys = [x for x, _ in xy], [y for _, y in xy]
            if min(xs) <= 0.01 and min(ys) <= 0.01:  # the background, the whole canvas
                continue
            found += [(html_mod.unescape(m.group(1)), x) for x in xs
                      if x <= 0.5 or x >= width - 0.5]
    return found


for name in reports:
    edges = edge_lines(open(f"{name}.html", encoding="utf-8").read())
    check(f"{name}: every legend inside its plot", not edges, str(sorted(set(edges))[:6]))


# --- no page left nearly empty before the last ----------------------------------------------
def page_fill(pdf):
    """How far down each page its text reaches, as a share of the page's height, without the
    running header and the footer (in the margins)."""
    out = subprocess.run(["pdftotext", "-bbox", pdf, "-"], capture_output=True, text=True,
                         check=True).stdout
    fills = []
    for _, height, body in re.findall(r'<page width="([0-9.]+)" height="([0-9.]+)">(.*?)</page>',
                                      out, re.S):
        h = float(height)
        ys = [float(y) / h for y in re.findall(r'yMax="([0-9.]+)"', body)]
        fills.append(max([y for y in ys if 0.05 < y < 0.95], default=0.0))
    return fills


# A circle's page one overflowed by the three lines under "What to fix first", and the details'
# page break left them alone on page two.
for name in ("linear", "vdi3441", "suspect", "circle"):
    fills = page_fill(f"{name}.pdf")
    check(f"{name}: no page but the last less than half full",
          len(fills) >= 2 and all(f > 0.5 for f in fills[:-1]),
          " ".join(f"{f:.2f}" for f in fills))
check("circle: the details follow what to fix first on page two",
      "Details of the results" in text["circle"][1], text["circle"][1][:300])

check("as found / as left: each run's report starts on a page of its own",
      "As found: SIMULATED" not in text["asfound"][0], text["asfound"][0][-300:])

# --- comparison and as found / as left --------------------------------------------------------
# Its head and run 1's row: each value marked against its limit, the verdict, air and material
# (pdftotext may read a head's wrapped cells, "M (µm)", apart).
check("comparison: the table on page one", all(w in text["comparison"][0] for w in (
    "run date E (µm)", "R (µm)", "A (µm)", "B (µm)", "B̄ (µm)", "verdict air")) and re.search(
    r"[0-9.]+ ✓ [0-9.]+ ✓ [0-9.]+ ✓ [0-9.]+ ✓ [0-9.]+ ✗ -?[0-9.]+ FAIL [0-9.]+ [0-9.]+",
    text["comparison"][0]) is not None, text["comparison"][0])
# Page one says in words why a comparison fails: which value of which run, against which limit
# (it said so only by the table's ✗). The demo's runs 1 and 3 both fail B (4 µm of backlash
# injected, limit 3 µm); the circle's backlash X (limit 3 µm) with what to check.
c1 = text["comparison"][0]
check("comparison: page one says which value of which run fails, against which limit",
      re.search(r"The newest run, run 3 \([0-9-]+ [0-9:]+\): FAIL — B = 4\.0[0-9]{2} µm \(limit ≤ "
                r"3\.000 µm\)\. Earlier runs outside their specification: 1 of 1 — run 1 \([0-9-]+ "
                r"[0-9:]+\): B = 4\.0[0-9]{2} µm \(limit ≤ 3\.000 µm\)\.", c1) is not None, c1[:1200])
check("circle comparison: the failing backlash X in words, with what to check",
      re.search(r"The newest run, run 2 \([^)]*\): FAIL — Backlash X = \+4\.0[0-9]{2} µm \(limit ≤ "
                r"3\.000 µm\): check the X axis' backlash compensation",
                text["comparison-circle"][0]) is not None, text["comparison-circle"][0][:1200])
a1 = text["asfound"][0]
# Page one keeps room: the table of the values a specification limits (the unidirectional six
# are in each run's report), so a second warning above does not push its verdict row off it.
check("as found / as left: the bidirectional values only, the verdict row on page one",
      "E↑" not in a1 and "B̄ (µm)" in a1 and re.search(r"verdict (-?[0-9.]+ )?FAIL", a1)
      is not None, a1)
import report_checks  # noqa: E402  (its page_fill: page_fill above is this file's own)
af_fill = report_checks.page_fill(*pdf_words("asfound.pdf")[0])
check("as found / as left: page one not full to its last line (< 95 %)", af_fill < 0.95,
      f"{af_fill:.2f}")
check("as found / as left: table and verdicts on page one",
      "as found, run 1" in a1 and "as left, run 3" in a1 and "verdict" in a1, a1)
# Each value with its unit: a circle's table mixed µm, µm/m and ms under a head without any, and
# printed its diagnostics unsigned.
check("as found / as left: the values' unit", "E (µm)" in a1 and "B̄ (µm)" in a1, a1)
daq("report", "--as-found", "2", "--as-left", "2", *db, "-o", "asfound-circle.html")
afc = {row[0]: row[1:] for row in cells(open("asfound-circle.html", encoding="utf-8").read(),
                                        "num results")}
check("as found / as left of a circle: each value in its unit, diagnostics signed",
      re.match(r"[+-][0-9]+\.[0-9]{3}", afc.get("Squareness XY (µm/m)", [""])[0]) is not None
      and "Servo mismatch (Y lags X) (ms)" in afc and "G(b) (µm)" in afc, str(afc)[:800])

# A circle's comparison: its table, then the trends on page one (the polar overlay under the
# table left half of page one empty); a diagnostic with its sign, as every run's own table has it
# (the demo's squareness +20.019 µm/m was printed 20.019).
cc1 = text["comparison-circle"][0]
check("circle comparison: the trends on page one", "Each value over time" in cc1
      and "G(b) (µm)" in cc1, cc1)
check("circle comparison: the polar overlay after the trends",
      " ".join(text["comparison-circle"]).index("Polar plots overlaid")
      > " ".join(text["comparison-circle"]).index("Each value over time"), "")
cc_rows = {row[0]: row[1:] for row in cells(open("comparison-circle.html", encoding="utf-8").read(),
                                            "num")}
square_cells = next((v for k, v in cc_rows.items() if k.startswith("Squareness")), [])
check("circle comparison: squareness signed", len(square_cells) == 2 and all(
    re.match(r"[+-][0-9]+\.[0-9]{3}", c) for c in square_cells), str(cc_rows)[:600])
check("circle comparison: G unsigned",
      all(re.match(r"[0-9]+\.[0-9]{3}", c) for k, v in cc_rows.items() if k.startswith("G")
          for c in v), str(cc_rows)[:600])
# Every limited value has its small plot (ten are drawn): the failing backlash X, ranked last of
# the diagnostics, was left out.
cc_html = open("comparison-circle.html", encoding="utf-8").read()
cc_plots = re.findall(r'<svg[^>]*aria-label="([^"]*)"', cc_html[cc_html.index(
    '<div class="multiples">'):])
check("circle comparison: the failing backlash X over time",
      any(t.startswith("Backlash X") for t in cc_plots), str(cc_plots))
comparison_html = open("comparison.html", encoding="utf-8").read()
# The date cell breaks between the day and the time, never inside one ("11-" over "28").
check("comparison: the dates unbroken", re.search(r'<td[^>]*><span class="nw">[0-9]{2}-[0-9]{2}'
                                                  r'</span> <span class="nw">[0-9]{2}:[0-9]{2}'
                                                  r'</span></td>', comparison_html) is not None,
      re.findall(r"<tr>.{0,200}", comparison_html)[1][:200])
check("comparison: the trends' minimum span is stated", "Each y axis spans at least" in
      comparison_html, "")
# The small multiples' labels under x (the runs) do not overlap: centred texts other than the
# title and the markers, at least half a character height per character apart from centre to
# centre on each side.
multiples = comparison_html[comparison_html.index('<div class="multiples">'):]
for m in re.finditer(r'<svg[^>]*aria-label="([^"]*)"(.*?)</svg>', multiples, re.S):
    title, body = html_mod.unescape(m.group(1)), m.group(2)
    labels = []
    for t in re.finditer(r'<text([^>]*)>(.*?)</text>', body, re.S):
        words = html_mod.unescape(re.sub(r"<[^>]+>", "", t.group(2))).strip()
        if 'text-anchor="middle"' not in t.group(1) or words in ("•", "", title):
            continue
        x = float(re.search(r"matrix\(([^)]*)\)", t.group(1)).group(1).split()[4])
        labels.append((x, float(re.search(r'font-size="([0-9.]+)"', t.group(1)).group(1)), words))
    labels.sort()
    overlap = [(a[2], b[2]) for a, b in zip(labels, labels[1:])
               if b[0] - a[0] < 0.25 * a[1] * len(a[2]) + 0.25 * b[1] * len(b[2])]
    check(f"comparison: '{title}' labels apart", len(labels) >= 2 and not overlap,
          f"{labels} overlap: {overlap}")

# --- traceability gaps: a missing certificate or due date warns on page one, not only a past one
shutil.copy("demo.sqlite", "gaps.sqlite")
con = sqlite3.connect("gaps.sqlite")
settings = json.loads(con.execute("SELECT settings_json FROM runs WHERE id = 1").fetchone()[0])
laser = next(i for i in settings["context"]["instruments"] if i["role"] == "laser")
laser.pop("certificate")
laser["calibration_due"] = ""
con.execute("UPDATE runs SET settings_json = ? WHERE id = 1", (json.dumps(settings),))
con.commit()
con.close()
daq("report", "1", "--db", "gaps.sqlite", "--format", "pdf", "-o", "gaps.pdf")
g1 = squash(pages("gaps.pdf")[0])
check("traceability: a missing certificate and due date warned on page one",
      "Traceability: laser: no certificate or calibration due date stated" in g1, g1[:1500])

# --- instruments configured under ids other than their roles ([devices.ids] with role "laser",
# [devices.table] with role "material"): a run stores each under its role, and the legends found
# no configured instrument by that name ("air sensor of laser laser", "material sensor material").
# By the role now, with the configured id and serial number; the Instruments table too.
shutil.copy("demo.sqlite", "ids.sqlite")
con = sqlite3.connect("ids.sqlite")
settings = json.loads(con.execute("SELECT settings_json FROM runs WHERE id = 1").fetchone()[0])
renamed = {"laser": "ids", "material": "table"}
for i in settings["context"]["instruments"]:
    i["id"] = renamed.get(i["role"], i["id"])
con.execute("UPDATE runs SET settings_json = ? WHERE id = 1", (json.dumps(settings),))
con.commit()
con.close()
daq("report", "1", "--db", "ids.sqlite", "-o", "ids.html")
ids_page = open("ids.html", encoding="utf-8").read()
ids_plots = [html_mod.unescape(t) for t in re.findall(r"<tspan[^>]*>(.*?)</tspan>", ids_page)]
ids_rows = [[html_mod.unescape(re.sub(r"<[^>]+>", "", c)) for c in re.findall(r"<td[^>]*>(.*?)</td>", r)]
            for r in re.findall(r"<tr>(.*?)</tr>", ids_page.split("<h4>Instruments</h4>")[-1].split("</table>")[0])]
check("configured ids: the legends name each instrument by its role, id and serial number",
      "air sensor of laser ids IDS3010 (serial SIM-IDS-0001)" in ids_plots
      and "material sensor table (serial SIM-TH-0001)" in ids_plots
      and not any(re.search(r"\b(laser laser|material material)\b", t) for t in ids_plots),
      str([t for t in ids_plots if "sensor" in t]))
check("configured ids: the Instruments table gives the configured model and serial number",
      ["laser", "ids3010 SIM-IDS-0001"] in [r[:2] for r in ids_rows]
      and ["material", "gauge SIM-TH-0001"] in [r[:2] for r in ids_rows], str(ids_rows))

# Past-due calibrations of runs of different days in one warning, each instrument with its due
# date: the demo's thermometer (due 2020-01-31) in runs 1 and 3, run 3 a day later, and in run 1
# a laser due 2021-06-30 too. Before, a line per run and date: "material was past due on the
# test date (2020-01-31 < DAY 1)", the same again for day 2, and one more for the laser.
shutil.copy("demo.sqlite", "late.sqlite")
con = sqlite3.connect("late.sqlite")
settings = json.loads(con.execute("SELECT settings_json FROM runs WHERE id = 1").fetchone()[0])
next(i for i in settings["context"]["instruments"]
     if i["role"] == "laser")["calibration_due"] = "2021-06-30"
con.execute("UPDATE runs SET settings_json = ? WHERE id = 1", (json.dumps(settings),))
con.execute("UPDATE runs SET started_unix_ms = started_unix_ms + 86400000, "
            "ended_unix_ms = ended_unix_ms + 86400000 WHERE id = 3")
day1, day2 = [time.strftime("%Y-%m-%d", time.gmtime(ms / 1000)) for (ms,) in con.execute(
    "SELECT started_unix_ms FROM runs WHERE id IN (1, 3) ORDER BY id")]
con.commit()
con.close()
for args in (["--compare", "1", "3"], ["--as-found", "1", "--as-left", "3"]):
    daq("report", *args, "--db", "late.sqlite", "--format", "pdf", "-o", "late.pdf")
    l1 = squash(pages("late.pdf")[0])
    check(f"traceability ({args[0]}): past-due calibrations of two days in one warning",
          f"Traceability: the calibrations of laser (due 2021-06-30, run 1) and material (due "
          f"2020-01-31) were past due on the test dates ({day1} and {day2}): their readings are "
          f"not traceable to a valid certificate." in l1 and l1.count("past due") == 1, l1[:1500])

# --- other runs (an imported .rtx): the plots name the quantity and its unit, not its key -------
with open("lin.rtx", "wb") as f:
    f.write(b"HEADER::\r\nOwner: CARTO-Dynamic\r\nVersion no: 4.13\r\nSerial No: XL-8123\r\nFile Type: Linear\r\n"
            b"Sample rate: 50000\r\nSample no: 3\r\nActual sample rate: 1000\r\nAxis: X\r\n"
            b"Data:\r\n" + b"\x00" * 6 + b"\xf0\x3f" + b"\x00" * 6 + b"\x04\xc0" + b"\x00" * 8
            + b"\r\nEOF::\r\n")
imported = re.search(r"run (\d+)", daq("import", "rtx", "lin.rtx", *db)).group(1)
daq("report", imported, *db, "-o", "imported.html")
imported_plot = " ".join(html_mod.unescape(t) for t in re.findall(
    r"<tspan[^>]*>(.*?)</tspan>", open("imported.html", encoding="utf-8").read()))
# In mm (the run moves metres: 1 m, -2.5 m, 0), not in m with a "x10^3" at the axis.
check("imported run: the plot says displacement (mm), not displacement_m or (m)",
      "displacement (mm)" in imported_plot and "displacement_m" not in imported_plot
      and "displacement (m)" not in imported_plot
      and " ch 0" not in imported_plot, imported_plot[:300])
# Its three samples 1 ms apart on a time axis in ms, ticked to 2.0 (it was in minutes, ticked
# 0.00000 to 3.00000 "(x10⁻⁵)").
check("imported run: 2 ms of samples on a time axis in ms, in plain numbers",
      "time (ms)" in imported_plot and " 2.0 " in imported_plot and "x10" not in imported_plot
      and "time (min)" not in imported_plot, imported_plot[:300])
# Its legend names the file's instrument once, with the serial number its header states (it
# read "renishaw-rtx (CARTO-Dynamic 4.13) renishaw-rtx (CARTO-Dynamic 4.13)").
instrument = "renishaw-rtx (CARTO-Dynamic 4.13)"
check("imported run: the legend names the file's instrument once, with its serial number",
      f"{instrument} (serial XL-8123)" in imported_plot and f"{instrument} {instrument}" not in imported_plot,
      imported_plot[-200:])
# Made without a configuration: the report says what the file states (the serial number, no
# calibration), not "give serial_number ... in the configuration".
imported_text = html_mod.unescape(re.sub(r"<[^>]+>", "", open("imported.html", encoding="utf-8").read()))
said = (f"the readings of {instrument} were imported from Renishaw .rtx file lin.rtx (the file does "
        "not say whether the instrument was real), which states the serial number XL-8123 but no "
        "certificate or calibration due date.")
# The Instruments table: the serial number the file states where the model and serial number
# go (the cell was blank, as if the data were missing).
instruments_row = re.search(r"<h4>Instruments</h4>.*?<tr><td>([^<]*)</td><td>(.*?)</td>",
                            open("imported.html", encoding="utf-8").read(), re.S)
check("imported run: the Instruments table gives the file's serial number, no blank cell",
      instruments_row is not None and instruments_row.group(1) == html_mod.escape(instrument)
      and instruments_row.group(2) == 'serial XL-8123 <span class="unstated">(model not stated)</span>',
      str(instruments_row and instruments_row.groups()))
check("imported run: page one and Instruments say what the file states of its instrument",
      f"Traceability: {said}" in imported_text and "The" + said[3:] in imported_text
      and "give serial_number" not in imported_text,
      str(re.findall(r"Traceability:[^\n]*|The (?:readings|instruments)[^\n]*", imported_text)[:3]))

# --- straightness and squareness: signed values through the shared formatter -----------------
# Two profiles whose slopes differ by 1e-7 µm/m: the squareness printed "-0.000".
with open("a.csv", "w") as f:
    f.write("position_mm,deviation_um\n" + "".join(f"{x},0\n" for x in range(0, 500, 100)))
with open("b.csv", "w") as f:
    f.write("position_mm,deviation_um\n" + "".join(f"{x},{-1e-10 * x}\n" for x in range(0, 500, 100)))
daq("analyse", "squareness", "-m", "straightness", "--along-a", "a.csv", "--along-b", "b.csv",
    "--report", "square.html")
square = html_mod.unescape(re.sub(r"<[^>]+>", " ", open("square.html", encoding="utf-8").read()))
check("squareness report: no -0.000 or +0.000", "-0.000" not in square and "+0.000" not in square,
      str(re.findall(r".{40}[+-]0\.000.{20}", square)[:3]))

# --- plots: text of at least 9 pt as printed --------------------------------------------------
# Printed widths (pt): A4 less the 14 mm margins is 516 pt; a polar plot 72 % of it, a small
# multiple half of it less the gap.
content_pt = (210 - 28) / 25.4 * 72
MARKS = ("", "•", "▲", "▽", "■", "□", "◆", "◇", "●", "○")
for name in reports:
    html = open(f"{name}.html", encoding="utf-8").read()
    for m in re.finditer(r"<svg class=\"([^\"]*)\"[^>]*aria-label=\"([^\"]*)\"[^>]*viewBox=\"0 0 "
                         r"(\d+) (\d+)\"", html):
        cls, title, width = m.group(1), m.group(2), float(m.group(3))
        end = html.find("</svg>", m.end())
        # Each text's size, but not the markers (PLplot draws a data point as a "•" glyph, a
        # run-by-run plot's as triangles, also beside each legend entry's line).
        sizes = [float(size) for size, text in re.findall(
            r'font-size="([0-9.]+)"[^<]*(?:<[^t][^>]*>[^<]*)*?<tspan[^>]*>(.*?)</tspan>',
            html[m.end():end]) if html_mod.unescape(text).strip() not in MARKS]
        if not sizes:
            continue
        inside_multiples = html.rfind('<div class="multiples">', 0, m.start()) > html.rfind(
            "</div>", 0, m.start())
        # A plot beside a table (class "pair"): half of the page less the gap (1 rem, 10 pt).
        inside_pair = html.rfind('<div class="pair">', 0, m.start()) > html.rfind(
            "</figure></div>", 0, m.start())
        shown = ((content_pt - 10) / 2 if inside_pair else content_pt * 0.72 if "polar" in cls
                 else 0.48 * content_pt if inside_multiples else content_pt)
        printed = min(sizes) * min(1.0, shown / width)
        check(f"{name}: plot '{title}' text >= 9 pt", printed >= 9.0,
              f"{printed:.1f} pt (font {min(sizes)} in a {width:.0f} wide plot shown {shown:.0f} pt)")
    # Legends name the instrument (driver and serial number), not "air air ch 0".
    plot_text = " ".join(html_mod.unescape(t) for t in re.findall(r"<tspan[^>]*>(.*?)</tspan>",
                                                                  html))
    check(f"{name}: no 'air air ch' legend", " ch 0" not in plot_text, "")
    # ... by its role, product and serial number as an engineer reads them ("air: ids3010" named
    # neither the laser nor its sensor).
    if "Temperatures" in html:
        check(f"{name}: legends name the instrument",
              "air sensor PTU300 (serial SIM-PTU-0001)" in plot_text
              and "material sensor (serial SIM-TH-0001)" in plot_text, plot_text[:600])
        check(f"{name}: no legend by a driver's key", re.search(
            r"(air|material): |\b(ids3010|ptu300)\b", plot_text) is None, plot_text[:600])

# --- straightness, angular and roll runs: page one is their ISO 230-1 answer ------------------
# One run of each on the volumetric shop, acquired by `daq sim --measure --acquire` in its own
# process on simulated time (the same readings on a loaded machine; run live at --speed 10 beside
# `daq run`, a starved process missed a stop); the straightness judged by a limit given with
# --tolerances, the roll by another, the angular run by none. Their reports showed only the raw
# readings against time.
def measure(component, tolerances=""):
    """One run of a component acquired on the simulated volumetric shop; its number and output."""
    limits = []
    if tolerances:
        with open(f"tol-{component}.toml", "w", encoding="utf-8") as f:
            f.write(tolerances)
        limits = ["--tolerances", f"tol-{component}.toml"]
    out = daq("sim", "--measure", component, "--topology", "YFXZ", "--acquire", *limits, *db,
              "-o", f"m-{component}.toml")
    return re.search(r"run (\d+) stored", out).group(1), out


# The injected truth: each error a polynomial of the position along X (um or urad), measured at 6
# targets over the travel (daq/src/sim/sim_volumetric.cpp). The angular deviation is the range of
# the means; the straightness is not compared here (the indicator 100 mm below the spindle also
# reads the roll and pitch through that offset: the model build accounts for it).
daq("sim", "--truth-out", "truth.json", "--topology", "YFXZ")
truth = json.load(open("truth.json", encoding="utf-8"))


def truth_range(component):
    coefficients = truth["components"][component]["polynomial"]
    last_mm = truth["travel_mm"]["X"][1]
    values = [sum(c * (last_mm * k / 5) ** i for i, c in enumerate(coefficients))
              for k in range(6)]
    return max(values) - min(values)


profile_runs = {
    "straightness": measure("E_YX", "[tolerances.X]\nstraightness_um = 0.1\n"),
    "angular": measure("E_BX"),
    "roll": measure("E_AX", "[tolerances.X]\nangular_urad = 1000\n"),
}
for kind, (run, run_out) in profile_runs.items():
    daq("report", run, *db, "--format", "pdf", "-o", f"{kind}.pdf")
    daq("report", run, *db, "-o", f"{kind}.html")
    p = [squash(x) for x in pages(f"{kind}.pdf")]
    p1 = p[0]
    component = {"straightness": "E_YX", "angular": "E_BX", "roll": "E_AX"}[kind]
    check(f"{kind}: the ISO 230-1 results on page one",
          re.search(rf"Results: (straightness|angular deviation) {component} Evaluated by ISO "
                    r"230-1:2012", p1) is not None, p1[:1500])
    # (pdftotext may read the head's cells between the first row's)
    check(f"{kind}: the values table on page one",
          all(w in p1 for w in ("symbol", "value", "meaning", "limit", "verdict")), p1)
    title = "Straightness E_YX along the axis" if kind == "straightness" else (
        f"Angular {component} along the axis")
    check(f"{kind}: the deviation plot on page one", title in " ".join(
        html_mod.unescape(t) for t in re.findall(r"<tspan[^>]*>(.*?)</tspan>", open(
            f"{kind}.html", encoding="utf-8").read())) and "mean of the stops" in p1, p1)
    # The numbers: the report's table, daq show --json (the stored result), daq analyse --json
    # (evaluated again from the stops) and the terminal of daq show and daq run are one.
    doc = json.loads(daq("show", run, *db, "--json"))
    stored = current(doc)
    analysed = json.loads(daq("analyse", run, *db, "--json"))
    report_values = [row[1].split(" ")[0] for row in cells(open(f"{kind}.html",
                                                                encoding="utf-8").read(),
                                                           "num results profile")]
    three = lambda x: "0.000" if f"{x:.3f}" == "-0.000" else f"{x:.3f}"  # noqa: E731
    json_values = [(f"{v['value']:+.3f}" if v["key"] == "slope_um_per_m" else three(v["value"]))
                   for v in stored["result"]["values"]]
    check(f"{kind}: the report's values as daq show --json", report_values == json_values
          and len(json_values) >= 1, f"{report_values} / {json_values}")
    check(f"{kind}: daq analyse --json as daq show --json",
          [three(v["value"]) for v in analysed["values"]]
          == [three(v["value"]) for v in stored["result"]["values"]], str(analysed)[:500])
    if kind != "straightness":  # the injected range (10.5 urad of E_BX, 6 urad of E_AX)
        check(f"{kind}: {component} as injected", abs(stored["result"]["values"][0]["value"]
                                                    - truth_range(component)) < 0.1,
              f"{stored['result']['values'][0]} / injected {truth_range(component):.3f}")
    show_text = daq("show", run, *db)
    check(f"{kind}: daq show prints the values", all(v in show_text for v in json_values)
          and "0 runs per direction" not in show_text, show_text)
    check(f"{kind}: daq run printed the same values", all(v in run_out for v in json_values),
          run_out[-800:])
    verdict = stored["verdict"]
    if kind == "straightness":  # about 0.4 um against 0.1 um
        check("straightness: judged against straightness_um, failing value named",
              re.search(r"FAIL.*E_YX = [0-9.]+ µm \(limit ≤ 0\.100 µm\)", p1) is not None
              and verdict["summary"] == "FAIL" and analysed["verdict"]["summary"] == "FAIL", p1)
    elif kind == "roll":
        check("roll: judged against angular_urad", "PASS" in p1 and verdict["summary"] == "PASS"
              # (pdftotext may read the head's cells between the symbol and its value)
              and re.search(r"E_AX (meaning limit )?[0-9.]+ µrad angular deviation.* "
                            r"≤ 1000\.000 µrad pass", p1)
              is not None, f"verdict {verdict['summary']}: " + p1[p1.find("Results:"):])
    else:
        check("angular: no tolerance stated, and where it would be",
              "No tolerance configured" in p1 and "angular_urad under [tolerances.X]" in p1
              and verdict["summary"] == "no tolerance configured", p1)
    # The details follow the plot on page one (after a page break, page one of the angular run
    # was 70 % full, the roll's 66 %, the per-target table alone on page two).
    fills = [report_checks.page_fill(*x) for x in pdf_words(f"{kind}.pdf")]
    check(f"{kind}: the details begin on page one, filled to >= 85 %",
          "Details of the results" in p1 and fills[0] >= 0.85, f"{fills}")
    # The positioning cycle's standard by its title, said to be the cycle's only (the appendix
    # read "iso230-2:2014", a key, of a run evaluated by ISO 230-1).
    standard = appendix(kind).get("Standard", "")
    check(f"{kind}: the appendix's standard by its title, the cycle's",
          standard.startswith("ISO 230-2:2014 (its targets and cycle; the result is evaluated by "
                              "ISO 230-1:2012)"), standard)
    check(f"{kind}: nothing past the right margin", not words_beyond_margin(f"{kind}.pdf"), "")
    html_text = open(f"{kind}.html", encoding="utf-8").read()
    check(f"{kind}: every legend inside its plot", not edge_lines(html_text),
          str(edge_lines(html_text)[:4]))
    if kind == "straightness":
        # The instruments by name, model and connection: the acquisition's device numbers
        # (0, 1, 2, 4: the unused device 3 a gap) meant nothing to the reader.
        inst = html_text[html_text.index("<h4>Instruments</h4>"):]
        inst = inst[:inst.index("</table>")]
        head = [html_mod.unescape(re.sub(r"<[^>]+>", "", c)) for c in
                re.findall(r"<th>(.*?)</th>", inst)]
        first = [re.sub(r"<[^>]+>", "", c) for c in re.findall(r"<tr><td>(.*?)</td>", inst)]
        check("straightness: the instruments by name, not device number",
              head == ["instrument", "model and serial number", "connection"]
              and first == ["laser", "air", "material", "indicator"], f"{head} {first}")
        # The same gaps of several instruments in one warning, in words ("or", not a list).
        check("straightness: one traceability warning for the instruments lacking the same",
              re.search(r"Traceability: (\w+, ){3}\w+: no serial number, certificate or "
                        r"calibration due date stated\.", p1) is not None
              and p1.count("Traceability:") == 1, p1[:1200])

print(f"{fails} failed" if fails else "all passed")
sys.exit(1 if fails else 0)
