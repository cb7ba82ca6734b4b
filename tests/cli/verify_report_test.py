#!/usr/bin/env python3
"""The compensation loop's report (`daq report --verify RUN`), built on the simulated shop: an
E_YX straightness run as found, a SINUMERIK CEC table written from it (`daq compensate --run`),
then the simulated control loading that table as Siemens' text reads (as predicted) and with
the other sign (--control-inverted, the injected fault). Each report is checked against that
truth: its finding and verdict, its sign/units/reference-point rows, and its numbers point by
point (as left = as found + the table's change when applied as written; as found − that change
when inverted: the error about twice as large), the same largest deviations `daq verify --json`
prints, the plot and the verdict on page one of the PDF, the table's file name escaped.
Usage: verify_report_test.py DAQ_BINARY"""
import html as html_mod
import json
import os
import re
import shutil
import sqlite3
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from report_checks import check, finish, pdf_pages, runner  # noqa: E402

daq = runner(os.path.abspath(sys.argv[1]))


work = tempfile.mkdtemp(prefix="verify_report.")
os.chdir(work)
db = ["--db", "loop.sqlite"]


def sim(*extra):
    return daq("sim", "--measure", "E_YX", "--topology", "YFXZ", "--acquire", *db, "-o", "m.toml",
               *extra)


sim()  # run 1: E_YX as found
daq("compensate", "--run", "1", *db, "-f", "siemens-cec", "--start-mm", "0", "--interval-mm",
    "100", "--points", "6", "-o", "cec.mpf")  # compensation 1
sim("--control-table", "cec.mpf", "--control-format", "siemens-cec")  # run 2: as Siemens reads
sim("--control-table", "cec.mpf", "--control-format", "siemens-cec",
    "--control-inverted")  # run 3: the other sign (the injected fault)


def cells(row):
    return [html_mod.unescape(re.sub(r"<[^>]+>", "", c)).strip()
            for c in re.findall(r"<td[^>]*>(.*?)</td>", row, re.S)]


def points(page):
    """The point-by-point table: (target, direction, as found, expected change, expected as left,
    as left, measured change, measured - expected) as numbers."""
    table = page[page.index("measured − expected (µm)"):]
    table = table[:table.index("</table>")]
    out = []
    for row in re.findall(r"<tr>(.*?)</tr>", table, re.S):
        c = cells(row)
        if len(c) == 8:
            out.append([float(c[0]), c[1]] + [float(x.replace("−", "-")) for x in c[2:]])
    return out


def kv(page, label):
    m = re.search(r"<td>" + re.escape(label) + r"</td><td[^>]*>(.*?)</td>", page, re.S)
    return html_mod.unescape(re.sub(r"<[^>]+>", "", m.group(1))).strip() if m else None


reports = {}
for run in ("2", "3"):
    out = json.loads(daq("report", "--verify", run, *db, "-o", f"verify-{run}.html", "--json"))
    check(f"run {run}: the report says what it is", out["kind"] == "verification"
          and out["runs"] == [int(run)], out)
    reports[run] = open(f"verify-{run}.html", encoding="utf-8").read()
    verify = json.loads(daq("verify", run, *db, "--json"))
    page = reports[run]
    # The same numbers as daq verify, in its order.
    for label, key in (("Largest |deviation| as left, predicted", "predicted_max_um"),
                       ("Largest |deviation| as left, measured", "measured_max_um")):
        check(f"run {run}: {label} as daq verify prints it",
              kv(page, label) == f"{verify[key]:.3f} µm", (kv(page, label), verify[key]))
    check(f"run {run}: the points compared as daq verify counts them",
          (kv(page, "Points compared") or "").startswith(f"{verify['points']} "),
          kv(page, "Points compared"))
    pts = points(page)
    check(f"run {run}: a row per point compared", len(pts) == verify["points"] and len(pts) >= 6,
          len(pts))
    # The table was written from the as-found run: where it corrects, it adds minus that error.
    check(f"run {run}: the expected change removes the as-found error",
          all(abs(p[3] + p[2]) < 0.05 for p in pts), pts)
    for p in pts:
        # Each row's arithmetic: expected as left = as found + expected change; measured
        # change = as left - as found (to the printed 0.001).
        if abs(p[4] - (p[2] + p[3])) > 0.0015 or abs(p[6] - (p[5] - p[2])) > 0.0015:
            check(f"run {run}: each row adds up", False, p)
            break
    else:
        check(f"run {run}: each row adds up", True)
    tolerance = verify["tolerance_um"]
    largest = max(abs(p[2]) for p in pts)
    check(f"run {run}: the as-found error is there to correct (> 1 µm)", largest > 1.0, largest)
    reports[run] = (page, pts, tolerance, largest)

page, pts, tol, largest = reports["2"]
check("as Siemens reads it: the finding is 'as predicted', PASS",
      "Verdict: <strong>PASS</strong> &mdash; finding: <strong>as predicted</strong>" in page,
      re.findall(r'<p class="verdict[^>]*>.*?</p>', page, re.S)[:1])
