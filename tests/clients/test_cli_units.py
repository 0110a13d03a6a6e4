"""Values in engineering units in ``cnc``: read, watch and write in mm, mm/min and %,
``--raw`` for the object's own value, ``--json`` without float noise, ``cnc lookahead``
in mm; against a real service (a fresh one per test: the tests move axes and write)."""

from __future__ import annotations

import re

from cnc_objects.clients import Client
from cnc_objects.clients.units import noise_free, round_to, tidy
from cnc_objects.testing import ServiceProcess
from tests.support.cli import cnc, json_lines

LONG_DECIMALS = re.compile(r"\d\.\d{7,}")  # float noise: 0.18900000000007822


def moved(endpoint: str) -> None:
    """X to 12.3456 mm, Y to -0.189 mm (0.1 um resolution), as a manual block."""
    done = cnc("mdi", "G01 X12.3456 Y-0.189 F6000", "--wait", endpoint=endpoint)
    assert done.returncode == 0, done.stderr


def test_read_shows_mm_and_percent_and_raw_on_request(service: ServiceProcess) -> None:
    ep = service.endpoint
    moved(ep)
    names = ("ch1.ax1.command_position_acs", "ch1.ax2.command_position_acs",
             "ch1.mc_active_feed_override_r", "ch1.actual_path_velocity", "cnc_cycle_time_r",
             "ch1.mc_active_state_r")
    human = cnc("read", *names, endpoint=ep)
    assert human.returncode == 0, human.stderr
    assert human.stdout.splitlines() == [
        "ch1.ax1.command_position_acs = 12.3456 mm",
        "ch1.ax2.command_position_acs = -0.1890 mm",
        "ch1.mc_active_feed_override_r = 100.0 %",
        "ch1.actual_path_velocity = 0.000 mm/min",  # um/s, read as F is programmed
        "cnc_cycle_time_r = 1000 (us)",  # a unit people read as it is
        "ch1.mc_active_state_r = 3 (READY)",  # an enumeration: its name
    ]
    raw = cnc("read", "--raw", *names[:3], endpoint=ep)
    assert raw.stdout.splitlines() == [
        "ch1.ax1.command_position_acs = 123456 (0.1 um)",
        "ch1.ax2.command_position_acs = -1890 (0.1 um)",
        "ch1.mc_active_feed_override_r = 1000 (0.1 %)",
    ]
    assert json_lines(cnc("--json", "read", *names[1:3], endpoint=ep)) == [
        {"name": "ch1.ax2.command_position_acs", "value": -0.189, "unit": "mm",
         "raw": -1890, "raw_unit": "0.1 um"},
        {"name": "ch1.mc_active_feed_override_r", "value": 100.0, "unit": "%",
         "raw": 1000, "raw_unit": "0.1 %"},
    ]
    assert json_lines(cnc("--json", "read", "--raw", names[1], endpoint=ep)) == [
        {"name": "ch1.ax2.command_position_acs", "value": -1890, "unit": "0.1 um"}]


def test_write_takes_engineering_units_and_raw_on_request(service: ServiceProcess) -> None:
    ep = service.endpoint
    written = cnc("write", "ch1.mc_command_feed_override_w", "75.5", endpoint=ep)
    assert written.returncode == 0, written.stderr
    assert written.stdout.strip() == "ch1.mc_command_feed_override_w := 75.5 %"
    with Client(ep, timeout_s=10) as c:
        assert c.read("ch1.mc_active_feed_override_r") == 755
        assert cnc("write", "--raw", "ch1.mc_command_feed_override_w", "500",
                   endpoint=ep).returncode == 0
        assert c.read("ch1.mc_active_feed_override_r") == 500
        # a REAL object in 0.1 um takes mm too: the tool radius
        assert cnc("write", "ch1.wz[4].radius", "2.5", endpoint=ep).returncode == 0
        assert c.read("ch1.wz[4].radius") == 25_000.0
    record = json_lines(cnc("--json", "write", "ch1.mc_command_feed_override_w", "80",
                            endpoint=ep))
    assert record == [{"name": "ch1.mc_command_feed_override_w", "value": 80.0, "unit": "%",
                       "raw": 800, "raw_unit": "0.1 %", "ok": True}]


