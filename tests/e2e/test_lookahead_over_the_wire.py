"""The enhanced look-ahead over the wire: the limits the planner uses are objects, a
program of 5 um chords with a 30-block buffer is slowed down by the buffer (and says
so with warning 50301), and the same program inside LA_ON .. LA_OFF runs at the speed
the machine can do, never faster than the axes allow."""

from __future__ import annotations

import math

import pytest

from cnc_objects.clients import AdsError, Client
from cnc_objects.testing import run_program

# The machine of every test here: channel 1 with the low look-ahead buffer (30 blocks).
pytestmark = pytest.mark.cnc_service(config="data/low-buffer-machine.toml")

FEED_MM_MIN = 6000.0


def _chords(radius_mm: float, chord_mm: float = 0.005, la_on: bool = False) -> bytes:
    """A full circle (centre (r, 0), from the origin) as straight chords."""
    n = round(2 * math.pi * radius_mm / chord_mm)
    lines = [f"G01 F{FEED_MM_MIN:g}"] + (["LA_ON"] if la_on else [])
    for k in range(1, n + 1):
        angle = math.pi - 2 * math.pi * k / n  # clockwise from (0, 0)
        x = radius_mm + radius_mm * math.cos(angle)
        y = radius_mm * math.sin(angle)
        lines.append(f"X{x:.9f} Y{y:.9f}")
    lines += (["LA_OFF"] if la_on else []) + ["M30", ""]
    return "\n".join(lines).encode()


def test_limits_and_buffer_size_are_read_only_objects(cnc_client: Client) -> None:
    api = cnc_client
    assert api.read_many(["ch1.lookahead_blocks", "ch1.ax1.vel_max", "ch1.ax2.acc_max",
                          "ch1.ax3.vel_jump_max"]) == {
        "ch1.lookahead_blocks": 30, "ch1.ax1.vel_max": 500.0, "ch1.ax2.acc_max": 5000.0,
        "ch1.ax3.vel_jump_max": 20.0}
    with pytest.raises(AdsError) as info:
        api.write("ch1.lookahead_blocks", 190)
    assert info.value.code == 0x704
    assert api.read("ch1.lookahead_blocks") == 30


def test_la_on_runs_short_blocks_at_speed_the_buffer_alone_cannot(cnc_client: Client) -> None:
    api = cnc_client
    api.upload("chords.nc", _chords(2.0))
    api.upload("chords-la.nc", _chords(2.0, la_on=True))
    slow_s = run_program(api, "chords.nc", timeout_s=60).program_time_s
    warnings = api.channel_errors(1)
    assert len(warnings) == 1 and warnings[0].startswith("warning 50301"), warnings
    assert "buffer of 30 blocks limits the path speed" in warnings[0]
    fast_s = run_program(api, "chords-la.nc", timeout_s=60).program_time_s
    assert api.read("ch1.mc_error_count_r") == 0, api.channel_errors(1)
    # ends exactly at the programmed end point (the origin)
    assert [api.read(f"ch1.ax{a}.command_position_acs") for a in (1, 2)] == [0, 0]
    # 2513 chords of 5 um = 12.57 mm at F6000 (100 mm/s): 126 ms of cruise plus 20 ms
    # of ramps; with 30 blocks (150 um) ahead the path may not exceed
    # sqrt(2 a 150 um) ~ 39 mm/s; LA_ON's block rate allows 29 blocks/ms = 145 mm/s
    assert fast_s < 0.150
    assert slow_s > 2.2 * fast_s
