"""The analysis library from Python: the same numbers as the CLI's JSON, bit for bit (JSON
numbers are printed so that they read back to the same double)."""
import csv
import io
import json
import shlex
import subprocess

import numpy as np
import pytest

import caldaq

STANDARDS = [s["key"] for s in caldaq.iso230_2_standards()]


def same(a, b):
    """Equal, with numbers compared exactly and arrays element by element."""
    if isinstance(a, np.ndarray):
        a = a.tolist()
    if isinstance(a, dict):
        return isinstance(b, dict) and all(k in b and same(v, b[k]) for k, v in a.items())
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    return a == b


def test_same_is_strict():
    assert not same({"x": 1.0}, {"x": 1.0000000000000002})
    assert not same(np.array([1.0, 2.0]), [1.0, 2.0000000000000004])


@pytest.mark.parametrize("humidity", [("--rh", "43", "relative"), ("--dew-point", "8.5", "dew_point")])
def test_refractive_index_matches_daq_env(cli, humidity):
    opt, value, kind = humidity
    doc = cli("env", "-t", "21.3", "-p", "1005.2", opt, value, "--co2", "420", "-m", "21.5",
              "-a", "11.5", "-e", "all", "--json")
    assert len(doc["results"]) == 3
    for r in doc["results"]:
        mine = caldaq.refractive_index(21.3, 1005.2 * 100.0, float(value), kind, 420.0,
                                       equation=r["equation"])
        assert mine["n"] == r["n"] and mine["n"] != 1.0
        assert mine["water_vapour_pressure_pa"] == r["water_vapour_pressure_pa"]
        assert mine["warnings"] == r["warnings"]
        f = caldaq.compensation_factor(mine["n"], 11.5 * 1e-6, 21.5)
        for k in ("factor", "air_ppm", "material_ppm", "total_ppm"):
            assert f[k] == r[k], k


def test_refractive_index_bad_input_has_the_cli_message(cli_error):
    with pytest.raises(caldaq.InputError) as e:
        caldaq.refractive_index(200.0, equation="edlen")
    assert str(e.value) == cli_error("env", "-t", "200", "-e", "edlen")
    with pytest.raises(ValueError):  # InputError is a ValueError
        caldaq.refractive_index(equation="nope")


@pytest.mark.parametrize("standard", STANDARDS)
def test_stored_run_under_each_standard_matches_daq_analyse(demo, cli, standard):
    with caldaq.open(demo / "demo.sqlite") as db:
        run = next(r for r in db.runs() if r.kind == "linear")
        mine = db.evaluate(run.id, standard)
    doc = cli("analyse", run.id, "--db", demo / "demo.sqlite", "--standard", standard, "--json")
    verdict = doc.pop("verdict")
    assert mine == doc and len(mine["axis"]) >= 6
    with caldaq.open(demo / "demo.sqlite") as db:
        assert caldaq.verdict(json.dumps(db.run(run.id).settings), json.dumps(mine)) == verdict


def test_any_array_matches_daq_analyse_iso230_2_input(demo, cli, daq_bin, tmp_path):
    with caldaq.open(demo / "demo.sqlite") as db:
        run = next(r for r in db.runs() if r.kind == "linear")
    out = subprocess.run([daq_bin, "export", str(run.id), "--db", str(demo / "demo.sqlite"),
                          "--what", "targets"], capture_output=True, text=True, check=True).stdout
    rows = list(csv.DictReader(io.StringIO(out)))
    # Half the deviations scaled: an array that is not the stored run's.
    for r in rows:
        r["deviation_um"] = repr(float(r["deviation_um"]) * 0.5 + 0.25)
    path = tmp_path / "targets.csv"
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["target_mm", "run", "direction", "deviation_um"], extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)
    for standard in ("iso230-2:2014", "vdi3441", "iso230-2:1988"):
        doc = cli("analyse", "iso230-2", "--input", path, "--standard", standard, "--json")
        mine = caldaq.iso230_2_evaluate(np.array([float(r["target_mm"]) for r in rows]),
                                        np.array([int(r["run"]) for r in rows]),
                                        [r["direction"] for r in rows],
                                        np.array([float(r["deviation_um"]) for r in rows]), standard)
        doc.pop("input")
        assert mine == doc


def test_iso230_2_errors_are_the_cli_messages(tmp_path, cli_error):
    path = tmp_path / "one.csv"
    path.write_text("target_mm,run,direction,deviation_um\n0,1,up,1\n0,1,down,2\n10,1,up,1\n10,1,down,1\n")
    with pytest.raises(caldaq.InputError) as e:
        caldaq.iso230_2_evaluate([0, 0, 10, 10], [1, 1, 1, 1], ["up", "down", "up", "down"], [1, 2, 1, 1])
    assert str(e.value) == cli_error("analyse", "iso230-2", "--input", path)
    with pytest.raises(caldaq.InputError) as e:
        caldaq.iso230_2_evaluate([0], [1], ["up"], [1], "asme")
    assert str(e.value) == cli_error("analyse", "iso230-2", "--input", path, "--standard", "asme")


