"""The issue's "done": docs/python.md's notebook session, run as written on the demo's database
(a fresh build's package, as `python3 -c "import caldaq; ..."` gets it): it plots a run's
deviations and its compensated readings with matplotlib and re-evaluates the stops under
another standard, with the CLI's numbers."""
import re
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # no display in the suite

import numpy as np  # noqa: E402

DOC = Path(__file__).resolve().parents[2] / "docs" / "python.md"


def notebook_code() -> str:
    text = DOC.read_text()
    m = re.search(r"<!-- notebook: begin -->\s*```python\n(.*?)```\s*<!-- notebook: end -->",
                  text, re.S)
    assert m, f"{DOC}: no notebook block"
    return m.group(1)


def test_the_documented_notebook_runs(demo, cli, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    ns = {"DB": str(demo / "demo.sqlite")}
    exec(compile(notebook_code(), str(DOC), "exec"), ns)
    png = tmp_path / "run.png"
    assert png.stat().st_size > 10000
    run, d = ns["run"], ns["d"]
    ax1, ax2 = ns["ax1"], ns["ax2"]
    assert len(ax1.lines) == 2
    assert sum(len(line.get_xdata()) for line in ax1.lines) == len(d["target_mm"]) == 110
    # The compensated laser readings: every one, finite, and different from the raw ones.
    assert len(ns["comp"]) == len(ns["raw"]) > 1000 and np.all(np.isfinite(ns["comp"]))
    assert np.all(ns["comp"] != ns["raw"]) and len(ax2.lines) == 1
    doc = cli("analyse", run.id, "--db", demo / "demo.sqlite", "--standard", "vdi3441", "--json")
    assert ns["vdi"] == {k: doc[k] for k in ns["vdi"]}  # the CLI's document, every number
    assert ns["vdi"]["axis"]["P"]["value_um"] == doc["axis"]["P"]["value_um"] > 0
