"""The objects an operator HMI reads and writes, cycle by cycle over the wire.

A real cnc-service on the step clock (``--clock step``): no cycle runs until the test
writes ``cnc_cycle_step_w``, and the read after the step's reply shows exactly that
cycle. Each test plays a short program and checks what the objects show while it runs:
the rapid override scales G0 (and the feed override no longer does: P-CHAN-00181
ACTIVE), the block skip switch skips lines ``/``, M1 stops only with its switch on,
the coolant state follows M7/M8/M9 and RESET, the distance to go counts down during a
block, and the spindle mode has its value names.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

import pytest

from cnc_objects.clients import Client
from cnc_objects.protocol.values import ChannelState, CoolantState, SpindleMode
from cnc_objects.protocol.wait_reasons import WaitReason
from cnc_objects.testing import ServiceProcess, start_service

STEP = "cnc_cycle_step_w"
X, Y = "ch1.ax1.command_position_acs", "ch1.ax2.command_position_acs"  # 0.1 um
VELOCITY = "ch1.actual_path_velocity"  # um/s
STATE = "ch1.mc_active_state_r"
INCR = 10_000  # 0.1 um per mm
MAX_STEPS = 4_000
AXIS_SPEED_UM_S = 500_000.0  # the default machine's vel_max_mm_s, 500 mm/s


@pytest.fixture(scope="module")
def service() -> Iterator[ServiceProcess]:
    svc = start_service("--clock", "step")
    try:
        yield svc
    finally:
        svc.stop()


@pytest.fixture
def client(service: ServiceProcess) -> Iterator[Client]:
    with Client(service.endpoint) as c:
        _run(c, "origin.nc", "G90 G00 X0 Y0 Z0\nM30\n", cycles_per_step=20)
        yield c
        c.reset()  # RESET between the tests: the channel READY, the switches as left
        for name, value in (("ch1.mc_command_feed_override_w", 1000),
                            ("ch1.mc_command_rapid_override_w", 1000),
                            ("ch1.mc_command_block_ignore_w", 0),
                            ("ch1.mc_command_M01_stop_enable_w", False)):
            c.write(name, value)


@dataclass(frozen=True)
class Cycle:
    """What the HMI read after one step."""

    x_mm: float
    y_mm: float
    velocity_um_s: float
    state: int
    values: dict[str, object]


def _read(client: Client, extra: tuple[str, ...]) -> Cycle:
    got = client.read_many((X, Y, VELOCITY, STATE, *extra))
    return Cycle(got[X] / INCR, got[Y] / INCR, got[VELOCITY], got[STATE],
                 {name: got[name] for name in extra})


def _run(client: Client, name: str, text: str, extra: tuple[str, ...] = (),
         cycles_per_step: int = 1) -> list[Cycle]:
    """Run ``text`` to its end (or to a stop that waits for START), one step at a time;
    every step's reading."""
    client.upload(name, text.encode())
    client.run_program(name)  # applied at once: no cycle is granted
    rows: list[Cycle] = []
    for _ in range(MAX_STEPS):
        client.write(STEP, cycles_per_step)
        row = _read(client, extra)
        rows.append(row)
        if row.state != ChannelState.ACTIVE or client.read("ch1.mc_waiting_for_start_r"):
            return rows
    raise AssertionError(f"{name} did not end within {MAX_STEPS} steps: {rows[-1]}")


def test_rapid_override_scales_g0_and_the_feed_override_only_feed_blocks(
        client: Client) -> None:
    client.write("ch1.mc_command_feed_override_w", 500)  # 50 %
    client.write("ch1.mc_command_rapid_override_w", 250)  # 25 %
    assert client.read("ch1.mc_command_rapid_override_r") == 250
    assert client.read("ch1.mc_active_rapid_override_r") == 250
    assert client.read("ch1.mc_g00_override_mode_r") == 2  # ACTIVE (P-CHAN-00181)
    rows = _run(client, "rapid.nc", "G90 G00 X60\nG01 X80 F6000\nM30\n",
                cycles_per_step=5)
    rapid = max(r.velocity_um_s for r in rows if r.x_mm < 60.0)
    feed = max(r.velocity_um_s for r in rows if 60.0 < r.x_mm < 80.0)
    assert rapid == pytest.approx(0.25 * AXIS_SPEED_UM_S)  # not 50 % of it
    assert feed == pytest.approx(0.5 * 100_000.0)  # F6000 = 100 mm/s at 50 %
    assert rows[-1].x_mm == 80.0


