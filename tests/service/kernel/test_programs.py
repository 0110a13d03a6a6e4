"""NC programs run by the real kernel on the virtual clock, with their expected outcome.

Data-driven: each case is a program and what must come out (final positions, the error
with its line, the machining time from the closed-form trapezoid of the documented
model). Default machine: X/Y/Z with V = 500 mm/s, A = 5000 mm/s², ΔV = 20 mm/s, 1 ms cycle.
"""

from __future__ import annotations

import math

import pytest

from cnc_objects.service.kernel.channel_mode import ChannelMode, ChannelState
from cnc_objects.service.kernel.commands import (
    Feedhold,
    ManualBlock,
    RefusalReason,
    ResetChannel,
    SelectProgram,
    SetExecutionMode,
    SetSingleBlock,
    StartProgram,
)

CYCLE_S = 0.001
V, A = 500.0, 5000.0


def trapezoid_s(length_mm: float, v_mm_s: float, a_mm_s2: float) -> float:
    """Time of a rest-to-rest move with constant acceleration and a speed limit."""
    if length_mm >= v_mm_s**2 / a_mm_s2:
        return length_mm / v_mm_s + v_mm_s / a_mm_s2
    return 2.0 * math.sqrt(length_mm / a_mm_s2)


@pytest.fixture(autouse=True)
def fresh_channel(kernel):
    """Every test starts from RESET at the origin."""
    kernel.command(ResetChannel(0, True))
    kernel.mdi("G90 G0 X0 Y0 Z0")
    yield


# (program, final X/Y/Z in mm, closed-form machining time in s or None, stops)
FINISHING = {
    "single line": ("G1 X100 F6000\nM30\n", (100, 0, 0), trapezoid_s(100, 100, A), 2),
    "diagonal line": (
        "G1 X100 Y100 F6000\nM30\n", (100, 100, 0),
        trapezoid_s(math.hypot(100, 100), 100, A * math.sqrt(2)), 2,
    ),
    "collinear lines are one trapezoid": (
        "G1 X25 F6000\nX50\nX75\nX100\nM30\n", (100, 0, 0), trapezoid_s(100, 100, A), 2,
    ),
    "short move never reaches F": ("G1 X1 F30000\nM30\n", (1, 0, 0), trapezoid_s(1, 500, A), 2),
    "dwell adds its time": (
        "G1 X10 F6000\nG4 X0.5\nG1 X20\nM30\n", (20, 0, 0),
        2 * trapezoid_s(10, 100, A) + 0.5, 4,
    ),
    "incremental": ("G91 G1 X10 Y-5 F600\nX10 Y-5\nM30\n", (20, -10, 0), None, 2),
    "rapid then feed": ("G0 X50 Y50 Z10\nG1 Z0 F300\nM30\n", (50, 50, 0), None, 3),
    "full circle ends where it began": (
        "G0 X10\nG2 X10 Y0 I-10 J0 F3000\nM30\n", (10, 0, 0), None, 3,
    ),
    "subprogram loop": (
        "%main\n#VAR\nV.P.I = 0\n#ENDVAR\n$FOR V.P.I = 1, 4, 1\nLL STEP\n$ENDFOR\nM30\n"
        "%L STEP\nG91 G1 X2.5 F600\nM17\n",
        (10, 0, 0), None, 2,
    ),
}


@pytest.mark.parametrize("case", FINISHING, ids=list(FINISHING))
def test_program_finishes_where_and_when_expected(kernel, case) -> None:
    text, final, time_s, stops = FINISHING[case]
    run = kernel.run(text)
    ch = run.channel
    assert ch.state == ChannelState.READY and ch.mode == ChannelMode.AUTOMATIC, ch.errors.entries
    assert run.positions_mm == pytest.approx(final, abs=1e-9)
    drives = [p.command_position_01um for p in run.final.physical_axes]
    assert drives == [round(x * 10_000) for x in final]  # physical axes followed
    if time_s is not None:
        assert abs(ch.path.program_time_s - time_s) <= (stops + 1) * CYCLE_S, (ch.path.program_time_s, time_s)


# (program, error line, error column, final X in mm)
FAILING = {
    "unknown word": ("G1 X10 F600\nX20\nQ5\nM30\n", 3, 1, 20.0),
    "no feed for G1": ("G1 X10\nM30\n", 1, None, 0.0),
    "software limit: no move": ("G1 X5000 F600\nM30\n", 1, None, 0.0),
    "limit after a good block": ("G1 X10 F600\nG1 X-2000\nM30\n", 2, None, 10.0),
    "missing M30": ("G1 X10 F600\n", None, None, 10.0),
    "goto unknown label": ("G1 X1 F600\n$GOTO [NOWHERE]\nM30\n", 2, None, 1.0),
    # radius compensation holds a block back until the next: the error must release it
    "error after a compensated block": (
        "G41 D1 G1 X10 Y0 F600\nX20\nQ5\nM30\n", 3, 1, 20.0),
    # the held block fails only when released at the end of the data (limit with r = 5);
    # its approach line, released before, has run: X ends at the offset start point
    "limit of a compensated block at the end": (
        "G0 Y990\nG41 D3 G1 X20 Y998 F6000\nM30\n", 2, None, -5 * 8 / math.hypot(20, 8)),
}


