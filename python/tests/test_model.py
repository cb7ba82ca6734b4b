"""The machine model from Python against `daq model show|map --json` on the project's model files."""
import json
from pathlib import Path

import numpy as np
import pytest

import caldaq

MODELS = Path(__file__).resolve().parents[2] / "tests" / "data" / "model"


@pytest.mark.parametrize("name", ["yfxz.json", "square50.json"])
def test_model_show_and_map_match_daq(cli, tmp_path, name):
    model = caldaq.Model.load(str(MODELS / name))
    assert json.loads(model.to_json()) == cli("model", "show", MODELS / name, "--json")
    doc = cli("model", "map", MODELS / name, "--count", 3, 4, 2, "--json")
    grid = model.map_grid([3, 4, 2])
    pts = doc["points"]
    assert grid["positions_mm"].tolist() == [p["position_mm"] for p in pts]
    assert grid["error_um"].tolist() == [p["error_um"] for p in pts]
    assert grid["rotation_urad"].tolist() == [p["rotation_urad"] for p in pts]
    assert grid["max_norm_um"] == doc["summary"]["max_norm_um"] > 0
    # Points of one's own choosing, both methods.
    points = np.array([[10.0, 20.0, 30.0], [120.5, -3.0, 44.0], [0.0, 0.0, 0.0]])
    csv = tmp_path / "points.csv"
    csv.write_text("x_mm,y_mm,z_mm\n" + "".join(",".join(repr(v) for v in p) + "\n" for p in points))
    for method in ("htm", "first-order"):
        try:
            doc = cli("model", "map", MODELS / name, "--points", csv, "--method", method, "--json")
        except AssertionError:  # outside the model's tables: the CLI refuses, so must we
            with pytest.raises(caldaq.InputError):
                model.map_points(points, method)
            continue
        mine = model.map_points(points, method)
        assert mine["error_um"].tolist() == [p["error_um"] for p in doc["points"]]
        assert mine["rotation_urad"].tolist() == [p["rotation_urad"] for p in doc["points"]]


def test_a_bad_model_file_has_the_cli_message(cli_error):
    with pytest.raises(caldaq.InputError) as e:
        caldaq.Model.load(str(MODELS / "bad_carrier.json"))
    assert str(e.value) == cli_error("model", "show", MODELS / "bad_carrier.json")


def test_build_from_profiles():
    pos = [0.0, 100.0, 200.0, 300.0]
    model = caldaq.model_build(
        [{"component": "E_XX", "kind": "positioning", "position_mm": pos, "value": [1.0, 3.0, 4.0, 2.0]}],
        machine="test", topology="FXYZ", allow_missing=True)
    doc = json.loads(model.to_json())
    assert doc["machine"] if "machine" in doc else True
    # Positioning is relative to its first target: E_XX(200) = 4 - 1 um, seen along X.
    e = model.map_points([[200.0, 0.0, 0.0]])["error_um"][0]
    assert e[0] == pytest.approx(3.0) and e[1] == 0.0 and e[2] == 0.0
    with pytest.raises(caldaq.InputError):
        caldaq.model_build([], machine="test")


def test_long_calls_release_the_gil():
    """A map of 216 000 points computed in a thread while this thread keeps running Python. Held,
    the GIL would let this thread run no bytecode from the call's entry to its return, so none of
    its loop's time stamps could fall in the middle half of the call. Counted, not timed: a loaded
    machine stretches the call and this loop's gaps alike, and cannot put a stamp inside a call
    that holds the GIL."""
    import threading
    import time
    model = caldaq.Model.load(str(MODELS / "yfxz.json"))
    span = {}

    def work():
        span["start"] = time.perf_counter()
        model.map_grid([60, 60, 60])
        span["end"] = time.perf_counter()

    t = threading.Thread(target=work)
    stamps = []
    t.start()
    while t.is_alive():
        stamps.append(time.perf_counter())
    t.join()
    start, end = span["start"], span["end"]
    # Long enough that the thread switch before the call's entry (the 5 ms switch interval) ends
    # well before the middle half begins.
    assert end - start > 0.05, end - start
    quarter = (end - start) / 4
    inside = [s for s in stamps if start + quarter < s < end - quarter]
    assert len(inside) > 0, (len(stamps), end - start)


def test_rotary_model_maps_poses_as_daq_does(cli, tmp_path):
    """A caldaq.model.v2 trunnion: Model.map_poses gives `daq model map --points` bit for bit."""
    path = MODELS / "trunnion_ac.json"
    model = caldaq.Model.load(str(path))
    assert json.loads(model.to_json()) == cli("model", "show", path, "--json")
    axes = model.rotary_axes
    assert sorted(axes) == ["A", "C"]
    poses = np.array([[10.0, 20.0, -30.0, 0.0, 0.0],
                      [120.5, -3.0, -44.0, 90.0, 30.0],
                      [0.0, 0.0, 0.0, 233.25, -17.5],
                      [55.0, 65.0, -75.0, 180.0, 45.0]])
    csv = tmp_path / "poses.csv"
    header = "x_mm,y_mm,z_mm," + ",".join(a.lower() + "_deg" for a in axes)
    csv.write_text(header + "\n" + "".join(",".join(repr(v) for v in p) + "\n" for p in poses))
    for method in ("htm", "first-order"):
        doc = cli("model", "map", path, "--points", csv, "--method", method, "--json")
        mine = model.map_poses(poses, method)
        assert mine["error_um"].tolist() == [p["error_um"] for p in doc["points"]]
        assert mine["rotation_urad"].tolist() == [p["rotation_urad"] for p in doc["points"]]
        assert np.abs(mine["error_um"]).max() > 1.0  # the location errors are seen
    # The linear map of a rotary model would leave its rotary axes out: refused, as the CLI's
    # linear-only commands refuse it; a pose without its angles too.
    with pytest.raises(caldaq.InputError, match="rotary"):
        model.map_points(poses[:, :3])
    with pytest.raises(caldaq.InputError, match="rotary"):
        model.map_grid([2, 2, 2])
    with pytest.raises(caldaq.InputError, match=r"N x 5 array \(x_mm, y_mm, z_mm, ._deg, ._deg\)"):
        model.map_poses(poses[:, :4])


def test_a_linear_model_maps_poses_without_angles():
    model = caldaq.Model.load(str(MODELS / "yfxz.json"))
    assert model.rotary_axes == []
    points = np.array([[10.0, 20.0, 30.0], [120.5, 3.0, 44.0]])
    assert model.map_poses(points)["error_um"].tolist() == model.map_points(points)["error_um"].tolist()
