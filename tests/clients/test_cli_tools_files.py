"""``cnc tool export/import`` and ``cnc offsets export/import`` against a real service (a
fresh one per test): a round trip through a file restores the tables, bad files are
refused before anything is written."""

from __future__ import annotations

import json
from pathlib import Path

from cnc_objects.clients import Client
from cnc_objects.testing import ServiceProcess
from tests.support.cli import cnc

INCR = 10_000  # 0.1 um per mm


def tool_rows(c: Client) -> dict[str, object]:
    return c.read_many(f"ch1.wz[{i}].{f}" for i in range(1, 33)
                       for f in ("valid", "radius", "laenge", "name", "wear", "life_max"))


def offsets(c: Client) -> dict[str, object]:
    return c.read_many(f"ch1.ax{a}.np_grp[{g}].v" for g in range(1, 10) for a in (1, 2, 3))


def test_tool_export_and_import_round_trip(service: ServiceProcess, tmp_path: Path) -> None:
    file = tmp_path / "tools.json"
    e = service.endpoint
    assert cnc("tool", "set", "5", "--radius", "3", "--length", "42", endpoint=e).returncode == 0
    with Client(e, timeout_s=10) as c:
        c.write("ch1.wz[5].name", "end mill 6")
        c.write("ch1.wz[5].wear", 0.01 * INCR)
        before = tool_rows(c)
    done = cnc("tool", "export", str(file), endpoint=e)
    assert done.returncode == 0, done.stderr
    document = json.loads(file.read_text())
    [channel] = document["channels"]
    assert {"wz": 5, "valid": True, "radius_mm": 3.0, "length_mm": 42.0,
            "name": "end mill 6", "wear_mm": 0.01} in channel["tools"]
    assert "zero_offsets" not in channel  # a tools export leaves the offsets alone
    # the operator changes the table: a new row, a row emptied, a length changed
    for args in (("7", "--radius", "1", "--length", "9"), ("2", "--invalid"),
                 ("5", "--length", "40")):
        assert cnc("tool", "set", *args, endpoint=e).returncode == 0
    with Client(e, timeout_s=10) as c:
        c.write("ch1.wz[5].name", "renamed")
    imported = cnc("tool", "import", str(file), endpoint=e)
    assert imported.returncode == 0, imported.stderr
    assert "3 rows written" in imported.stdout
    with Client(e, timeout_s=10) as c:
        assert tool_rows(c) == before


def test_offsets_export_and_import_round_trip(service: ServiceProcess, tmp_path: Path) -> None:
    file = tmp_path / "offsets.json"
    e = service.endpoint
    assert cnc("offsets", "set", "G55", "X=100", "Y=50", "Z=-10", endpoint=e).returncode == 0
    with Client(e, timeout_s=10) as c:
        before = offsets(c)
    assert cnc("offsets", "export", str(file), endpoint=e).returncode == 0
    [channel] = json.loads(file.read_text())["channels"]
    assert channel["zero_offsets"] == [
        {"np_grp": 2, "name": "G55", "offsets_mm": {"X": 100.0, "Y": 50.0, "Z": -10.0}}]
    assert cnc("offsets", "set", "G55", "X=1", endpoint=e).returncode == 0
    assert cnc("offsets", "set", "G57", "Z=3", endpoint=e).returncode == 0
    imported = cnc("offsets", "import", str(file), endpoint=e)
    assert imported.returncode == 0, imported.stderr
    with Client(e, timeout_s=10) as c:
        assert offsets(c) == before


def test_import_refuses_a_bad_file_and_writes_nothing(service: ServiceProcess,
                                                      tmp_path: Path) -> None:
    e = service.endpoint
    with Client(e, timeout_s=10) as c:
        before = tool_rows(c)
    cases = [
        ("not json", "not JSON"),
        ('{"format": "other"}', 'must be "cnc-objects operator data"'),
        ('{"format": "cnc-objects operator data", "version": 1, "channels": [{"channel": 1,'
         ' "tools": [{"wz": 5, "radius_mm": -1}]}]}', "radius_mm: -1 mm is outside"),
        ('{"format": "cnc-objects operator data", "version": 1, "channels": [{"channel": 1,'
         ' "tools": [{"wz": 99, "radius_mm": 1}]}]}', "wz[99] is beyond the tool list"),
        ('{"format": "cnc-objects operator data", "version": 1, "channels": [{"channel": 2,'
         ' "tools": []}]}', "no tools of channel 1"),
    ]
    for k, (text, words) in enumerate(cases):
        file = tmp_path / f"bad{k}.json"
        file.write_text(text)
        result = cnc("tool", "import", str(file), endpoint=e)
        assert result.returncode == 2, (text, result.stderr)
        assert words in result.stderr, result.stderr
    missing = cnc("offsets", "import", str(tmp_path / "none.json"), endpoint=e)
    assert missing.returncode == 2 and "cannot be read" in missing.stderr
    with Client(e, timeout_s=10) as c:
        assert tool_rows(c) == before