@pytest.mark.parametrize("case", FAILING, ids=list(FAILING))
def test_wrong_program_stops_with_a_precise_error(kernel, case) -> None:
    text, line, column, final_x = FAILING[case]
    kernel.home()  # the software limits count once the axes are referenced (P-AXIS-00705)
    run = kernel.run(text, name="bad.nc")
    ch = run.channel
    assert ch.state == ChannelState.ERROR
    assert ch.errors.count >= 1
    error = ch.errors.entries[0]
    assert error.id > 0 and error.text
    assert error.file == "bad.nc"
    if line is not None:
        assert error.line == line, error
    if column is not None:
        assert error.column == column, error
    assert run.positions_mm[0] == pytest.approx(final_x, abs=1e-9)
    assert kernel.command(ResetChannel(0, True)) is None
    assert kernel.kernel.snapshot.channels[0].state == ChannelState.READY
    assert kernel.kernel.snapshot.channels[0].errors.entries == ()


def test_same_program_twice_gives_the_same_cycles(kernel) -> None:
    text = "G1 X20 Y10 F3000\nG2 X40 Y10 I10 J0\nG1 Y-10\nG3 X20 Y-10 R10\nG0 X0 Y0\nM30\n"
    def moving(samples: list) -> list:
        """The positions from the cycle before the first that moves to the first that
        stands at the end: the decoder thread hands the first block over after a cycle
        or two more or less (1 run in 4 under load), and the recording ends a cycle or
        two after READY (the harness's wait), so the standing cycles around the motion
        are not the program's."""
        positions = [s.positions_mm for s in samples]
        start = next(k for k, p in enumerate(positions) if p != positions[0])
        end = next(k for k in range(len(positions) - 1, 0, -1)
                   if positions[k - 1] != positions[-1])
        return positions[start - 1:end + 1]

    first = kernel.run(text, record=True).samples
    kernel.mdi("G90 G0 X0 Y0 Z0")
    second = kernel.run(text, record=True).samples
    assert len(first) > 100
    assert moving(first) == moving(second)


def test_axis_speed_and_acceleration_stay_within_limits_inside_blocks(kernel) -> None:
    text = (
        "G1 X30 Y10 F12000\nG2 X50 Y30 I0 J20\nG1 X50 Y60\nG3 X30 Y80 I-20 J0\n"
        "G1 X-20 Y40 Z5\nG0 X0 Y0 Z0\nM30\n"
    )
    samples = kernel.run(text, record=True).samples
    pos = [s.positions_mm for s in samples]
    blocks = [s.block_count for s in samples]
    for k in range(2, len(pos)):
        if blocks[k] != blocks[k - 2]:
            continue  # a junction lies in this window: the model allows the ΔV jump there
        for axis in range(3):
            v1 = (pos[k - 1][axis] - pos[k - 2][axis]) / CYCLE_S
            v2 = (pos[k][axis] - pos[k - 1][axis]) / CYCLE_S
            assert abs(v2) <= V * (1 + 1e-9)
            assert abs(v2 - v1) / CYCLE_S <= A * (1 + 1e-6) + 1e-6, (k, axis, v1, v2)


def test_arc_samples_lie_on_the_circle(kernel) -> None:
    run = kernel.run("G0 X20 Y0\nG3 X-20 Y0 I-20 J0 F6000\nG3 X20 Y0 R20\nM30\n", record=True)
    on_arc = [s.positions_mm for s in run.samples if s.block_count >= 1 and s.state == 4]
    assert len(on_arc) > 50
    for x, y, _ in on_arc[:-1]:
        if abs(x - 20) < 1e-12 and abs(y) < 1e-12:
            continue
        assert math.hypot(x, y) == pytest.approx(20.0, abs=1e-6)


def test_feedhold_stops_within_limits_and_resume_finishes(kernel) -> None:
    kernel.start("G1 X200 F12000\nM30\n", record=True)
    kernel.wait_for(lambda s: s.channels[0].path.path_velocity_mm_s >= 199.0)
    assert kernel.command(Feedhold(0, True)) is None
    held = kernel.wait_for(lambda s: s.channels[0].path.path_velocity_mm_s == 0.0)
    ch = held.channels[0]
    assert ch.state == ChannelState.HOLD
    assert 0 < ch.axes[0].position_mm < 200
    assert kernel.command(StartProgram(0, True)) is None
    run = kernel.wait()
    assert run.positions_mm[0] == pytest.approx(200.0, abs=1e-9)
    v = [s.path_velocity_mm_s for s in run.samples]
    assert all(abs(b - a) <= A * CYCLE_S * (1 + 1e-6) for a, b in zip(v, v[1:]))


