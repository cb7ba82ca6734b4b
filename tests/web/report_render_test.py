"""Renders a report in headless Chromium (WebDriver): every plot must be laid out with a real
size and hold drawn lines, nothing may be fetched from elsewhere, and a screenshot is taken.
Usage: report_render_test.py REPORT.html SCREENSHOT.png"""
import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
from webdriver import Browser, png_size  # noqa: E402

report, shot = sys.argv[1], sys.argv[2]
with Browser(width=1100, height=1400) as b:
    b.get("file://" + os.path.abspath(report))
    b.wait("return document.readyState === 'complete'", what="the page to load")
    plots = b.js("""
        return Array.from(document.querySelectorAll('svg.plot')).map(s => {
          const r = s.getBoundingClientRect();
          return {w: r.width, h: r.height, lines: s.querySelectorAll('polyline').length};
        });""")
    assert plots, "no plots in the report"
    for i, p in enumerate(plots):
        assert p["w"] > 400 and p["h"] > 150, f"plot {i} is not laid out: {p}"
        assert p["lines"] > 10, f"plot {i} has nothing drawn: {p}"
    fetched = b.js("return performance.getEntriesByType('resource').map(e => e.name);")
    assert not fetched, f"the report loaded resources: {fetched}"
    title = b.js("return document.querySelector('h1').textContent;")
    assert title.startswith("Run "), title
    png = b.screenshot(shot)
    w, h = png_size(png)
    assert w >= 1000 and h >= 800, (w, h)
    assert len(png) > 30000, "the screenshot is nearly empty"
print(f"rendered {len(plots)} plots; screenshot {w}x{h}, {len(png)} bytes")
