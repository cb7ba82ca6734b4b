"""The fleet page (daq serve --db postgresql://...) in headless Chromium, for pg_fleet_test.sh: it
renders both sites' machines with their verdicts and trends, the instruments' flags and the runs
awaiting approval; the machine named with markup is shown as those characters (no script ran, no
element was made of it); a screenshot at 1366x768 (fleet.png) and one of the page's foot.
Usage: pg_fleet_page.py URL SCREENSHOT_DIR"""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "web"))
from webdriver import Browser, png_size  # noqa: E402
from page_checks import ascii_units  # noqa: E402

url, shots = sys.argv[1], sys.argv[2]
os.makedirs(shots, exist_ok=True)


def need(cond, what):
    if not cond:
        sys.exit(f"FAIL: {what}")
    print("ok", what)


with Browser(width=1366, height=768) as b:
    b.get(url + "/")
    b.wait("return document.body.dataset.rendered !== undefined", what="the fleet to render")
    # Both machines are open (few machines): their histories load into trend tables.
    b.wait("return document.querySelectorAll('table.trends').length === 2", what="the histories")
    page = b.js("""
      const text = s => [...document.querySelectorAll(s)].map(e => e.textContent);
      return {
        sites: text('.site > h3'),
        names: text('details.machine .name'),
        scripts: document.querySelectorAll('script').length,
        imgs: document.querySelectorAll('img').length,
        pwned: window.pwned === undefined ? null : window.pwned,
        verdicts: [...document.querySelectorAll('[data-verdict]')].map(e => e.dataset.verdict),
        statuses: [...document.querySelectorAll('td[data-status]')].map(e => e.dataset.status),
        sparks: document.querySelectorAll('svg.spark circle.pt').length,
        past: text('td.past'), soon: text('td.soon'),
        awaiting: document.querySelectorAll('#awaiting-list tr[data-run]').length,
        error: document.getElementById('error').textContent,
        overflow: document.documentElement.scrollWidth - window.innerWidth,
      };""")
    need(page["error"] == "", f"no error shown ({page['error']!r})")
    need(page["sites"] == ["Plant North (1)", "Plant South (1)"], f"sites {page['sites']}")
    need(page["names"][0].startswith('Mill <script>window.pwned=1</script><img src=x onerror='),
         f"the markup name shown as text: {page['names'][0]!r}")
    need(page["scripts"] == 1 and page["imgs"] == 0 and page["pwned"] is None,
         "no element made of the name, no script ran")
    need(len(page["verdicts"]) == 4 and "pass" in page["verdicts"] and "fail" in page["verdicts"],
         f"verdict chips {page['verdicts']}")
    need("leaving" in page["statuses"] and "outside" in page["statuses"]
         and "not enough history" in page["statuses"] and "steady" in page["statuses"],
         f"trend statuses {page['statuses']}")
    need(page["sparks"] >= 6, f"history points drawn ({page['sparks']})")
    need(len(page["past"]) == 1 and page["past"][0].startswith("past due (10 days ago)"), f"past due {page['past']}")
    need(len(page["soon"]) == 1 and page["soon"][0].startswith("due soon (in 12 days)"), f"due soon {page['soon']}")
    need(page["awaiting"] == 5, f"awaiting approval rows ({page['awaiting']})")
    need(page["overflow"] <= 0, "nothing wider than 1366 px")
    leaving = b.js("return document.querySelector('td[data-status=\"leaving\"]').textContent;")
    need(leaving.startswith("leaves its limit about 20"), f"the projection in words: {leaving!r}")
    # Units in the signs an engineer reads (the store writes um, urad): µm, the slope a year.
    cells = b.js("return [...document.querySelectorAll('td.num')].map(c => c.textContent);")
    need(any(c.endswith(" µm") for c in cells) and any(c.endswith(" µm/yr") for c in cells)
         and not any(c.endswith((" um", " urad", " um/m")) for c in cells), f"units {cells[:12]}")
    # Its numbers through the operator page's presentation (daq/web/present.js): never "-0.000".
    need(not any(ascii_units(c) for c in cells), f"no ASCII unit nor '-0.000' in a cell: {[c for c in cells if ascii_units(c)][:5]}")
    need(b.js("return [present.fixed(-0.0004, 3), present.text('slope -0.0001 um/yr')];") == ["0.000", "slope -0.0001 µm/yr"],
         "the shared presentation is the fleet page's")
    for name, script in (("fleet.png", "window.scrollTo(0, 0);"),
                         ("fleet-foot.png", "window.scrollTo(0, document.body.scrollHeight);")):
        b.js(script)
        png = b.screenshot(os.path.join(shots, name))
        w, h = png_size(png)
        need(len(png) > 20000 and (w, h) == (1366, 768) or w == 1366, f"screenshot {name} {w}x{h}")
print("page ok")