def test_rapid_override_write_out_of_range_is_refused(client: Client) -> None:
    with pytest.raises(Exception, match="0x706|INVALID"):
        client.write("ch1.mc_command_rapid_override_w", 1001)
    assert client.read("ch1.mc_command_rapid_override_r") == 1000


def test_distance_to_go_counts_down_during_the_block(client: Client) -> None:
    extra = ("ch1.ax1.distance_to_go_pcs", "ch1.ax2.distance_to_go_pcs")
    rows = _run(client, "dtg.nc", "G90 G01 X10 Y5 F600\nM30\n", extra)
    moving = [r for r in rows if 0.0 < r.y_mm < 5.0]  # the G01 block: only it moves Y
    assert len(moving) > 100  # about 1100 cycles at 10 mm/s
    for r in moving:  # the end point minus the command position, each cycle
        assert r.values["ch1.ax1.distance_to_go_pcs"] == round((10.0 - r.x_mm) * INCR)
        assert r.values["ch1.ax2.distance_to_go_pcs"] == round((5.0 - r.y_mm) * INCR)
    togo = [r.values["ch1.ax1.distance_to_go_pcs"] for r in moving]
    assert all(b < a for a, b in zip(togo, togo[1:]))  # counts down, cycle by cycle
    assert rows[-1].values["ch1.ax1.distance_to_go_pcs"] == 0  # program ended


@pytest.mark.parametrize(("mask", "end_x_mm"), [(0, 5.0), (1, 1.0), (2, 5.0)])
def test_block_skip_switch_skips_lines_with_a_slash(
        client: Client, mask: int, end_x_mm: float) -> None:
    client.write("ch1.mc_command_block_ignore_w", mask)
    assert client.read("ch1.mc_command_block_ignore_r") == mask
    rows = _run(client, f"skip{mask}.nc",
                "G90 G01 X1 F6000\n/ G01 X5\nG01 Y1\nM30\n")
    assert client.read("ch1.mc_active_block_ignore_r") == mask
    assert (rows[-1].x_mm, rows[-1].y_mm) == (end_x_mm, 1.0)
    assert max(r.x_mm for r in rows) == end_x_mm  # a skipped line never moves


def test_block_skip_beyond_level_10_is_refused(client: Client) -> None:
    with pytest.raises(Exception, match="0x706|INVALID"):
        client.write("ch1.mc_command_block_ignore_w", 0x400)


PROGRAM_M1 = "G90 G01 X1 F6000\nM1\nG01 X2\nM30\n"


def test_optional_stop_switch_off_runs_through_m1(client: Client) -> None:
    assert client.read("ch1.mc_command_M01_stop_enable_r") is False
    rows = _run(client, "m1off.nc", PROGRAM_M1, ("ch1.mc_wait_reason_r",))
    assert rows[-1].x_mm == 2.0 and rows[-1].state != ChannelState.ACTIVE
    assert all(r.values["ch1.mc_wait_reason_r"] != WaitReason.OPTIONAL_STOP for r in rows)


def test_optional_stop_switch_on_stops_at_m1_until_start(client: Client) -> None:
    client.write("ch1.mc_command_M01_stop_enable_w", True)
    assert client.read("ch1.mc_command_M01_stop_enable_r") is True
    rows = _run(client, "m1on.nc", PROGRAM_M1, ("ch1.mc_wait_reason_r",))
    stop = rows[-1]
    assert (stop.x_mm, stop.state) == (1.0, ChannelState.ACTIVE)
    assert stop.values["ch1.mc_wait_reason_r"] == WaitReason.OPTIONAL_STOP
    client.write(STEP, 50)
    assert client.read(X) == 1 * INCR  # it waits for START
    client.start()
    for _ in range(MAX_STEPS):
        client.write(STEP, 10)
        if client.read(STATE) != ChannelState.ACTIVE:
            break
    assert client.read(X) == 2 * INCR


