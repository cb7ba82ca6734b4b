"""caldaq for Python: the run store, the analysis library and the captures (docs/python.md).

    import caldaq
    with caldaq.open("caldaq-demo.sqlite") as db:        # read-only unless read_only=False
        run = db.runs()[0]
        for chunk in db.iter_readings(run.id):           # bounded memory, numpy arrays
            ...
        result = caldaq.iso230_2_evaluate(..., standard="vdi3441")

Everything numeric comes from the same C++ code the `daq` command runs, so the numbers are the
CLI's, bit for bit. Errors raise caldaq.Error subclasses with the CLI's messages.
"""
from __future__ import annotations

import json as _json
from dataclasses import dataclass, field
from typing import Any, Dict, Iterator, List, Optional, Sequence

import numpy as np

from . import _caldaq
from ._caldaq import (  # noqa: F401  (re-exported)
    QUANTITIES,
    SCHEMA_VERSION,
    CaptureError,
    Error,
    InputError,
    Model,
    StoreError,
    circle_analyse,
    circular_standards,
    compensation_factor,
    decode,
    driver_names,
    equation_standard_uncertainty,
    iso230_2_evaluate,
    iso230_2_standards,
    model_build,
    refractive_index,
    squareness_from_circle,
    squareness_from_diagonals,
    squareness_from_straightness,
    straightness,
    uncertainty_budget,
    verdict,
)

__all__ = [
    "open", "Store", "Run", "Instrument", "Result", "Capture", "Error", "InputError",
    "StoreError", "CaptureError", "QUANTITIES", "quantity_code", "refractive_index",
    "iso230_2_evaluate", "iso230_2_standards", "circle_analyse", "circular_standards",
    "straightness", "squareness_from_straightness", "squareness_from_diagonals",
    "squareness_from_circle", "uncertainty_budget", "compensation_factor",
    "equation_standard_uncertainty", "decode", "driver_names", "verdict", "Model", "model_build",
]

STATUS = ("ok", "signal_lost", "out_of_range")


def quantity_code(name: str) -> int:
    """The stored number of a quantity name (QUANTITIES), e.g. "displacement_m" -> 0."""
    try:
        return QUANTITIES.index(name)
    except ValueError:
        raise InputError(f"quantity '{name}': expected one of {', '.join(QUANTITIES)}") from None


@dataclass(frozen=True)
class Instrument:
    device: int
    driver: str
    transport: str
    settings: Dict[str, Any]
    origin: str  # real | simulated | replay | imported | "" (stored before schema 5)
    origin_detail: str


@dataclass(frozen=True)
class Run:
    id: int
    machine_id: int
    campaign: str
    kind: str
    axis: str
    settings: Dict[str, Any]
    capture_path: str
    software_version: str
    started_unix_ms: int
    ended_unix_ms: Optional[int]
    status: str
    note: str
    origin_session_ns: Optional[int]
    origin_unix_ns: Optional[int]


@dataclass(frozen=True)
class Result:
    id: int
    standard: str
    result: Dict[str, Any]
    provenance: Dict[str, Any]
    created_unix_ms: int
    current: bool
    superseded_by: Optional[int]
    # Pass/fail against the run's tolerances, as `daq show RUN --json` gives it: configured,
    # pass, summary ("PASS", "FAIL", "no tolerance configured"), basis, checks, notes.
    verdict: Optional[Dict[str, Any]] = None


def _run(d: dict) -> Run:
    d = dict(d)
    d["settings"] = _json.loads(d.pop("settings_json") or "{}")
    return Run(**d)


