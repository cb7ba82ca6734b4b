"""The fleet page (daq serve --db postgresql://...) in headless Chromium, for pg_fleet_test.sh.

Mode "few" (the two laptops' machines): both sites and both machines open; the verdicts of every
kind, the trends with the window each line uses (grey points before it), a chosen "since" date
applied to machine A, the instruments' flags and the runs awaiting approval; the machine named with
markup shown as those characters (no script ran, no element was made of it); screenshots at
1366x768 (fleet.png, fleet-since.png, fleet-foot.png).
Mode "paged" (30 more machines at Plant North): only the first site open, its first page of 25
machines (none opened), the pager to the second page (machines 26 - 31, the markup name last);
the other site not loaded; a screenshot (fleet-paged.png).
Usage: pg_fleet_page.py URL SCREENSHOT_DIR few SINCE(YYYY-MM-DD) | paged"""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "web"))
from webdriver import Browser, png_size  # noqa: E402
from page_checks import ascii_units  # noqa: E402

url, shots, mode = sys.argv[1], sys.argv[2], sys.argv[3]
os.makedirs(shots, exist_ok=True)


def need(cond, what):
    if not cond:
        sys.exit(f"FAIL: {what}")
    print("ok", what)


def shot(b, name, script="window.scrollTo(0, 0);"):
    b.js(script)
    png = b.screenshot(os.path.join(shots, name))
    w, h = png_size(png)
    need(len(png) > 20000 and w == 1366, f"screenshot {name} {w}x{h}")


