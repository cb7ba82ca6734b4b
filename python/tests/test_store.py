"""The store from Python against the CLI's JSON and exports of the same demo database."""
import csv
import io
import subprocess

import numpy as np
import pytest

import caldaq


@pytest.fixture()
def db(demo):
    with caldaq.open(demo / "demo.sqlite") as s:
        yield s


def test_runs_match_daq_runs(db, demo, cli):
    doc = cli("runs", "--db", demo / "demo.sqlite", "--json")
    runs = db.runs()
    assert [r.id for r in runs] == [r["id"] for r in doc["runs"]]
    for mine, theirs in zip(runs, doc["runs"]):
        assert mine.kind == theirs["kind"] and mine.axis == theirs["axis"]
        assert mine.status == theirs["status"] and mine.campaign == theirs["campaign"]
        assert mine.settings == theirs["settings"]
        assert db.reading_count(mine.id) == theirs["readings"]
    assert {r.kind for r in runs} == {"linear", "circle"}


def test_show_matches_instruments_results_provenance(db, demo, cli):
    for run in db.runs():
        doc = cli("show", run.id, "--db", demo / "demo.sqlite", "--json")
        inst = db.instruments(run.id)
        assert [i.device for i in inst] == [i["device"] for i in doc["instruments"]]
        assert [i.origin for i in inst] == [i["origin"] for i in doc["instruments"]]
        assert [i.origin_detail for i in inst] == [i["origin_detail"] for i in doc["instruments"]]
        assert db.origin(run.id) == doc["origin"]["label"].lower() == "simulated"
        assert len(db.targets(run.id)) == doc["targets"]
        assert db.missed_stops(run.id) == [
            dict(m, target_index=m["target_index"] - 1) for m in doc["missed_stops"]]
        results = db.results(run.id)
        assert [r.id for r in results] == [r["id"] for r in doc["results"]]
        for mine, theirs in zip(results, doc["results"]):
            assert mine.standard == theirs["standard"] and mine.current == theirs["current"]
            assert mine.provenance == theirs["provenance"]
            assert mine.result == theirs["result"]  # every number, compared as parsed doubles
            assert mine.verdict == theirs["verdict"]
        q = db.quality(run.id)
        if doc.get("quality") is not None and q is not None:
            assert q["state"] == doc["quality"]["state"]


def _export_csv(daq_bin, demo, run_id):
    p = subprocess.run([daq_bin, "export", str(run_id), "--db", str(demo / "demo.sqlite"),
                        "--format", "csv"], capture_output=True, text=True, check=True)
    return list(csv.DictReader(io.StringIO(p.stdout)))