class Store:
    """A caldaq database. Read-only by default: nothing is created, migrated or changed, as for
    the CLI's reading commands. Use as a context manager or call close()."""

    def __init__(self, path: str, read_only: bool = True):
        self._db = _caldaq.Store(str(path), read_only)

    # -- lifetime -------------------------------------------------------------------------
    def close(self) -> None:
        self._db = None

    def __enter__(self) -> "Store":
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()

    @property
    def _c(self) -> Any:
        if self._db is None:
            raise StoreError("the store is closed")
        return self._db

    @property
    def path(self) -> str:
        return self._c.path

    @property
    def version(self) -> int:
        return self._c.version

    # -- runs -----------------------------------------------------------------------------
    def runs(self) -> List[Run]:
        return [_run(r) for r in self._c.runs()]

    def run(self, run_id: int) -> Run:
        r = self._c.run(run_id)
        if r is None:
            raise InputError(f"{self.path}: no run {run_id} (see daq runs)")
        return _run(r)

    def instruments(self, run_id: int) -> List[Instrument]:
        out = []
        for i in self._c.instruments(run_id):
            i = dict(i)
            i["settings"] = _json.loads(i.pop("settings_json") or "{}")
            out.append(Instrument(**i))
        return out

    def origin(self, run_id: int) -> str:
        """Where the run's readings came from: "real", "simulated", "replay", "imported", or ""
        (not recorded); "mixed" when its instruments differ."""
        origins = {i.origin for i in self.instruments(run_id)}
        return origins.pop() if len(origins) == 1 else ("mixed" if origins else "")

    def machine(self, machine_id: int) -> Optional[Dict[str, Any]]:
        m = self._c.machine(machine_id)
        if m is not None:
            m["config"] = _json.loads(m.pop("config_json") or "{}")
        return m

    def series(self, run_id: int) -> List[Dict[str, Any]]:
        out = self._c.series(run_id)
        for s in out:
            s["quantity_name"] = QUANTITIES[s["quantity"]]
        return out

    def reading_count(self, run_id: int) -> int:
        return self._c.reading_count(run_id)

    def targets(self, run_id: int) -> List[Dict[str, Any]]:
        return self._c.targets(run_id)

    def results(self, run_id: int, current_only: bool = False) -> List[Result]:
        settings = self._c.run(run_id)
        settings = settings["settings_json"] if settings else "{}"
        out = []
        for r in self._c.results(run_id):
            if current_only and not r["current"]:
                continue
            try:
                doc = _json.loads(r["json"] or "{}")
            except ValueError:
                doc = None
            out.append(Result(id=r["id"], standard=r["standard"], result=doc,
                              provenance=_json.loads(r["provenance_json"] or "{}"),
                              created_unix_ms=r["created_unix_ms"], current=r["current"],
                              superseded_by=r["superseded_by"],
                              verdict=None if doc is None else _caldaq.verdict(settings, r["json"])))
        return out

    def missed_stops(self, run_id: int) -> List[Dict[str, Any]]:
        return self._c.missed_stops(run_id)

    def quality(self, run_id: int) -> Optional[Dict[str, Any]]:
        """The stored stop quality (state ok/suspect/not checked, summary, suspect stops), or
        None when never stored (runs before schema 5, imports)."""
        return self._c.quality(run_id)

    def compensations(self, machine_id: int = 0, axis: str = "") -> List[Dict[str, Any]]:
        out = self._c.compensations(machine_id, axis)
        for c in out:
            c["table"] = _json.loads(c.pop("json") or "{}")
        return out

    def add_compensation(self, machine_id: int, axis: str, format: str, table: Dict[str, Any],
                         source: str = "", source_run_id: int = 0) -> int:
        return self._c.add_compensation(machine_id, axis, format, _json.dumps(table), source,
                                        source_run_id)

    # -- writing (read_only=False) ---------------------------------------------------------
    def add_machine(self, name: str, description: str = "") -> int:
        return self._c.add_machine(name, description)

    def begin_run(self, machine_id: int, kind: str, axis: str = "", campaign: str = "",
                  settings: Optional[Dict[str, Any]] = None) -> int:
        return self._c.begin_run(machine_id, kind, axis, campaign, _json.dumps(settings or {}))

    def add_instrument(self, run_id: int, device: int, driver: str, transport: str = "",
                       origin: str = "imported", origin_detail: str = "") -> None:
        self._c.add_instrument(run_id, device, driver, transport, origin, origin_detail)

    def append_readings(self, run_id: int, time_ns: Any, value: Any, device: Any = 0,
                        channel: Any = 0, quantity: Any = "displacement_m", status: Any = 0) -> None:
        """Stores readings in one transaction; device, channel, quantity (a name or a code) and
        status may be single values for the whole batch."""
        time_ns = np.ascontiguousarray(time_ns, dtype=np.int64)
        if isinstance(quantity, str):
            quantity = quantity_code(quantity)
        n = time_ns.shape[0]
        col = lambda v, t: np.ascontiguousarray(np.broadcast_to(np.asarray(v, dtype=t), (n,)))
        self._c.append_readings(run_id, time_ns, col(device, np.uint16), col(channel, np.uint8),
                                col(quantity, np.uint8), col(status, np.uint8), col(value, np.float64))

    def set_time_origin(self, run_id: int, session_ns: int, unix_ns: int) -> None:
        self._c.set_time_origin(run_id, session_ns, unix_ns)

    def finish_run(self, run_id: int, status: str = "complete", note: str = "") -> None:
        self._c.finish_run(run_id, status, note)

    # -- readings -------------------------------------------------------------------------
    def iter_readings(self, run_id: int, quantities: Sequence[str] = (), chunk: int = 65536,
                      compensated: bool = False) -> Iterator[Dict[str, np.ndarray]]:
        """The run's readings, `chunk` at a time, as dicts of numpy arrays, in the order and with
        the times of `daq export`: time_ns (stored session time), time_s (seconds from the run's
        start), utc (datetime64[ns], NaT without a time origin), device, channel, quantity (code;
        QUANTITIES names it), status (0 ok, 1 signal lost, 2 out of range), value (SI, raw:
        uncompensated). Readings that came in one transport read (a ballbar's lines) share their
        time_ns; time_s and utc spread them back by the sample period, as the export does.

        compensated=True (a linear run) adds compensated (the laser's displacement as a length
        at 20 degC, m), refractive_index and material_temperature_degc: each laser reading
        compensated as the acquisition's pipeline did it, NaN for the other readings. Memory is
        bounded by the chunk size whatever the run's length."""
        self.run(run_id)  # the CLI's message for an unknown run
        codes = [quantity_code(q) for q in quantities]
        stream = self._c.stream(run_id, codes, chunk, compensated)
        while True:
            c = stream.next()
            if c is None:
                return
            c["utc"] = c.pop("utc_ns").view("datetime64[ns]")  # int64 min is NaT
            yield c

    def readings(self, run_id: int, quantities: Sequence[str] = (),
                 compensated: bool = False) -> Dict[tuple, Dict[str, np.ndarray]]:
        """Every reading of the run per series, {(device, channel, quantity name): arrays} (the
        arrays of iter_readings, less device/channel/quantity). Holds the whole run: for long
        runs, iterate with iter_readings."""
        names = ["time_ns", "time_s", "utc", "status", "value"]
        if compensated:
            names += ["compensated", "refractive_index", "material_temperature_degc"]
        parts: Dict[tuple, Dict[str, list]] = {}
        for c in self.iter_readings(run_id, quantities, compensated=compensated):
            keys = (c["device"].astype(np.int64) << 16) | (c["channel"].astype(np.int64) << 8) | c["quantity"]
            for k in np.unique(keys):
                mask = keys == k
                key = (int(k >> 16), int((k >> 8) & 0xFF), QUANTITIES[int(k & 0xFF)])
                slot = parts.setdefault(key, {n: [] for n in names})
                for n in slot:
                    slot[n].append(c[n][mask])
        return {k: {n: np.concatenate(v) for n, v in s.items()} for k, s in parts.items()}

    def dataframe(self, run_id: int, quantities: Sequence[str] = (), compensated: bool = False) -> Any:
        """The run's readings as a pandas DataFrame (needs pandas), one row per reading, with
        the columns of iter_readings and quantity as its name."""
        try:
            import pandas as pd
        except ImportError as e:
            raise ImportError("caldaq.Store.dataframe needs pandas (Debian: python3-pandas)") from e
        frames = [pd.DataFrame(c) for c in self.iter_readings(run_id, quantities, compensated=compensated)]
        columns = ["time_ns", "device", "channel", "quantity", "status", "value", "time_s", "utc"]
        if compensated:
            columns += ["compensated", "refractive_index", "material_temperature_degc"]
        df = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame(columns=columns)
        df["quantity"] = pd.Categorical.from_codes(df["quantity"].astype(int), categories=list(QUANTITIES))
        return df

    def deviations(self, run_id: int) -> Dict[str, np.ndarray]:
        """A linear run's captured stops as arrays: target_mm, run, direction ("up"/"down"),
        deviation_um (compensated, at 20 degC), raw_m, refractive_index,
        material_temperature_degc, target_index: what iso230_2_evaluate takes."""
        ts = self.targets(run_id)
        return {
            "target_mm": np.array([t["nominal_mm"] for t in ts], dtype=float),
            "run": np.array([t["run"] for t in ts], dtype=np.int32),
            "direction": [t["direction"] for t in ts],
            "deviation_um": np.array([t["deviation_um"] for t in ts], dtype=float),
            "raw_m": np.array([t["raw_m"] for t in ts], dtype=float),
            "refractive_index": np.array([t["refractive_index"] for t in ts], dtype=float),
            "material_temperature_degc": np.array([t["material_temperature_degc"] for t in ts], dtype=float),
            "target_index": np.array([t["target_index"] for t in ts], dtype=np.int32),
        }

    def evaluate(self, run_id: int, standard: str = "iso230-2:2014") -> Dict[str, Any]:
        """The run's stops evaluated under a standard (as `daq analyse RUN --standard`)."""
        d = self.deviations(run_id)
        return iso230_2_evaluate(d["target_mm"], d["run"], d["direction"], d["deviation_um"], standard)