def test_coolant_state_follows_m7_m8_m9(client: Client) -> None:
    rows = _run(client, "coolant.nc",
                "G90 M8\nG01 X1 F6000\nM7\nG01 X2\nM9\nG01 X3\nM30\n",
                ("ch1.mc_coolant_state_r",))
    seen = [(r.x_mm, r.values["ch1.mc_coolant_state_r"]) for r in rows]
    assert all(c == CoolantState.FLOOD for x, c in seen if 0.0 < x < 1.0)
    assert all(c == CoolantState.MIST_AND_FLOOD for x, c in seen if 1.0 < x < 2.0)
    assert all(c == CoolantState.OFF for x, c in seen if 2.0 < x)
    assert {c for _, c in seen} >= {CoolantState.FLOOD, CoolantState.MIST_AND_FLOOD,
                                    CoolantState.OFF}


def test_reset_switches_the_coolant_off(client: Client) -> None:
    client.upload("flood.nc", b"G90 M8\nG01 X10 F600\nM30\n")
    client.run_program("flood.nc")
    client.write(STEP, 200)
    assert client.read("ch1.mc_coolant_state_r") == CoolantState.FLOOD
    client.reset()
    assert client.read("ch1.mc_coolant_state_r") == CoolantState.OFF


def test_spindle_mode_has_its_value_names(client: Client) -> None:
    for name in ("ch1.mc_spindle_mode_r", "gpCh[0].spindle.mode_r"):
        info = client.describe(name)
        assert info.enum == {int(m): m.name for m in SpindleMode}
    assert client.read("ch1.mc_spindle_mode_r") == SpindleMode.M05


def test_tool_name_wear_and_life_in_the_tool_table(client: Client) -> None:
    client.write("ch1.wz[1].name", "Endmill 2 mm")
    client.write("ch1.wz[1].wear", 5000.0)  # 0.5 mm: G41 compensates by 1 + 0.5 mm
    client.write("ch1.wz[1].life_max", 0.5)
    client.write("ch1.wz[1].life_used", 0.0)
    assert client.read_many(["ch1.wz[1].name", "ch1.wz[1].wear", "ch1.wz[1].life_max",
                             "ch1.wz[1].life_expired"]) == {
        "ch1.wz[1].name": "Endmill 2 mm", "ch1.wz[1].wear": 5000.0,
        "ch1.wz[1].life_max": 0.5, "ch1.wz[1].life_expired": False}
    try:
        rows = _run(client, "tool.nc",
                    "G90 T1 M6\nG00 X5 Y-10\nD1 G41 G01 X5 Y0 F600\nG01 X15\n"
                    "G40 G00 X0 Y0\nM30\n", ("ch1.wz[1].life_used",), cycles_per_step=10)
        used = [r.values["ch1.wz[1].life_used"] for r in rows]
        assert used[0] == 0.0 or rows[0].y_mm > -10.0  # nothing cut before the G01
        at_end = max(range(len(rows)), key=lambda k: rows[k].x_mm)  # end of G01 X15
        cutting = [r for r in rows[:at_end] if 6.0 < r.x_mm < 14.0]
        assert cutting and all(r.y_mm == pytest.approx(1.5) for r in cutting)  # worn radius
        assert all(b >= a for a, b in zip(used, used[1:]))
        # about 24 mm of G01 (the approach with G41, X5..X15) at 10 mm/s; G0 adds nothing
        assert 2.0 <= used[-1] <= 2.5
        assert used[at_end + 1:] == [used[-1]] * len(used[at_end + 1:])  # G40 G00 back
        assert client.read("ch1.wz[1].life_expired") is True  # 0.5 s allowed
        client.write("ch1.wz[1].life_used", 0.0)  # a new tool
        assert client.read("ch1.wz[1].life_used") == 0.0
        assert client.read("ch1.wz[1].life_expired") is False
    finally:
        client.write("ch1.wz[1].wear", 0.0)
        client.write("ch1.wz[1].life_max", 0.0)
    with pytest.raises(Exception, match="0x706|INVALID"):
        client.write("ch1.wz[1].life_max", -1.0)