def few(b, since):
    # Both machines are open (few machines): their trends load into trend tables.
    b.wait("return document.querySelectorAll('table.trends').length === 2", what="the trends")
    page = b.js("""
      const text = s => [...document.querySelectorAll(s)].map(e => e.textContent);
      return {
        sites: text('details.site > summary .site-name'),
        names: text('details.machine .name'),
        scripts: document.querySelectorAll('script').length,
        imgs: document.querySelectorAll('img').length,
        pwned: window.pwned === undefined ? null : window.pwned,
        verdicts: [...document.querySelectorAll('[data-verdict]')].map(e => e.dataset.verdict),
        chips: text('[data-verdict]'),
        statuses: [...document.querySelectorAll('td[data-status]')].map(e => e.dataset.status),
        windows: [...document.querySelectorAll('td[data-window]')].map(e => [e.parentElement.dataset.series, e.textContent]),
        sparks: document.querySelectorAll('svg.spark circle.pt').length,
        old: document.querySelectorAll('svg.spark circle.pt.old').length,
        rules: document.querySelectorAll('svg.spark line.win').length,
        // The narrowest share of a plot's width its points span (plots of points at two times
        // or more): the projected line is not allowed to squeeze the history to one edge.
        spread: Math.min(...[...document.querySelectorAll('svg.spark')].map(g => {
          const xs = [...g.querySelectorAll('circle.pt')].map(c => +c.getAttribute('cx'));
          const w = Math.max(...xs) - Math.min(...xs);
          return w > 0 ? w / (220 - 2 * 3) : 1;
        })),
        past: text('td.past'), soon: text('td.soon'), count: text('#instrument-count'),
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
    # A: X, Y, its circle, E_YX, E_BX, E_AX; B: X, Z, its circle (fleet_stores.py). Failing: A's
    # E_BX and circle (the demo's backlash limit), B's X (E) and circle (squareness).
    need(len(page["verdicts"]) == 9 and page["verdicts"].count("fail") == 4, f"verdict chips {page['verdicts']}")
    need(any(c.startswith("E_BX angular: FAIL (E_BX)") for c in page["chips"])
         and any(c.startswith("E_YX straightness: PASS") for c in page["chips"])
         and any(c.startswith("E_AX roll: PASS") for c in page["chips"]), f"profile chips {page['chips']}")
    need("leaving" in page["statuses"] and "outside" in page["statuses"]
         and "not enough history" in page["statuses"] and "steady" in page["statuses"],
         f"trend statuses {page['statuses']}")
    windows = dict(page["windows"])
    need(windows["linear|X|E"] == "all history", f"X's window {windows['linear|X|E']!r}")
    need(windows["linear|Y|E"].startswith("since 20") and ": compensation table " in windows["linear|Y|E"]
         and "of axis Y (csv)" in windows["linear|Y|E"], f"Y's window {windows['linear|Y|E']!r}")
    need(windows["linear|Z|E"].endswith(": controller compensation switched on (run "
                                         + windows["linear|Z|E"].split("(run ")[-1]), f"Z's window {windows['linear|Z|E']!r}")
    # Grey points before the windows: Y's E and M (0, 30 d), Z's E and M (0, 30 d): 8; a rule at
    # each of those four windows.
    need(page["old"] == 8 and page["rules"] == 4, f"points before the windows {page['old']}, rules {page['rules']}")
    need(page["sparks"] >= 30, f"history points drawn ({page['sparks']})")
    need(page["spread"] >= 0.45, f"every plot's points span half its width or more ({page['spread']:.3f})")
    need(len(page["past"]) == 1 and page["past"][0].startswith("past due (10 days ago)"), f"past due {page['past']}")
    need(len(page["soon"]) == 1 and page["soon"][0].startswith("due soon (in 12 days)"), f"due soon {page['soon']}")
    need(page["count"] and "1 past due, 1 due within 30 days, 1 later" in page["count"][0], f"instrument counts {page['count']}")
    need(page["awaiting"] == 20, f"awaiting approval rows ({page['awaiting']})")
    need(page["overflow"] <= 0, "nothing wider than 1366 px")
    leaving = b.js("return document.querySelector('td[data-status=\"leaving\"]').textContent;")
    need(leaving.startswith("leaves its limit about 20"), f"the projection in words: {leaving!r}")
    # Units in the signs an engineer reads (the store writes um, urad): µm, µrad, the slope a year.
    cells = b.js("return [...document.querySelectorAll('td.num')].map(c => c.textContent);")
    need(any(c.endswith(" µm") for c in cells) and any(c.endswith(" µrad") for c in cells)
         and any(c.endswith(" µm/yr") for c in cells)
         and not any(c.endswith((" um", " urad", " um/m")) for c in cells), f"units {cells[:12]}")
    # Its numbers through the operator page's presentation (daq/web/present.js): never "-0.000".
    need(not any(ascii_units(c) for c in cells), f"no ASCII unit nor '-0.000' in a cell: {[c for c in cells if ascii_units(c)][:5]}")
    need(b.js("return [present.fixed(-0.0004, 3), present.text('slope -0.0001 um/yr')];") == ["0.000", "slope -0.0001 µm/yr"],
         "the shared presentation is the fleet page's")
    shot(b, "fleet.png")
    # A date chosen for machine A: Y's line from it (2 runs: not enough history), said so.
    b.js("""const box = document.querySelector('details.machine .body');
            const input = box.querySelector('input[type=date]');
            input.value = arguments[0];
            box.querySelector('.since button').click();""", since)
    b.wait(f"return document.querySelector('details.machine .body').dataset.loaded === '{since}'",
           what="the chosen date's lines")
    row = b.js("""const r = document.querySelector('details.machine .body tr[data-series="linear|Y|E"]');
                  return [r.querySelector('td[data-window]').textContent,
                          r.querySelector('td[data-status]').dataset.status,
                          r.children[5].textContent];""")
    need(row == [f"since {since} (chosen)", "not enough history", "2 of 5"], f"Y's line from {since}: {row}")
    shot(b, "fleet-since.png", "document.querySelector('details.machine').scrollIntoView();")
    shot(b, "fleet-foot.png", "window.scrollTo(0, document.body.scrollHeight);")


def paged(b):
    page = b.js("""
      const text = s => [...document.querySelectorAll(s)].map(e => e.textContent);
      const north = document.querySelector('details.site[data-site="Plant North"]');
      const south = document.querySelector('details.site[data-site="Plant South"]');
      return {sites: text('details.site > summary .site-name'), north_open: north.open,
              south_open: south.open, machines: north.querySelectorAll('details.machine').length,
              opened: document.querySelectorAll('details.machine[open]').length,
              south_machines: south.querySelectorAll('details.machine').length,
              pager: north.querySelector('.pager span').textContent,
              trends: document.querySelectorAll('table.trends').length,
              count: document.getElementById('fleet-count').textContent};""")
    need(page["sites"] == ["Plant North (31)", "Plant South (1)"], f"sites {page['sites']}")
    need(page["north_open"] and not page["south_open"] and page["south_machines"] == 0,
         "the first site open, the other not loaded")
    need(page["machines"] == 25 and page["opened"] == 0 and page["trends"] == 0,
         f"25 machines, none opened ({page['machines']}, {page['opened']})")
    need(page["pager"] == "machines 1–25 of 31 (page 1 of 2)", f"pager {page['pager']!r}")
    need(page["count"].startswith("32 machine(s) at 2 site(s)"), f"count {page['count']!r}")
    shot(b, "fleet-paged.png")
    b.js("document.querySelector('details.site[data-site=\"Plant North\"] .pager button.next').click();")
    b.wait("return document.querySelector('details.site[data-site=\"Plant North\"] .site-body').dataset.page === '2'",
           what="the second page")
    names = b.js("""return [...document.querySelectorAll('details.site[data-site="Plant North"] details.machine .name')]
                      .map(e => e.textContent);""")
    need(len(names) == 6 and names[0] == "Machine 26" and names[4] == "Machine 30"
         and names[5].startswith("Mill <script>"), f"page 2 {names}")
    shot(b, "fleet-paged-2.png")


with Browser(width=1366, height=768) as b:
    b.get(url + "/")
    b.wait("return document.body.dataset.complete !== undefined", what="the fleet to render")
    if mode == "few":
        few(b, sys.argv[4])
    else:
        paged(b)
print("page ok")