def open(path: str, read_only: bool = True) -> Store:  # noqa: A001 (as io.open)
    """Opens a caldaq database (read-only by default)."""
    return Store(path, read_only)


@dataclass
class Capture:
    """A wire-level capture (.cdq): its header and its records, read in order."""
    path: str
    header: Dict[str, Any] = field(init=False)
    damage: Optional[Dict[str, Any]] = field(init=False, default=None)

    def __post_init__(self) -> None:
        r = _caldaq.CaptureReader(str(self.path))
        self.header = _json.loads(r.header_json or "{}")

    def records(self) -> Iterator[Dict[str, Any]]:
        """Each record: time_ns, device, kind (received/sent/event), bytes. After the last one,
        `damage` says where a damaged or truncated file stopped (None when whole)."""
        r = _caldaq.CaptureReader(str(self.path))
        while (rec := r.next()) is not None:
            yield rec
        self.damage = r.damage

    def device_bytes(self, device: int, kinds: Sequence[str] = ("received",)) -> bytes:
        """The bytes of one device's records of these kinds, concatenated in order: what
        `daq decode` reads (the IDS3010 takes both directions: kinds=("received", "sent"))."""
        return b"".join(r["bytes"] for r in self.records()
                        if r["device"] == device and r["kind"] in kinds)

    def decode(self, device: int, driver: str, options: Optional[Dict[str, str]] = None,
               kinds: Sequence[str] = ("received",)) -> Dict[str, Any]:
        """The device's bytes through a registered driver's decoder (see caldaq.decode)."""
        return decode(driver, self.device_bytes(device, kinds), options or {})