def _circle_export(daq_bin, demo, tmp_path):
    with caldaq.open(demo / "demo.sqlite") as db:
        run = next(r for r in db.runs() if r.kind == "circle")
    out = subprocess.run([daq_bin, "export", str(run.id), "--db", str(demo / "demo.sqlite"),
                          "--what", "circle"], capture_output=True, text=True, check=True).stdout
    path = tmp_path / "circle.csv"
    path.write_text(out)
    comment = next(line for line in out.splitlines() if line.startswith("#"))
    words = shlex.split(comment[comment.index("--"):])
    opts, args, k = {}, [], 0
    while k < len(words):  # "--input FILE --radius-mm 100 ... --uncalibrated"
        flag = k + 1 == len(words) or words[k + 1].startswith("--")
        opts[words[k]] = True if flag else words[k + 1]
        if words[k] != "--input":
            args += words[k:k + (1 if flag else 2)]
        k += 1 if flag else 2
    rows = list(csv.DictReader(line for line in out.splitlines() if not line.startswith("#")))
    return path, args, opts, rows


def test_circle_matches_daq_analyse_circle(demo, cli, daq_bin, tmp_path):
    path, args, opts, rows = _circle_export(daq_bin, demo, tmp_path)
    doc = cli("analyse", "circle", "--input", path, *args, "--json")
    traces = []
    for d in ("cw", "ccw"):  # the CLI's order
        sel = [r for r in rows if r["direction"] == d]
        traces.append((d, np.array([float(r["angle_deg"]) for r in sel]),
                       np.array([float(r["deviation_um"]) for r in sel])))
    mine = caldaq.circle_analyse(traces, plane=opts.get("--plane", "XY"),
                                 radius_mm=float(opts["--radius-mm"]),
                                 feed_mm_per_min=float(opts["--feed-mm-min"]),
                                 cyclic_period_mm=float(opts["--cyclic-period-mm"]) if "--cyclic-period-mm" in opts else None,
                                 radius_calibrated="--uncalibrated" not in opts)
    assert mine == doc and mine["iso230_4"]["G_bi_um"] > 0 and len(mine["diagnostics"]) > 5
    other = caldaq.circle_analyse(traces, plane=opts.get("--plane", "XY"),
                                  radius_mm=float(opts["--radius-mm"]),
                                  feed_mm_per_min=float(opts["--feed-mm-min"]),
                                  radius_calibrated="--uncalibrated" not in opts, standard="iso230-4:1996")
    assert other == cli("analyse", "circle", "--input", path, *args, "--standard", "iso230-4:1996", "--json")
    assert "H_um" in other["iso230_4"]


def _write(path, header, cols):
    with open(path, "w") as f:
        f.write(header + "\n")
        for row in zip(*cols):
            f.write(",".join(repr(float(x)) for x in row) + "\n")


@pytest.fixture()
def straight_runs(tmp_path):
    pos = np.linspace(0, 400, 21)
    a = 0.8 + 3.1e-3 * pos + 1.7 * np.sin(pos / 55.0)
    b = -0.4 - 2.2e-3 * pos + 0.9 * np.cos(pos / 35.0)
    _write(tmp_path / "a.csv", "position_mm,deviation_um", [pos, a])
    _write(tmp_path / "b.csv", "position_mm,deviation_um", [pos, b])
    return tmp_path, pos, a, b


@pytest.mark.parametrize("reference", ["lsq", "endpoint", "minzone"])
def test_straightness_matches_daq(cli, straight_runs, reference):
    d, pos, a, _ = straight_runs
    doc = cli("analyse", "straightness", "--input", d / "a.csv", "--reference", reference, "--json")
    mine = caldaq.straightness(pos, a, reference)
    for k in ("straightness_um", "slope_um_per_m", "intercept_um"):
        assert mine[k] == doc[k], k
    assert same(mine["residual_um"], doc["residual_um"])


def test_squareness_matches_daq(cli, straight_runs):
    d, pos, a, b = straight_runs
    doc = cli("analyse", "squareness", "--method", "straightness", "--along-a", d / "a.csv",
              "--along-b", d / "b.csv", "--square-error", "1.5", "--json")
    mine = caldaq.squareness_from_straightness(pos, a, pos, b, 1.5)
    assert mine["squareness_um_per_m"] == doc["squareness_um_per_m"] != 0
    doc = cli("analyse", "squareness", "--method", "diagonal", "--x-mm", "400", "--y-mm", "300",
              "--d1-um", "12.5", "--d2-um", "-3.25", "--json")
    mine = caldaq.squareness_from_diagonals(400, 300, 12.5, -3.25)
    assert mine["squareness_um_per_m"] == doc["squareness_um_per_m"] != 0


def test_uncertainty_matches_daq(cli):
    doc = cli("uncertainty", "-L", "0.8", "-t", "21.5", "-p", "990", "-r", "40", "-m", "22",
              "-a", "11.5", "--drift-um", "1.2", "--dead-path-m", "0.1", "-e", "edlen", "--json")
    mine = caldaq.uncertainty_budget(length_m=0.8, temperature_degc=21.5, pressure_pa=990 * 100.0,
                                     humidity_pct=40.0, material_degc=22.0, alpha_per_k=11.5 * 1e-6,
                                     u_alpha_per_k=1.0 * 1e-6, environmental_variation_um=1.2,
                                     dead_path_m=0.1, equation="edlen")
    assert mine == doc and mine["expanded_um"] > 0
    with pytest.raises(caldaq.InputError, match="unknown setting 'lenght_m'"):
        caldaq.uncertainty_budget(lenght_m=1.0)
