#!/usr/bin/env python3
"""Issue 30, the pages a calibration customer reads after a volumetric campaign: the 21-error
campaign report (18 runs of the simulated shop on simulated time), the model map and its
compensation (`daq model map --report`, `daq model compensate --report`) and as found / as
left (linear and circle). Each check is a defect seen in those pages printed by Chromium:
- the campaign's page one said nothing of the simulated origin (only its name did);
- a run's readings plots had a legend repeating the title ("laser displacement (mm)"), not the
  instrument;
- legends wider than the plot lost their frame's right edge (the temperature plot);
- the model page began with the model's 21 sources, the answer on page four; the sources were
  key dumps ("probe_offset_mm: 0.0, 0.0, -100.0; run_id: 3"); the residual after a compensation
  was drawn magnified 1e+08 times (rounding noise shown as a distorted grid); no page numbers;
- as found / as left had no origin, customer or verdict line on page one, and a circle's polar
  plot fell to page two.
Usage: campaign_pages_test.py DAQ_BINARY"""
import html as html_mod
import os
import re
import shutil
import sqlite3
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from report_checks import check, finish, pdf_pages, pdf_words, runner  # noqa: E402

daq = runner(os.path.abspath(sys.argv[1]))


def chromium_pdf(html_file, pdf):
    """Prints an HTML file as `daq report --format pdf` does (a report written by another
    command, e.g. model map --report)."""
    browser = os.environ.get("CALDAQ_CHROMIUM") or shutil.which("chromium")
    profile = tempfile.mkdtemp(prefix="profile.")
    subprocess.run([browser, "--headless", "--no-sandbox", "--disable-gpu",
                    "--no-pdf-header-footer", f"--user-data-dir={profile}",
                    f"--print-to-pdf={os.path.abspath(pdf)}",
                    "file://" + os.path.abspath(html_file)],
                   capture_output=True, timeout=180, check=True)
    shutil.rmtree(profile, ignore_errors=True)


def svg_text(svg):
    """The text PLplot wrote in an SVG (each character a reference)."""
    return html_mod.unescape(" ".join(re.findall(r"<tspan[^>]*>(.*?)</tspan>", svg, re.S)))


def rightmost(svg):
    """The largest x drawn (a clip path, the whole canvas, is not drawn) and the width."""
    width = float(re.search(r'viewBox="0 0 ([0-9.]+) ', svg).group(1))
    drawn = re.sub(r"<clipPath.*?</clipPath>", "", svg, flags=re.S)
    xs = [float(xy.split(",")[0]) for pts in re.findall(r'points="([^"]*)"', drawn)
          for xy in pts.split()]
    return max(xs, default=0.0), width


work = tempfile.mkdtemp(prefix="campaign_pages.")
os.chdir(work)
db = ["--db", "vol.sqlite"]
for c in ["E_BX", "E_CX", "E_AX", "E_AY", "E_CY", "E_BY", "E_AZ", "E_BZ", "E_CZ",
          "E_XX", "E_YX", "E_ZX", "E_YY", "E_XY", "E_ZY", "E_ZZ", "E_XZ", "E_YZ"]:
    daq("sim", "--measure", c, "--topology", "YFXZ", "--acquire", *db, "-o", "sim.toml")
daq("sim", "--measure", "E_XX", "--topology", "YFXZ", "--acquire", *db, "-o", "sim.toml")  # 19
daq("model", "build", "--machine", "SIMULATED YFXZ", *db, "-o", "built.json",
    "--tool-offset-mm", "0", "0", "-100")
# Renamed as a customer's campaign on a customer's machine: the origin is stored, not named.
con = sqlite3.connect("vol.sqlite")
con.execute("UPDATE machines SET name = 'Customer Mill 7'")
con.execute("UPDATE runs SET campaign = 'annual calibration'")
con.commit()
con.close()

# --- the campaign ----------------------------------------------------------------------------
daq("report", "--campaign", "annual calibration", *db, "-o", "campaign.html")
camp = open("campaign.html", encoding="utf-8").read()
daq("report", "--campaign", "annual calibration", *db, "-f", "pdf", "-o", "campaign.pdf")
one = pdf_pages("campaign.pdf")[0]
check("campaign: page one says SIMULATED for all its runs",
      "SIMULATED: all 19 runs of this report were made on the simulated machine" in one
      and "SIMULATED — Campaign annual calibration" in one, one[:400])
