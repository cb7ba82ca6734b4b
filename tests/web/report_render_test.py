"""Renders a report in headless Chromium (WebDriver): every plot must be laid out with a real
size and hold drawn lines, every plot's text must be drawn (hit-testing at the centre of each
text finds that text: a text clipped away, as when plots shared PLplot's clip-path ids, is not
hit), nothing may be fetched from elsewhere, and a screenshot is taken.
Usage: report_render_test.py REPORT.html SCREENSHOT.png [TITLE_PREFIX]"""
import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
from webdriver import Browser, png_size  # noqa: E402

report, shot = sys.argv[1], sys.argv[2]
title_prefix = sys.argv[3] if len(sys.argv) > 3 else "Run "
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
    # Each plot's texts, scrolled into view one plot at a time: the share that hit-testing finds
    # at their own centre (the tick labels, axis labels and titles drawn, not clipped).
    drawn = b.js("""
        return Array.from(document.querySelectorAll('svg.plot')).map(s => {
          s.scrollIntoView({block: 'center'});
          // Words and numbers; PLplot draws point markers as one-glyph texts (•), which
          // overlap each other and the lines.
          const texts = Array.from(s.querySelectorAll('text'))
                            .filter(t => /[0-9A-Za-z]/.test(t.textContent));
          let hit = 0;
          for (const t of texts) {
            const r = t.getBoundingClientRect();
            const e = document.elementFromPoint(r.left + r.width / 2, r.top + r.height / 2);
            if (e && (e === t || t.contains(e))) hit++;
          }
          return {texts: texts.length, hit: hit};
        });""")
    for i, d in enumerate(drawn):
        assert d["texts"] >= 3 and d["hit"] >= 0.8 * d["texts"], f"plot {i}: text not drawn: {d}"
    b.js("window.scrollTo(0, 0);")
    fetched = b.js("return performance.getEntriesByType('resource').map(e => e.name);")
    assert not fetched, f"the report loaded resources: {fetched}"
    title = b.js("return document.querySelector('h1').textContent;")
    assert title.startswith(title_prefix), title
    png = b.screenshot(shot)
    w, h = png_size(png)
    assert w >= 1000 and h >= 800, (w, h)
    assert len(png) > 30000, "the screenshot is nearly empty"
texts = sum(d["hit"] for d in drawn)
print(f"rendered {len(plots)} plots, {texts} texts drawn; screenshot {w}x{h}, {len(png)} bytes")