def test_m19_angle_shows_the_oriented_position(client: Client) -> None:
    extra = ("ch1.mc_spindle_position_r", "ch1.mc_spindle_mode_r",
             "ch1.mc_spindle_speed_reached_r")
    rows = _run(client, "orient.nc", "S1000 M3\nG01 X1 F6000\nM19 S.POS=90\n"
                "M19 S.POS=-45\nM30\n", extra)
    seen = [(r.values["ch1.mc_spindle_mode_r"], r.values["ch1.mc_spindle_speed_reached_r"],
             r.values["ch1.mc_spindle_position_r"]) for r in rows]
    braking = [p for mode, reached, p in seen if mode == SpindleMode.M19 and not reached]
    assert braking and all(p in (0.0, 90.0) for p in braking)  # the angle comes at standstill
    assert (SpindleMode.M19, True, 90.0) in seen  # oriented to the first S.POS
    assert seen[-1] == (SpindleMode.M19, True, 315.0)  # -45 degrees, in 0..360


def test_spindle_bracket_syntax_orients_with_pos_modal(client: Client) -> None:
    """ISG's spindle-specific syntax S[...] (issue 39): POS is modal, M19 repeats it."""
    extra = ("ch1.mc_spindle_position_r", "ch1.mc_spindle_mode_r",
             "ch1.mc_spindle_speed_reached_r")
    rows = _run(client, "bracket.nc", "S[M3 REV1000]\nG01 X1 F6000\nS[M19 POS90]\n"
                "S[M3]\nS[M19]\nM30\n", extra)
    assert rows[-1].state == ChannelState.READY
    seen = [(r.values["ch1.mc_spindle_mode_r"], r.values["ch1.mc_spindle_speed_reached_r"],
             r.values["ch1.mc_spindle_position_r"]) for r in rows]
    oriented = seen.index((SpindleMode.M19, True, 90.0))
    assert (SpindleMode.M03, True, 90.0) in seen[oriented:]  # S[M3]: turning again
    assert seen[-1] == (SpindleMode.M19, True, 90.0)  # S[M19]: back to the modal POS90


def test_rapid_override_zero_stands_g0_and_feed_override_zero_does_not(
        client: Client) -> None:
    client.write("ch1.mc_command_feed_override_w", 0)
    client.upload("g0.nc", b"G90 G00 X100\nG01 X101 F6000\nM30\n")
    client.run_program("g0.nc")
    client.write(STEP, 50)
    moved = _read(client, ("ch1.mc_wait_reason_r",))
    assert 0.0 < moved.x_mm < 50.0 and moved.values["ch1.mc_wait_reason_r"] == WaitReason.NONE
    client.write("ch1.mc_command_rapid_override_w", 0)
    client.write(STEP, 200)  # brakes to a stand on the G0
    held = _read(client, ("ch1.mc_wait_reason_r",))
    client.write(STEP, 10)
    assert _read(client, ()).x_mm == held.x_mm < 100.0
    assert held.values["ch1.mc_wait_reason_r"] == WaitReason.OVERRIDE_ZERO


def test_the_plc_commands_the_skip_levels_through_its_control_unit(client: Client) -> None:
    unit = "gpCh[0].decoder_mc_control.program_block_ignore"
    client.write(f"{unit}.command_w", 1)
    client.write(f"{unit}.enable_w", True)  # the PLC's command_w counts, not the HMI's 0
    try:
        rows = _run(client, "plcskip.nc", "G90 G01 X1 F6000\n/ G01 X5\nG01 Y1\nM30\n")
        assert (rows[-1].x_mm, rows[-1].y_mm) == (1.0, 1.0)
        assert client.read_many([f"{unit}.request_r", f"{unit}.state_r",
                                 "ch1.mc_active_block_ignore_r"]) == {
            f"{unit}.request_r": 0, f"{unit}.state_r": 1, "ch1.mc_active_block_ignore_r": 1}
    finally:
        client.write(f"{unit}.enable_w", False)
        client.write(f"{unit}.command_w", 0)