# Issue 30: the runs' traceability gaps (the simulated instruments state no serial number,
# certificate or due date) warned on page one, as a single run's report does: each gap that a
# run's section warns of is on page one, once, with the runs it concerns when not all of them.
# Before, only each run's section, pages later, said so.
head, _, runs_part = camp.partition('<h2 class="run"')
in_runs = set(re.findall(r'<p class="warning">Traceability: ([^<]*)</p>', runs_part))
on_top = re.findall(r'<p class="warning">Traceability(?: \(runs? [0-9, ]+\))?: ([^<]*)</p>',
                    head)
check("campaign: each run's traceability gap warned on page one, once",
      in_runs and set(on_top) == in_runs and len(on_top) == len(in_runs), (in_runs, on_top))
check("campaign: the traceability warning printed on page one",
      re.search(r"Traceability(?: \(runs? [0-9, ]+\))?: .* no serial number, certificate or "
                r"calibration due date stated", one) is not None, one[:1200])
# Page one sums up the 21 errors: each name with its value and unit on its line (read from the
# PDF's words: the two halves of the summary stand side by side). Units: a translation in µm, an
# angle (angular, roll, squareness) in µrad.
words, _ = pdf_words("campaign.pdf")[0]
daq("sim", "--truth-out", "truth.json", "--topology", "YFXZ")
truth = __import__("json").load(open("truth.json", encoding="utf-8"))
found = {}
for w in words:
    if re.fullmatch(r"E_[XYZABC]0?[XYZ]", w[4]):
        line = sorted((x for x in words if abs(x[1] - w[1]) < 3 and x[0] > w[2]), key=lambda x: x[0])
        texts = [x[4] for x in line]
        for i, t in enumerate(texts[:-1]):
            if re.fullmatch(r"[+−-]?\d+\.\d{3}", t) and texts[i + 1] in ("µm", "µrad"):
                found.setdefault(w[4], (float(t.replace("−", "-")), texts[i + 1]))
                break
names = [a + b for b in "XYZ" for a in ("E_X", "E_Y", "E_Z", "E_A", "E_B", "E_C")]
expected_unit = {n: "µrad" if n[2] in "ABC" else "µm" for n in names}
expected_unit.update({"E_C0Y": "µrad", "E_B0Z": "µrad", "E_A0Z": "µrad"})
# Each error's name on one line, whole, before its value: "E_XZ straightness in" over "X" in
# the right half (the words between the symbol and the value on the symbol's line).
def kind_words(n):
    if n[3] == "0":
        return ["squareness", {"E_C0Y": "XY", "E_B0Z": "XZ", "E_A0Z": "YZ"}[n]]
    if n[2] == n[3]:
        return ["positioning"]
    if n[2] in "ABC":
        return ["roll" if "ABC".index(n[2]) == "XYZ".index(n[3]) else "angular"]
    return ["straightness"]


named = {}
for w in words:
    if re.fullmatch(r"E_[XYZABC]0?[XYZ]", w[4]):
        line = sorted((x for x in words if abs(x[1] - w[1]) < 3 and x[0] > w[2]),
                      key=lambda x: x[0])
        texts = [x[4] for x in line]
        value = next((i for i, t in enumerate(texts) if re.fullmatch(r"[+−-]?\d+\.\d{3}", t)),
                     len(texts))
        named.setdefault(w[4], texts[:value])
check("campaign: each of the 21 errors named whole on its line",
      len(named) == 21 and all(named[n][:len(kind_words(n))] == kind_words(n)
                               and len(named[n]) <= len(kind_words(n)) for n in named),
      {n: (named[n], kind_words(n)) for n in named if named[n] != kind_words(n)})
check("campaign: page one names all 21 errors, each with its value in its unit",
      "The 21 geometric errors (ISO 230-1): 21 of 21 measured" in one
      and {n: u for n, (_, u) in found.items()} == expected_unit, (sorted(found), found))
