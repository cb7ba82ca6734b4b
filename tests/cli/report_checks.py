"""Shared by the Python tests of the reports (verify_report_test.py, campaign_pages_test.py):
checks counted and printed, `daq` run with its exit status checked, a PDF's pages as text."""
import html
import re
import subprocess
import sys

failed = 0


def check(name, ok, detail=""):
    """Prints the check; a failed one with what was seen, and counted."""
    global failed
    print(("ok   " if ok else "FAIL ") + name + ("" if ok else ": " + str(detail)[:600]))
    if not ok:
        failed += 1


def runner(binary):
    """daq(*args, expect=0): stdout and stderr of the binary; another exit status ends the test."""
    def daq(*args, expect=0):
        r = subprocess.run([binary, *args], capture_output=True, text=True, timeout=400)
        if r.returncode != expect:
            raise SystemExit(f"daq {' '.join(args)}: exit {r.returncode}: {r.stdout}{r.stderr}")
        return r.stdout + r.stderr
    return daq


def pdf_pages(pdf):
    """Each page's text (pdftotext), its white space squashed."""
    out = subprocess.run(["pdftotext", pdf, "-"], capture_output=True, text=True,
                         check=True).stdout
    return [re.sub(r"\s+", " ", p) for p in out.split("\f")]


# The printed page's margins (print_css in daq/src/report/report.cpp: 18 mm top, 16 mm bottom),
# in PDF points: the running header and "page n of m" print there, not the report's content.
MM = 72 / 25.4
TOP_PT, BOTTOM_PT = 18 * MM, 16 * MM


def pdf_words(pdf):
    """Each page's words as (x_min, y_min, x_max, y_max, text) in points from the page's top
    left (pdftotext -bbox), and the page's height; the words in the margins left out."""
    out = subprocess.run(["pdftotext", "-bbox", pdf, "-"], capture_output=True, text=True,
                         check=True).stdout
    pages = []
    for m in re.finditer(r'<page width="[0-9.]+" height="([0-9.]+)">(.*?)</page>', out, re.S):
        height = float(m.group(1))
        words = [(float(a), float(b), float(c), float(d), html.unescape(t)) for a, b, c, d, t in
                 re.findall(r'<word xMin="([0-9.]+)" yMin="([0-9.]+)" xMax="([0-9.]+)" '
                            r'yMax="([0-9.]+)">(.*?)</word>', m.group(2))]
        pages.append(([w for w in words if TOP_PT <= w[1] and w[3] <= height - BOTTOM_PT],
                      height))
    return pages


def page_fill(words, height):
    """How far down the text area (between the margins) a page's content reaches, 0 to 1."""
    area = height - TOP_PT - BOTTOM_PT
    return max((w[3] - TOP_PT for w in words), default=0.0) / area


def finish():
    print(f"{'FAILED' if failed else 'passed'}: {failed} failed")
    sys.exit(1 if failed else 0)
