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
Laptop A also measured (copies of its linear run, as other kinds, at known days after it):
- axis Y: E = 8, 9 at 0, 30 d; a compensation table
  of axis Y stored at 45 d; E = 3, 3.5, 4 at 60, 90, 120 d (M 2 um throughout). The line's window
  starts at the table (45 d): (60, 3), (90, 3.5), (120, 4): 0.5 um / 30 d = 6.0875 um a year,
  E = 3 + (t - 60 d) / 60 d reaches 10 um at t = 480 d; 3 of 5 runs. From a chosen day 90 d on:
  2 runs, not enough history.
- a straightness run E_YX (kind straightness, axis X): straightness 2.0, 2.5, 3.0 um at 0, 30,
  60 d against straightness_um 4 (the by_length entry up to 1000 mm; the axis's own 9): pass;
  the line 2 + t / 60 d reaches 4 um at 120 d. The Y positioning table does not reset it (a
  straightness is reset by a cross table of its direction only): all history.
- an angular run E_BX (pitch, kind angular): range 10 urad against angular_urad 8: FAIL (E_BX),
  outside.
- a roll run E_AX (kind roll): range 5 urad against 8: pass; one run, not enough history.
Laptop B (site "Plant South", "Lathe 2"): its linear run's E set to 3.0 um against a limit of
2.5 um (a FAIL, "outside"); its circle's G limit 1.5 x its G (passes) and a squareness limit half
its squareness (fails), so the fleet's verdict can be compared with daq show's. Its instruments
state no calibration due date. Axis Z (copies of its linear run): the control's compensation off
at 0 and 30 d (E = 0.5, 0.6 um), on at 60, 90, 120 d (E = 2.0 um each): the window starts at
60 d (switched on), a flat line: steady (over all five runs the line would rise: leaving).
Prints, for the test: the first run's start (unix ms) on laptop A, then on laptop B.
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


def set_profile(db, run_id, kind, component, unit, value):
    """Run `run_id` made a profile run of `kind` with one current result: `value` its straightness
    (straightness) or its range (angular, roll), over targets 0 .. 500 mm."""
    db.execute("UPDATE runs SET kind = ? WHERE id = ?", (kind, run_id))
    keep = db.execute("SELECT min(id) FROM results WHERE run_id = ?", (run_id,)).fetchone()[0]
    db.execute("DELETE FROM results WHERE run_id = ? AND id <> ?", (run_id, keep))
    targets = [{"index": i, "position_mm": 50.0 * i, "mean": 0.0, "count": 2, "spread": 0.0,
                "mean_up": 0.0, "mean_down": 0.0} for i in range(11)]
    doc = {"schema": "caldaq.profile.v1", "kind": kind, "component": component, "unit": unit,
           "targets": targets, "range": value}
    if kind == "straightness":
        doc.update({"range": value, "straightness_um": value, "slope_um_per_m": 0.0,
                    "reference": "least squares"})
    db.execute("UPDATE results SET json = ?, standard = 'ISO 230-1:2012', superseded_by = NULL "
               "WHERE id = ?", (json.dumps(doc), keep))


def set_axis(db, run_id, axis):
    db.execute("UPDATE runs SET axis = ? WHERE id = ?", (axis, run_id))


def set_controller_compensation(db, run_id, on):
    s = settings_of(db, run_id)
    s.setdefault("context", {}).setdefault("conditions", {})["controller_compensation"] = on
    set_settings(db, run_id, s)


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
            ctx["tolerances"] = {"E_um": 10, "M_um": 8, "straightness_um": 9, "angular_urad": 8,
                                 "by_length": [{"up_to_mm": 1000, "straightness_um": 4}]}
        set_settings(db, run_id, s)
    linear = run_of(db, "linear")
    set_linear_values(db, linear, 4.0, 2.0)
    for days, e in ((30, 5.0), (60, 6.0)):
        set_linear_values(db, copy_run(db, linear, days * DAY_MS), e, 2.0)
    start = db.execute("SELECT started_unix_ms FROM runs WHERE id = ?", (linear,)).fetchone()[0]
    machine = db.execute("SELECT machine_id FROM runs WHERE id = ?", (linear,)).fetchone()[0]
    for days, e in ((0, 8.0), (30, 9.0), (60, 3.0), (90, 3.5), (120, 4.0)):
        y = copy_run(db, linear, days * DAY_MS)
        set_axis(db, y, "Y")
        set_linear_values(db, y, e, 2.0)
        if days == 30:
            db.execute("INSERT INTO compensations(machine_id, source_run_id, source, axis, format, "
                       "created_unix_ms, json) VALUES (?, ?, ?, 'Y', 'csv', ?, ?)",
                       (machine, y, f"run {y}", start + 45 * DAY_MS,
                        json.dumps({"schema": "caldaq.compensation.v1", "format": "csv"})))
    for days, v in ((0, 2.0), (30, 2.5), (60, 3.0)):
        set_profile(db, copy_run(db, linear, days * DAY_MS), "straightness", "E_YX", "um", v)
    set_profile(db, copy_run(db, linear, 0), "angular", "E_BX", "urad", 10.0)
    set_profile(db, copy_run(db, linear, 0), "roll", "E_AX", "urad", 5.0)
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
    linear = run_of(db, "linear")
    set_linear_values(db, linear, 3.0, 1.0)
    for days, e, on in ((0, 0.5, False), (30, 0.6, False), (60, 2.0, True), (90, 2.0, True),
                        (120, 2.0, True)):
        z = copy_run(db, linear, days * DAY_MS)
        set_axis(db, z, "Z")
        set_controller_compensation(db, z, on)
        set_linear_values(db, z, e, 1.0)
    start = db.execute("SELECT started_unix_ms FROM runs WHERE id = ?", (linear,)).fetchone()[0]
    db.commit()
    return start


if __name__ == "__main__":
    today = datetime.date.fromisoformat(sys.argv[3])
    print(laptop_a(sys.argv[1], today), laptop_b(sys.argv[2]))