# The squareness from the straightness pairs against the injected truth (urad; the straightness
# runs' noise and the Abbe terms removed leave a few hundredths).
for n in ("E_C0Y", "E_B0Z", "E_A0Z"):
    check(f"campaign: {n} as injected", n in found
          and abs(found[n][0] - truth["squareness"][n]["iso230_1_urad"]) < 0.2,
          (found.get(n), truth["squareness"][n]))
svgs = re.findall(r"<svg.*?</svg>", camp, re.S)
readings = [s for s in svgs if 'aria-label="laser displacement (mm)' in s]
check("campaign: each laser's readings plot names the instrument in its legend",
      len(readings) >= 18 and all("laser IDS3010" in svg_text(s) for s in readings),
      [svg_text(s) for s in readings[:2]])
cut = [(rightmost(s), re.search(r'aria-label="([^"]*)"', s).group(1)) for s in svgs]
cut = [c for c in cut if c[0][0] > c[0][1] - 1.0]
check(f"campaign: no plot drawn up to its right edge (a legend cut off), of {len(svgs)}",
      len(svgs) > 100 and not cut, cut[:5])

# --- as found / as left -----------------------------------------------------------------------
daq("report", "--as-found", "10", "--as-left", "19", *db, "-f", "pdf", "-o", "asfound.pdf")
one = pdf_pages("asfound.pdf")[0]
check("as found / as left: page one says SIMULATED, who and what",
      "SIMULATED: both runs of this report were made on the simulated" in one and "Customer" in one
      and "Positioning test (ISO 230-2), axis X" in one, one[:500])
check("as found / as left: each run's verdict on page one, before the table",
      0 <= one.find("As found (run 10):") < one.find("As left (run 19):")
      < one.find("as found, run 10"), one[:900])
check("as found / as left: the plot on page one",
      "Mean bidirectional deviation, as found and as left" in one, one)
daq("sim", "--test", "circle", "--acquire", *db, "-o", "circle.toml")  # run 20
daq("report", "--as-found", "20", "--as-left", "20", *db, "-f", "pdf", "-o", "circle.pdf")
one = pdf_pages("circle.pdf")[0]
check("as found / as left, circle: the polar plot and the table on page one",
      "as left cw" in one and "rings every" in one and "G(b)" in one
      and "Squareness XY" in one, one)

# --- the model map ----------------------------------------------------------------------------
daq("model", "map", "built.json", "--report", "map.html")
page = open("map.html", encoding="utf-8").read()
chromium_pdf("map.html", "map.pdf")
text = pdf_pages("map.pdf")
check("model map: page one is the answer (the error over the grid, the ranking)",
      "largest |e|" in text[0] and "Contributions, ranked" in text[0]
      and "Appendix: the model" not in text[0], text[0][:600])
check("model map: the model is the appendix",
      page.find("<h2>Volumetric error</h2>") < page.find("Appendix: the model"), "")
check("model map: each source in words, no key dump",
      "run 3 (roll, " in page and "probe_offset_mm:" not in page and "run_id:" not in page
      and "stationary axes at (200, 240, 180) mm" in page,
      re.findall(r"<td>([^<]*run[^<]*)</td>", page)[:3])
check("model map: page numbers", "page 1 of " in text[0], text[0][-200:])
daq("model", "compensate", "built.json", "-f", "isg-volumetric", "--interval-mm", "50", "50",
    "50", "--output-dir", "volc", "--report", "comp.html")
comp = open("comp.html", encoding="utf-8").read()
chromium_pdf("comp.html", "comp.pdf")
one = pdf_pages("comp.pdf")[0]
check("model compensate: the residual beside the model's error on page one",
      "the model after the compensation" in one and "largest |e|" in one, one[:600])
mags = re.findall(r"(?:with error|residual) x([0-9.e+]+)", " ".join(
    svg_text(s) for s in re.findall(r"<svg.*?</svg>", comp, re.S)))
check("model compensate: the residual drawn at the model's scale (no 1e+08 magnification)",
      len(mags) == 6 and len(set(mags)) == 1, mags)

shutil.rmtree(work, ignore_errors=True)
finish()
