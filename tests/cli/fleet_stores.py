"""Shapes two laptops' stores for the fleet view's test (pg_fleet_test.sh): each a `daq demo`
store (one linear run of X, one circle in XY), given its machine's name and site, the tolerances
and instruments its runs were made with, and known values, so that the fleet's answers can be
computed by hand.

Usage: fleet_stores.py A.sqlite B.sqlite TODAY(YYYY-MM-DD)

Laptop A (site "Plant North", a machine whose name holds markup): the linear run's result set to
E = 4 um, M = 2 um, and two copies of that run 30 and 60 days later with E = 5 and 6 um, M = 2 um;
limits E 10 um, M 8 um. By hand: the least-squares line through (0 d, 4), (30 d, 5), (60 d, 6) is
E = 4 + t / 30 d, which reaches 10 um at t = 180 d after the first run; M is flat (steady).
Instruments: laser L-100 due 10 days before TODAY (past due), thermometer T-7 due in 12 days (due
soon), barometer P-3 due in 200 days (ok).
Laptop B (site "Plant South", "Lathe 2"): its linear run's E set to 3.0 um against a limit of
2.5 um (a FAIL, "outside"); its circle's G limit 1.5 x its G (passes) and a squareness limit half
its squareness (fails), so the fleet's verdict can be compared with daq show's. Its instruments
state no calibration due date.
Prints, for the test: the first run's start (unix ms) on laptop A.
"""
import datetime
import json
import sqlite3
import sys
import uuid

DAY_MS = 86_400_000
MARKUP_NAME = 'Mill <script>window.pwned=1</script><img src=x onerror="window.pwned=2"> & Co'


def settings_of(db, run_id):
    return json.loads(db.execute("SELECT settings_json FROM runs WHERE id = ?", (run_id,)).fetchone()[0])


def set_settings(db, run_id, s):
    db.execute("UPDATE runs SET settings_json = ? WHERE id = ?", (json.dumps(s), run_id))


def set_linear_values(db, run_id, e_um, m_um):
    for rid, doc in db.execute("SELECT id, json FROM results WHERE run_id = ?", (run_id,)).fetchall():
        d = json.loads(doc)
        d["axis"]["E_bi"]["value_um"] = e_um
        d["axis"]["M"]["value_um"] = m_um
        db.execute("UPDATE results SET json = ? WHERE id = ?", (json.dumps(d), rid))


def copy_run(db, run_id, later_ms):
    """A copy of run `run_id` (its row and results) started `later_ms` after it; its id."""
    cols = [r[1] for r in db.execute("PRAGMA table_info(runs)") if r[1] not in ("id", "uuid")]
    c = ", ".join(cols)
    db.execute(f"INSERT INTO runs (uuid, {c}) SELECT ?, {c} FROM runs WHERE id = ?",
               (str(uuid.uuid4()), run_id))
    new = db.execute("SELECT last_insert_rowid()").fetchone()[0]
    db.execute("UPDATE runs SET started_unix_ms = started_unix_ms + ?, ended_unix_ms = "
               "ended_unix_ms + ? WHERE id = ?", (later_ms, later_ms, new))
    rcols = [r[1] for r in db.execute("PRAGMA table_info(results)") if r[1] not in ("id", "run_id")]
    rc = ", ".join(rcols)
    db.execute(f"INSERT INTO results (run_id, {rc}) SELECT ?, {rc} FROM results WHERE run_id = ?",
               (new, run_id))
    return new


def run_of(db, kind):
    return db.execute("SELECT id FROM runs WHERE kind = ? ORDER BY id LIMIT 1", (kind,)).fetchone()[0]


def laptop_a(path, today):
    db = sqlite3.connect(path)
    db.execute("UPDATE machines SET name = ?", (MARKUP_NAME,))
    due = lambda days: (today + datetime.timedelta(days=days)).isoformat()  # noqa: E731
    instruments = [
        {"id": "laser", "role": "laser", "driver": "ids3010", "serial_number": "L-100",
         "certificate": "C-1", "calibration_due": due(-10)},
        {"id": "material", "role": "thermometer", "driver": "pt100", "serial_number": "T-7",
         "certificate": "C-2", "calibration_due": due(12)},
        {"id": "air", "role": "barometer", "driver": "ptu300", "serial_number": "P-3",
         "certificate": "C-3", "calibration_due": due(200)}]
    for (run_id, kind) in db.execute("SELECT id, kind FROM runs").fetchall():
        s = settings_of(db, run_id)
        ctx = s.setdefault("context", {})
        ctx["customer"] = {"name": "Acme", "site": "Plant North", "contact": ""}
        ctx["instruments"] = instruments
        if kind == "linear":
            ctx["tolerances"] = {"E_um": 10, "M_um": 8}
        set_settings(db, run_id, s)
    linear = run_of(db, "linear")
    set_linear_values(db, linear, 4.0, 2.0)
    for days, e in ((30, 5.0), (60, 6.0)):
        set_linear_values(db, copy_run(db, linear, days * DAY_MS), e, 2.0)
    start = db.execute("SELECT started_unix_ms FROM runs WHERE id = ?", (linear,)).fetchone()[0]
    db.commit()
    return start


def laptop_b(path):
    db = sqlite3.connect(path)
    db.execute("UPDATE machines SET name = 'Lathe 2'")
    circle = run_of(db, "circle")
    circle_doc = json.loads(db.execute(
        "SELECT json FROM results WHERE run_id = ? AND superseded_by IS NULL", (circle,)).fetchone()[0])
    g = circle_doc["iso230_4"]["G_bi_um"]
    squareness = [d["value"] for d in circle_doc.get("diagnostics", []) if d["key"] == "squareness"]
    for (run_id, kind) in db.execute("SELECT id, kind FROM runs").fetchall():
        s = settings_of(db, run_id)
        ctx = s.setdefault("context", {})
        ctx["customer"] = {"name": "Acme", "site": "Plant South", "contact": ""}
        for i in ctx.get("instruments") or []:
            i["calibration_due"] = ""
        if kind == "linear":
            ctx["tolerances"] = {"E_um": 2.5}
        elif kind == "circle":
            ctx["tolerances"] = {"G_um": round(1.5 * g, 3)}
            if squareness:
                ctx["tolerances"]["diagnostics"] = {"squareness": round(abs(squareness[0]) / 2, 3)}
        set_settings(db, run_id, s)
    set_linear_values(db, run_of(db, "linear"), 3.0, 1.0)
    db.commit()


if __name__ == "__main__":
    today = datetime.date.fromisoformat(sys.argv[3])
    print(laptop_a(sys.argv[1], today))
    laptop_b(sys.argv[2])
