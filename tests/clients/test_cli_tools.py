"""``cnc tool`` and ``cnc offsets`` against a real service (a fresh one per test)."""

from __future__ import annotations

from cnc_objects.clients import Client
from cnc_objects.testing import ServiceProcess, run_program
from tests.support.cli import cnc, json_lines


def test_tool_set_and_show(service: ServiceProcess) -> None:
    done = cnc("tool", "set", "7", "--radius", "4.5", "--length", "80",
               endpoint=service.endpoint)
    assert done.returncode == 0, done.stderr
    assert "wz[7] written" in done.stdout
    with Client(service.endpoint, timeout_s=10) as c:
        assert c.read("ch1.wz[7].radius") == 45_000.0
        c.upload("t.nc", b"T7 M6\nD7\nM30\n")
        assert run_program(c, "t.nc").state == "READY"
    shown = cnc("--json", "tool", "show", endpoint=service.endpoint)
    assert shown.returncode == 0, shown.stderr
    active, *rows = json_lines(shown)
    assert active == {"channel": 1, "selected_tool": 7, "active_tool": 7, "d": 7,
                      "radius_mm": 4.5, "length_mm": 80.0}
    assert {"channel": 1, "wz": 7, "valid": True, "radius_mm": 4.5, "length_mm": 80.0} in rows
    assert [r["wz"] for r in rows] == [1, 2, 3, 7, 8, 9]  # the valid rows only
    human = cnc("tool", "show", "--all", endpoint=service.endpoint).stdout
    assert "tool T7 in the spindle (T7 selected), D7: radius 4.5000 mm" in human
    assert "wz[ 32] empty" in human


def test_tool_set_refused_values(service: ServiceProcess) -> None:
    bad = cnc("tool", "set", "3", "--radius", "-1", endpoint=service.endpoint)
    assert bad.returncode == 1
    assert "0x706" in bad.stderr and "wz[3].radius" in bad.stderr and "outside" in bad.stderr
    beyond = cnc("tool", "set", "33", "--radius", "1", endpoint=service.endpoint)
    assert beyond.returncode != 0 and "wz[33]" in beyond.stderr
    nothing = cnc("tool", "set", "3", endpoint=service.endpoint)
    assert nothing.returncode == 2 and "--radius" in nothing.stderr


def test_offsets_set_and_show(service: ServiceProcess) -> None:
    done = cnc("offsets", "set", "G55", "X=12.5", "z=-3", endpoint=service.endpoint)
    assert done.returncode == 0, done.stderr
    with Client(service.endpoint, timeout_s=10) as c:
        c.upload("o.nc", b"G55\nG0 X1 Y2 Z3\nM30\n")
        assert run_program(c, "o.nc").state == "READY"
    shown = cnc("--json", "offsets", "show", endpoint=service.endpoint)
    assert shown.returncode == 0, shown.stderr
    head, *groups = json_lines(shown)
    assert head["active"] == "G55" and head["active_group"] == 2
    assert head["positions_mm"]["X"] == {"acs": 13.5, "pcs": 1.0}
    assert head["positions_mm"]["Z"] == {"acs": 0.0, "pcs": 3.0}
    assert groups[1] == {"channel": 1, "group": 2, "name": "G55",
                         "offsets_mm": {"X": 12.5, "Y": 0.0, "Z": -3.0}}
    assert [g["name"] for g in groups] == ["G54", "G55", "G56", "G57", "G58", "G59",
                                           "G159=7", "G159=8", "G159=9"]
    human = cnc("offsets", "show", endpoint=service.endpoint).stdout
    assert "G55 active (np_grp[2])" in human and "* G55" in human


def test_offsets_set_bad_input(service: ServiceProcess) -> None:
    for args, words in [
        (("G60", "X=1"), "G54..G59"),
        (("G54", "Q=1"), "has the axes X, Y, Z"),
        (("G54", "X:1"), "AXIS=MM"),
    ]:
        result = cnc("offsets", "set", *args, endpoint=service.endpoint)
        assert result.returncode == 2, result.stderr
        assert words in result.stderr
    refused = cnc("offsets", "set", "G54", "X=1e9", endpoint=service.endpoint)
    assert refused.returncode == 1 and "0x706" in refused.stderr
