"""Checks the inlined SVG plots of a report (HTML parsed, no browser): every element id is
unique across the whole page, every reference (url(#id), href="#id") points to an id of its own
plot, and every plot carries text (axis labels, ticks, title) that is not clipped by a clip path
of another plot. PLplot writes the same ids ("text-clipping0", ...) into every SVG: inlined
together, the second plot's text was clipped by the first plot's clip path and disappeared.
Usage: report_ids_test.py REPORT.html [MIN_PLOTS]"""
import re
import sys
from html.parser import HTMLParser

path = sys.argv[1]
min_plots = int(sys.argv[2]) if len(sys.argv) > 2 else 1


class Plots(HTMLParser):
    def __init__(self):
        super().__init__()
        self.ids = []          # every id in the page
        self.plots = []        # per plot: {"ids", "refs", "texts"}
        self.depth = 0         # inside an <svg class="plot">
        self.in_text = False

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if "id" in a:
            self.ids.append(a["id"])
        if tag == "svg" and "plot" in (a.get("class") or ""):
            self.plots.append({"ids": set(), "refs": set(), "texts": []})
            self.depth = 1
            return
        if self.depth:
            if tag == "svg":
                self.depth += 1
            p = self.plots[-1]
            if "id" in a:
                p["ids"].add(a["id"])
            for v in a.values():
                for ref in re.findall(r"url\(#([^)]+)\)", v or ""):
                    p["refs"].add(ref)
            if (a.get("href") or a.get("xlink:href") or "").startswith("#"):
                p["refs"].add((a.get("href") or a.get("xlink:href"))[1:])
            if tag == "text":
                self.in_text = True

    def handle_endtag(self, tag):
        if self.depth and tag == "svg":
            self.depth -= 1
        if tag == "text":
            self.in_text = False

    def handle_data(self, data):
        if self.depth and self.in_text and data.strip():
            self.plots[-1]["texts"].append(data.strip())


p = Plots()
p.feed(open(path, encoding="utf-8").read())
dupes = sorted({i for i in p.ids if p.ids.count(i) > 1})
assert not dupes, f"ids used more than once in the page: {dupes[:5]}"
assert len(p.plots) >= min_plots, f"{len(p.plots)} plots, expected at least {min_plots}"
for n, plot in enumerate(p.plots):
    foreign = plot["refs"] - plot["ids"]
    assert not foreign, f"plot {n} refers to ids that are not its own: {sorted(foreign)[:5]}"
    assert len(plot["texts"]) >= 3, f"plot {n} has almost no text: {plot['texts']}"
print(f"{len(p.plots)} plots, {len(p.ids)} ids, all unique; every plot has its own text")