def test_watch_shows_engineering_units(service: ServiceProcess) -> None:
    ep = service.endpoint
    moved(ep)
    watched = cnc("--json", "watch", "ch1.ax1.command_position_acs", "--count", "1",
                  endpoint=ep)
    assert watched.returncode == 0, watched.stderr
    [sample] = json_lines(watched)
    assert (sample["value"], sample["unit"], sample["raw"]) == (12.3456, "mm", 123456)
    raw = cnc("watch", "--raw", "ch1.ax1.command_position_acs", "--count", "1", endpoint=ep)
    assert raw.stdout.strip().endswith("ch1.ax1.command_position_acs = 123456 (0.1 um)")
    human = cnc("watch", "ch1.ax1.command_position_acs", "--count", "1", endpoint=ep)
    assert human.stdout.strip().endswith("ch1.ax1.command_position_acs = 12.3456 mm")


def test_json_numbers_have_no_float_noise(service: ServiceProcess) -> None:
    """status, jog, tool and offsets print floats at their resolution: 0.189, not
    0.18900000000000003 (positions from 0.1 um, times from float sums)."""
    ep = service.endpoint
    moved(ep)
    outputs = [cnc("--json", *args, endpoint=ep) for args in (
        ("status",), ("read", "ch1.program_time", "cnc_kernel_time_r", "ch1.ax2.*position*"),
        ("jog", "Y", "+", "--increment", "0.0003"), ("offsets", "show"),
        ("tool", "show"))]
    for result in outputs:
        assert result.returncode == 0, result.stderr
        assert not LONG_DECIMALS.search(result.stdout), result.stdout
    status = json_lines(outputs[0])[0]
    assert status["positions_mm"] == {"X": 12.3456, "Y": -0.189, "Z": 0.0}
    assert json_lines(outputs[2])[0]["position_mm"] == -0.1887  # -0.189 + 0.0003 mm


def test_lookahead_takes_mm(service: ServiceProcess) -> None:
    ep = service.endpoint
    request = "gpCh[0].contour_lookahead.request"
    with Client(ep, timeout_s=10) as c:
        asked = cnc("lookahead", "21", "--length", "20", endpoint=ep)
        assert asked.returncode == 0, asked.stderr
        assert (c.read(f"{request}.start_position"), c.read(f"{request}.length")) == (
            210_000.0, 200_000.0)  # 0.1 um, as the PLC's request holds them
        asked = cnc("lookahead", "1500", "--length", "300", "--raw", endpoint=ep)
        assert asked.returncode == 0, asked.stderr
        assert (c.read(f"{request}.start_position"), c.read(f"{request}.length")) == (
            1500.0, 300.0)
        asked = cnc("lookahead", "3", endpoint=ep)  # mode 1: an index, in no unit
        assert asked.returncode == 0, asked.stderr
        assert (c.read(f"{request}.start_position"), c.read(f"{request}.length")) == (3.0, 0.0)


def test_tidy_rounds_by_the_unit_in_the_key() -> None:
    assert tidy({"program_time_s": 0.18900000000007822, "positions_mm": {"X": 12.34560000001},
                 "path_velocity_mm_s": 1.00049, "count": 3, "name": "x",
                 "ratio": 0.30000000000000004, "list": [0.1 + 0.2]}) == {
        "program_time_s": 0.189, "positions_mm": {"X": 12.3456}, "path_velocity_mm_s": 1.0,
        "count": 3, "name": "x", "ratio": 0.3, "list": [0.3]}
    assert noise_free(0.18900000000007822) == 0.189 and noise_free(1e-20) == 1e-20
    assert str(round_to(-0.00001, 4)) == "0.0"  # no "-0.0"
