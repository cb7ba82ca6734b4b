"""Runs tests/web/report_render_test.py on several reports in ONE headless Chromium: starting
chromedriver and Chromium takes about 1 s, the checks of a report a fraction of that. Each
report gets exactly the checks of report_render_test.py (run as it is, with its own arguments);
only its Browser is the shared one, already open at the same window size, and not closed
after each report. Prints one line per report: "NAME: <what report_render_test.py printed>",
or "NAME: FAIL <the assertion>"; exits 1 if any failed.
Usage: render_reports.py NAME=REPORT.html:SCREENSHOT.png[:TITLE_PREFIX] ..."""
import contextlib
import io
import os
import runpy
import sys

WEB = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "web")
sys.path.insert(0, WEB)
import webdriver  # noqa: E402

RealBrowser = webdriver.Browser

shared = None
shared_size = None


class SharedBrowser:
    """Stands in for webdriver.Browser inside report_render_test.py: the shared session, at the
    size asked for, left open on exit."""

    def __init__(self, width=1200, height=900):
        global shared, shared_size
        if shared is None:
            shared = RealBrowser(width=width, height=height)
        elif shared_size != (width, height):
            shared.set_size(width, height)
        shared_size = (width, height)
        self.b = shared

    def __enter__(self):
        return self.b

    def __exit__(self, *exc):
        return False


webdriver.Browser = SharedBrowser  # what `from webdriver import Browser` picks up
failed = 0
try:
    for arg in sys.argv[1:]:
        name, spec = arg.split("=", 1)
        sys.argv = [os.path.join(WEB, "report_render_test.py")] + spec.split(":")
        out = io.StringIO()
        try:
            with contextlib.redirect_stdout(out):
                runpy.run_path(sys.argv[0], run_name="__main__")
            print(f"{name}: {out.getvalue().strip()}")
        except AssertionError as e:
            failed += 1
            print(f"{name}: FAIL {e}")
finally:
    if shared is not None:
        shared.close()
sys.exit(1 if failed else 0)
