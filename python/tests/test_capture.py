"""A capture's records read from Python and decoded by the registered drivers: the items of
`daq decode --json` for the same bytes."""
import json

import pytest

import caldaq


def _text(v):
    return json.dumps(v) if isinstance(v, bool) else str(v)


def test_demo_capture_decoded_as_daq_decode(demo, cli, tmp_path):
    cap = caldaq.Capture(demo / "demo.cdq")
    assert cap.header["format"] == "caldaq.capture-header.v1"
    records = list(cap.records())
    assert cap.damage is None and len(records) > 100
    assert {r["kind"] for r in records} >= {"received", "event"}
    decoded = 0
    for inst in cap.header["instruments"]:
        driver = inst["driver"]
        if driver not in caldaq.driver_names():
            continue
        kinds = ("received", "sent") if driver == "ids3010" else ("received",)
        options = {k: _text(v) for k, v in inst.get("options", {}).items()
                   if isinstance(v, (str, int, float, bool))}
        data = b"".join(r["bytes"] for r in records if r["device"] == inst["device"] and r["kind"] in kinds)
        assert data == cap.device_bytes(inst["device"], kinds)
        dump = tmp_path / f"device{inst['device']}.bin"
        dump.write_bytes(data)
        sets = [a for k, v in options.items() for a in ("--set", f"{k}={v}")]
        theirs = cli("decode", driver, dump, *sets, "--json", lines=True)
        mine = cap.decode(inst["device"], driver, options, kinds)
        assert theirs[-1]["type"] == "summary"
        assert {k: theirs[-1][k] for k in mine["summary"]} == mine["summary"]
        assert len(mine["items"]) == len(theirs) - 1
        for m, t in zip(mine["items"], theirs[:-1]):
            assert m["type"] == t["type"] and m["offset"] == t["offset"]
            if m["type"] == "reading":
                assert (m["channel"], m["quantity"], m["value"], m["status"]) == \
                       (t["channel"], t["quantity"], t["value"], t["status"])
            elif m["type"] == "error":
                assert (m["kind"], m["reason"]) == (t["kind"], t["reason"])
            elif m["type"] == "note":
                assert m["text"] == t["text"]
        decoded += mine["summary"]["readings"]
    assert decoded > 1000


def test_decode_errors_are_the_cli_messages(tmp_path, cli_error):
    dump = tmp_path / "x.bin"
    dump.write_bytes(b"P= 1013.2 hPa\r\n")
    with pytest.raises(caldaq.InputError) as e:
        caldaq.decode("nosuch", b"")
    assert str(e.value) == cli_error("decode", "nosuch", dump)
    with pytest.raises(caldaq.InputError) as e:
        caldaq.decode("ptu300", b"", {"nosuchoption": "1"})
    assert str(e.value) == cli_error("decode", "ptu300", dump, "--set", "nosuchoption=1")


def test_a_damaged_capture_says_where(demo, tmp_path):
    data = bytearray((demo / "demo.cdq").read_bytes())
    data[len(data) // 2] ^= 0xFF
    bad = tmp_path / "bad.cdq"
    bad.write_bytes(bytes(data))
    cap = caldaq.Capture(bad)
    n = sum(1 for _ in cap.records())
    assert n > 0 and cap.damage is not None and "block" in cap.damage["text"]
    with pytest.raises(caldaq.CaptureError, match="not-there.cdq"):
        caldaq.Capture(tmp_path / "not-there.cdq")
