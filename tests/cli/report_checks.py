"""Shared by the Python tests of the reports (verify_report_test.py, campaign_pages_test.py):
checks counted and printed, `daq` run with its exit status checked, a PDF's pages as text."""
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


def finish():
    print(f"{'FAILED' if failed else 'passed'}: {failed} failed")
    sys.exit(1 if failed else 0)