def test_single_block_stops_after_each_block(kernel) -> None:
    assert kernel.command(SetSingleBlock(0, True)) is None
    try:
        kernel.start("G1 X10 F6000\nX20\nX30\nM30\n")
        for x in (10.0, 20.0):
            snap = kernel.wait_for(lambda s: s.channels[0].program.waiting_for_start)
            assert snap.channels[0].axes[0].position_mm == pytest.approx(x, abs=1e-9)
            assert kernel.command(StartProgram(0, True)) is None
        kernel.wait_for(lambda s: s.channels[0].program.waiting_for_start
                        or s.channels[0].state == ChannelState.READY)
        if kernel.kernel.snapshot.channels[0].state != ChannelState.READY:
            kernel.command(StartProgram(0, True))
        run = kernel.wait()
        assert run.positions_mm[0] == pytest.approx(30.0, abs=1e-9)
    finally:
        kernel.command(SetSingleBlock(0, False))


def test_m0_waits_for_start(kernel) -> None:
    kernel.start("G1 X10 F6000\nM0\nG1 X20\nM30\n")
    snap = kernel.wait_for(lambda s: s.channels[0].program.waiting_for_start)
    assert snap.channels[0].axes[0].position_mm == pytest.approx(10.0, abs=1e-9)
    assert kernel.command(StartProgram(0, True)) is None
    assert kernel.wait().positions_mm[0] == pytest.approx(20.0, abs=1e-9)


def test_manual_block_runs_in_mdi(kernel) -> None:
    run = kernel.mdi("G1 X5 Y5 F600")
    assert run.channel.mode == ChannelMode.MDI
    assert run.channel.state == ChannelState.READY
    assert run.positions_mm[:2] == pytest.approx((5, 5), abs=1e-9)


def test_extended_manual_blocks_continue_one_program(kernel) -> None:
    assert kernel.command(SetExecutionMode(0, 0x80)) is None
    try:
        done = kernel.kernel.snapshot.channels[0].block.manual_blocks_done
        kernel.begin(ManualBlock(0, "G1 X5 F600"))
        snap = kernel.wait_for(lambda s: s.channels[0].block.manual_blocks_done == done + 1)
        assert snap.channels[0].state == ChannelState.ACTIVE  # not the end of the program
        time_after_first = snap.channels[0].path.program_time_s
        # F600 and the modal state carry over to the next manual block
        assert kernel.command(ManualBlock(0, "G91 X5")) is None
        snap = kernel.wait_for(lambda s: s.channels[0].block.manual_blocks_done == done + 2)
        assert snap.channels[0].axes[0].position_mm == pytest.approx(10.0, abs=1e-9)
        assert snap.channels[0].path.program_time_s > time_after_first
        assert kernel.command(ManualBlock(0, "M30")) is None
        end = kernel.wait_for(lambda s: s.channels[0].state == ChannelState.READY)
        assert end.channels[0].axes[0].position_mm == pytest.approx(10.0, abs=1e-9)
    finally:
        kernel.command(ResetChannel(0, True))
        kernel.command(SetExecutionMode(0, 0))


def test_commands_not_allowed_in_the_state_are_refused(kernel) -> None:
    refusal = kernel.command(StartProgram(0, True))  # MDI/READY after the fixture: nothing selected
    assert refusal is not None and refusal.reason == RefusalReason.NOT_READY
    assert "AUTOMATIC/READY" in refusal.message
    refusal = kernel.command(SelectProgram(0, "missing.nc"))
    assert refusal is not None and refusal.reason == RefusalReason.NOT_FOUND
    kernel.start("G1 X100 F600\nM30\n")
    refusal = kernel.command(SelectProgram(0, "test.nc"))
    assert refusal is not None and refusal.reason == RefusalReason.NOT_READY
    assert "ACTIVE" in refusal.message
    refusal = kernel.command(ManualBlock(0, "G1 X1"))
    assert refusal is not None and refusal.reason == RefusalReason.NOT_READY
    assert kernel.command(ResetChannel(0, True)) is None
    assert kernel.kernel.snapshot.channels[0].state == ChannelState.READY


def test_tool_radius_compensation_offsets_the_square(kernel) -> None:
    """G41 with D3 (r = 5 mm) around a 40 mm square, clockwise: the tool runs 5 mm outside."""
    text = (
        "G0 X-20 Y-20\nG41 D3 G1 X0 Y0 F3000\nG1 Y40\nX40\nY0\nX0\nG40 G1 X-20 Y-20\nM30\n"
    )
    run = kernel.run(text, record=True)
    assert run.channel.state == ChannelState.READY, run.channel.errors.entries
    assert run.positions_mm[:2] == pytest.approx((-20, -20), abs=1e-9)
    # Samples in the middle of each edge: 5 mm outside the programmed square.
    edges = {2: (0, -5.0), 3: (1, 45.0), 4: (0, 45.0), 5: (1, -5.0)}  # block_count -> axis, value
    for count, (axis, value) in edges.items():
        along = [s.positions_mm for s in run.samples if s.block_count == count]
        middle = [p for p in along if 10 < p[1 - axis] < 30]
        assert middle, count
        assert all(p[axis] == pytest.approx(value, abs=1e-6) for p in middle), (count, middle[:3])
