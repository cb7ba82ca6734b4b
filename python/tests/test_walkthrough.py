"""The issue's "done": open the demo's database, plot a run's deviations with matplotlib,
re-evaluate it under another standard with the CLI's numbers (docs/python.md's example)."""
import matplotlib

matplotlib.use("Agg")  # no display in the suite
import matplotlib.pyplot as plt  # noqa: E402

import caldaq  # noqa: E402


def test_plot_and_reevaluate(demo, cli, tmp_path):
    with caldaq.open(demo / "demo.sqlite") as db:
        run = next(r for r in db.runs() if r.kind == "linear")
        d = db.deviations(run.id)
        fig, ax = plt.subplots()
        for direction in ("up", "down"):
            sel = [x == direction for x in d["direction"]]
            ax.plot(d["target_mm"][sel], d["deviation_um"][sel], "o", label=direction)
        ax.set_xlabel("target (mm)")
        ax.set_ylabel("deviation (um)")
        ax.legend()
        png = tmp_path / "deviations.png"
        fig.savefig(png)
        assert png.stat().st_size > 5000 and len(ax.lines) == 2
        assert sum(len(line.get_xdata()) for line in ax.lines) == len(db.targets(run.id)) == 110
        vdi = db.evaluate(run.id, "vdi3441")
    doc = cli("analyse", run.id, "--db", demo / "demo.sqlite", "--standard", "vdi3441", "--json")
    assert vdi["axis"]["P"]["value_um"] == doc["axis"]["P"]["value_um"] > 0