def test_streamed_readings_equal_the_csv_export(db, demo, daq_bin):
    for run in db.runs():
        rows = _export_csv(daq_bin, demo, run.id)
        chunks = list(db.iter_readings(run.id, chunk=1000))
        assert len(chunks) > 1  # really streamed in pieces
        got = {k: np.concatenate([c[k] for c in chunks]) for k in chunks[0]}
        assert len(got["value"]) == len(rows) == db.reading_count(run.id)
        assert np.array_equal(got["time_ns"], np.array([int(r["time_ns"]) for r in rows]))
        assert np.array_equal(got["value"], np.array([float(r["value"]) for r in rows]))
        assert np.array_equal(got["status"], np.array([int(r["status"]) for r in rows]))
        assert np.array_equal(got["device"], np.array([int(r["device"]) for r in rows]))
        assert [caldaq.QUANTITIES[q] for q in got["quantity"]] == [r["quantity"] for r in rows]
        # time_s and utc: the stored time; the export spreads a group of readings that arrived
        # in one transport read back by the sample period (docs/python.md), so compare where a
        # reading had its read to itself.
        t_export = np.array([float(r["time_s"]) for r in rows])
        key = got["time_ns"] * 65536 + got["device"].astype(np.int64) * 256 + got["quantity"]
        _, inv, counts = np.unique(key, return_inverse=True, return_counts=True)
        single = counts[inv] == 1
        # A linear run's readings come one per read; a ballbar's mostly several per read.
        assert single.sum() > (len(rows) // 2 if run.kind == "linear" else 0)
        assert np.array_equal(got["time_s"][single], t_export[single])
        utc = np.array([np.datetime64(r["utc"].rstrip("Z"), "us") for r in rows])
        assert np.array_equal(got["utc"][single].astype("datetime64[us]"), utc[single])


def test_per_series_and_dataframe(db):
    run = db.runs()[0]
    series = db.readings(run.id)
    stored = {(s["device"], s["channel"], s["quantity_name"]): s["count"] for s in db.series(run.id)}
    assert {k: len(v["value"]) for k, v in series.items()} == stored
    for v in series.values():
        assert np.all(np.diff(v["time_ns"]) >= 0)
    import pandas as pd  # scripts/test installs python3-pandas
    df = db.dataframe(run.id, quantities=["air_pressure_pa"])
    assert isinstance(df, pd.DataFrame)
    assert len(df) == sum(n for (d, c, q), n in stored.items() if q == "air_pressure_pa") > 0
    assert set(df["quantity"].astype(str)) == {"air_pressure_pa"}


def test_compensation_tables_round_trip(demo, tmp_path):
    import shutil
    path = tmp_path / "w.sqlite"
    shutil.copy(demo / "demo.sqlite", path)
    with caldaq.open(path, read_only=False) as s:
        run = s.runs()[0]
        table = {"schema": "caldaq.compensation.v1", "axis": "X", "points": [[0, 0.0], [500, 1.5]]}
        new_id = s.add_compensation(run.machine_id, "X", "csv", table, source=f"run {run.id}",
                                    source_run_id=run.id)
        got = [c for c in s.compensations(run.machine_id, "X") if c["id"] == new_id]
        assert got and got[0]["table"] == table and got[0]["source_run_id"] == run.id


def test_read_only_store_refuses_writes_and_missing_files(demo, tmp_path, cli_error):
    with caldaq.open(demo / "demo.sqlite") as s:
        with pytest.raises(caldaq.StoreError):
            s.add_compensation(1, "X", "csv", {})
    missing = tmp_path / "nope.sqlite"
    with pytest.raises(caldaq.StoreError) as e:
        caldaq.open(missing)
    assert isinstance(e.value, OSError) and isinstance(e.value, caldaq.Error)
    assert str(e.value) == cli_error("runs", "--db", missing)
    assert not missing.exists()


def test_an_unknown_run_has_the_cli_message(db, demo, cli_error):
    with pytest.raises(caldaq.InputError) as e:
        db.run(99)
    assert str(e.value) == cli_error("show", 99, "--db", demo / "demo.sqlite")
    with pytest.raises(caldaq.InputError):
        next(db.iter_readings(99))


def test_unknown_quantity_and_bad_chunk_are_input_errors(db):
    run = db.runs()[0]
    with pytest.raises(caldaq.InputError, match="quantity 'speed'"):
        next(db.iter_readings(run.id, quantities=["speed"]))
    with pytest.raises(caldaq.InputError, match="chunk"):
        next(db.iter_readings(run.id, chunk=0))


def test_threads_share_a_store_and_a_stream(db):
    """Four threads draw chunks from one stream of one store: every reading once, none torn."""
    import threading
    run = next(r for r in db.runs() if r.kind == "circle")
    stream = db._c.stream(run.id, [], 997)
    got, lock = [], threading.Lock()

    def drain():
        while (c := stream.next()) is not None:
            assert len(c["time_ns"]) == len(c["value"]) <= 997
            with lock:
                got.append(c)

    threads = [threading.Thread(target=drain) for _ in range(4)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert sum(len(c["value"]) for c in got) == db.reading_count(run.id)
    whole = np.concatenate([c["time_ns"] for c in db.iter_readings(run.id)])
    assert np.array_equal(np.sort(np.concatenate([c["time_ns"] for c in got])), np.sort(whole))
    assert stream.chunks_read > 0