check("as Siemens reads it: sign, units, reference point and positions as written",
      all(kv(page, k) == "as written" for k in ("Sign", "Units", "Reference point",
                                                "Table positions")),
      [kv(page, k) for k in ("Sign", "Units", "Reference point", "Table positions")])
check("as Siemens reads it: the measured change is the expected one (within the tolerance)",
      all(abs(p[7]) <= tol for p in pts), (tol, pts))
check("as Siemens reads it: nothing left beyond the tolerance",
      all(abs(p[5]) <= tol for p in pts), pts)

page, pts, tol, largest = reports["3"]
check("the other sign: the finding is 'inverted sign', FAIL",
      "Verdict: <strong>FAIL</strong> &mdash; finding: <strong>inverted sign</strong>" in page,
      re.findall(r'<p class="verdict[^>]*>.*?</p>', page, re.S)[:1])
check("the other sign: the sign row names it, the others as written",
      (kv(page, "Sign") or "").startswith("inverted")
      and all(kv(page, k) == "as written" for k in ("Units", "Reference point", "Table positions")),
      [kv(page, k) for k in ("Sign", "Units", "Reference point", "Table positions")])
check("the other sign: the measured change is minus the expected one",
      all(abs(p[6] + p[3]) <= tol for p in pts), (tol, pts))
check("the other sign: the error about twice as large as found",
      all(abs(p[5] - 2 * p[2]) <= tol for p in pts), pts)
check("the other sign: the corrected table offered", "--corrected FILE" in page)
check("the table named: compensation 1, siemens-cec, its file and its machine",
      kv(page, "Table") == "compensation 1, siemens-cec format, axis Y"
      and kv(page, "File") == "cec.mpf" and kv(page, "Machine") == "SIMULATED YFXZ",
      [kv(page, k) for k in ("Table", "File", "Machine")])
check("the runs named: as found run 1, as left run 3",
      "As found: run 1, " in page and "as left: run 3, " in page)
check("both runs' reports follow", 'id="run-1"' in page and 'id="run-3"' in page)
check("SIMULATED said on page one and in the title",
      "<strong>SIMULATED</strong>: both runs of this report were made on the simulated" in page
      and "<h1>SIMULATED — Verification of compensation 1" in page)

# Page one of the PDF: the verdict, the plot, the finding; the plot before the tables.
if shutil.which("pdftotext") and (shutil.which("chromium") or os.environ.get("CALDAQ_CHROMIUM")):
    daq("report", "--verify", "3", *db, "-f", "pdf", "-o", "verify-3.pdf")
    one = pdf_pages("verify-3.pdf")[0]
    check("PDF page one: the verdict and the finding", "Verdict: FAIL" in one
          and "inverted sign" in one, one[:600])
    check("PDF page one: the plot first, then the finding's tables",
          0 <= one.find("As found, as left and as the table should leave it")
          < one.find("The finding") and "expected as left" in one, one[:900])
    check("PDF page one: the largest deviations and the table", "Largest |deviation| as found"
          in one and "cec.mpf" in one, one)
    # Issue 30: the traceability gaps of the runs compared warned on page one, as a linear or
    # circle report does (the simulated instruments state no serial number, certificate or due
    # date); both runs lack the same, so one line without run numbers. Before, the warning was
    # only in each run's section, pages later.
    check("PDF page one: the traceability gaps of both runs, said once",
          one.count("Traceability: air, indicator, laser, material: no serial number, "
                    "certificate or calibration due date stated.") == 1
          and one.count("Traceability") == 1, one[:1500])
    # The finding and the table whole on page one: its last row fell onto page two, alone.
    two = pdf_pages("verify-3.pdf")[1]
    check("PDF page one: the finding's last row and the table's on page one",
          "Agreement with the finding" in one and "Written" in one
          and "Agreement with the finding" not in two and "Points compared" not in two, two[:300])
else:
    check("pdftotext and chromium to print the report", False, "not found")

# A file name from the store is text from outside: escaped.
shutil.copy("loop.sqlite", "hostile.sqlite")
con = sqlite3.connect("hostile.sqlite")
con.execute("""UPDATE compensations SET json = json_set(json, '$.file', '<b>x</b>&"') """)
con.commit()
con.close()
daq("report", "--verify", "3", "--db", "hostile.sqlite", "-o", "hostile.html")
hostile = open("hostile.html", encoding="utf-8").read()
check("the stored file name escaped", "&lt;b&gt;x&lt;/b&gt;&amp;&quot;" in hostile
      and "<b>x</b>" not in hostile)

# What cannot be verified says so.
out = daq("report", "--verify", "1", *db, expect=2)
check("the as-found run: nothing to verify", "nothing to verify" in out, out)
out = daq("report", "1", "--compensation", "1", *db, expect=2)
check("--compensation only with --verify", "--compensation is for --verify RUN" in out, out)
out = daq("report", "--verify", "3", "--compensation", "9", *db, expect=2)
check("an unknown compensation named", "no compensation 9" in out, out)

shutil.rmtree(work, ignore_errors=True)
finish()
