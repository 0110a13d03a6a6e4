"""Enhanced look-ahead (MTC200 LA_ON .. LA_OFF with METB, VFBT, BBTRC).

Two levels, both on the real code (no mocks):

* the section planner (``plan_section``) on blocks decoded from NC text, where the
  sub-blocks, their feeds, exits and the bottleneck error can be inspected one by one;
* the real kernel on the virtual clock (``KernelHarness``), where the 1 ms samples show
  what the path does: times, speeds, stops, errors, end points.

Default machine: axes X Y Z, V = 500 mm/s, A = 5000 mm/s^2, velocity jump 20 mm/s,
cycle 1 ms, look-ahead buffer 120 blocks (FCT_IPO_DEFAULT). Every expected value is
derived here from that model (trapezoids, corner limit = dV / |change of the axis'
direction component|, offset geometry of the tool radius compensation).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from bench.lookahead_programs import circle_chords, with_la_on
from bench.reference_optimum import axis_limits, optimum_time_s
from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.channel_mode import ChannelState
from cnc_objects.service.kernel.commands import (
    ResetChannel,
    SetFeedOverride,
    SetSingleBlock,
    StartProgram,
)
from cnc_objects.service.kernel.decoder_feed import SectionCollector
from cnc_objects.service.kernel.nc import Decoder, NcError, NcErrorId
from cnc_objects.service.kernel.nc.blocks import Block, MotionKind
from cnc_objects.service.kernel.path.errors import PathErrorId
from cnc_objects.service.kernel.path.limits import AxisDynamics
from cnc_objects.service.kernel.path.section_plan import plan_section
from tests.support.kernel import KernelHarness, Run

CONFIG = build_config()
CYCLE_S = CONFIG.cycle_ms / 1000.0
V, A, DV = 500.0, 5000.0, 20.0  # the default machine's axis limits
DYNAMICS = tuple(AxisDynamics(a.limits.vel_max_mm_s, a.limits.acc_max_mm_s2,
                              a.limits.vel_jump_mm_s) for a in CONFIG.channels[0].axes)
BUFFER = CONFIG.channels[0].look_ahead_blocks
TOOLS = {t.d: t.radius_mm for t in CONFIG.tools}
READY = ChannelState.READY
BOTTLENECK = int(PathErrorId.COMP_BOTTLENECK)
BUFFER_LIMITS_SPEED = int(PathErrorId.BUFFER_LIMITS_SPEED)
EPS = 1e-9


# ------------------------------------------------------------------------------ helpers

def decode(text: str) -> list[Block]:
    return list(Decoder(text, "prog.nc", axes=("X", "Y", "Z"), loader=lambda name: "",
                        tools=TOOLS).blocks())


def section_of(text: str) -> list[Block]:
    """The blocks decoded under LA_ON (the program holds one section)."""
    return [b for b in decode(text) if b.look_ahead is not None]


def plan(text: str, buffer_blocks: int = BUFFER):
    return plan_section(section_of(text), DYNAMICS, buffer_blocks=buffer_blocks,
                        cycle_s=CYCLE_S)


def trapezoid_s(length_mm: float, v_mm_s: float, a_mm_s2: float) -> float:
    """Rest-to-rest time with constant acceleration and a speed limit."""
    if length_mm >= v_mm_s ** 2 / a_mm_s2:
        return length_mm / v_mm_s + v_mm_s / a_mm_s2
    return 2.0 * math.sqrt(length_mm / a_mm_s2)


def corner_limit(u_in, u_out) -> float:
    """min_i dV / |u_out,i - u_in,i| over the axes whose direction component changes."""
    return min(DV / abs(o - i) for i, o in zip(u_in, u_out) if o != i)


def errors(run) -> list:
    """The channel's errors that are not warnings."""
    return [e for e in run.channel.errors.entries if not e.warning]


def positions(run) -> np.ndarray:
    return np.array([s.positions_mm for s in run.samples])


def motion(run: Run) -> np.ndarray:
    """The recorded positions up to the end of the motion: the recording goes on for the
    cycles the harness takes to see READY, a number that varies with the machine's load."""
    p = positions(run)
    end = len(p)
    while end > 1 and np.array_equal(p[end - 2], p[-1]):
        end -= 1
    return p[:end]


def speeds(run) -> np.ndarray:
    return np.array([s.path_velocity_mm_s for s in run.samples])


def max_axis_speed(run) -> float:
    return float(np.max(np.abs(np.diff(positions(run), axis=0)))) / CYCLE_S


def assert_finished_at(run, end) -> None:
    assert run.channel.state == READY, run.channel.errors.entries
    assert errors(run) == []
    assert run.positions_mm == pytest.approx(end, abs=EPS)


@pytest.fixture(autouse=True)
def fresh_channel(kernel):
    """Every kernel test starts from RESET at the origin, 100 %, no single block."""
    kernel.command(ResetChannel(0, True))
    kernel.command(SetFeedOverride(0, 1000))
    kernel.command(SetSingleBlock(0, False))
    kernel.mdi("G90 G40 G0 X0 Y0 Z0")
    yield
    kernel.command(SetFeedOverride(0, 1000))
    kernel.command(SetSingleBlock(0, False))


def run_from_origin(kernel, text: str, name: str = "la.nc"):
    kernel.command(ResetChannel(0, True))
    kernel.mdi("G90 G40 G0 X0 Y0 Z0")
    return kernel.run(text, name=name, record=True)


def machine_with_buffer(function: str):
    channels = list(CONFIG.channels)
    channels[0] = channels[0].model_copy(update={"interpolator_function": function})
    return CONFIG.model_copy(update={"channels": tuple(channels)})


def test_the_default_machine_is_the_model_of_these_tests() -> None:
    assert CYCLE_S == 0.001 and BUFFER == 120
    assert all((d.vel_max_mm_s, d.acc_max_mm_s2, d.vel_jump_mm_s) == (V, A, DV)
               for d in DYNAMICS)
    la = CONFIG.channels[0].la
    assert (la.metb_s, la.vfbt, la.bbtrc) == (0.01, 1.0, 8)
    sizes = [machine_with_buffer(f).channels[0].look_ahead_blocks for f in (
        "FCT_LOOK_AHEAD_LOW", "FCT_LOOK_AHEAD_STANDARD", "FCT_LOOK_AHEAD_HIGH")]
    assert sizes == [30, 120, 190]


# ---------------------------------------------------- 1. micro chords reach the optimum

def test_la_on_runs_1um_chords_of_a_small_circle_at_the_optimum(kernel) -> None:
    program = circle_chords(1.0)  # 2 x 6283 chords of 1 um, F6000
    optimum = optimum_time_s(program.elements, axis_limits(CONFIG))
    end = program.elements[-1].end
    on = run_from_origin(kernel, with_la_on(program.text))
    off = run_from_origin(kernel, program.text)
    for run in (on, off):
        assert_finished_at(run, end)
        assert max_axis_speed(run) <= V * (1 + EPS)
        assert float(np.max(speeds(run))) <= 100.0 * (1 + EPS)  # F6000
    t_on, t_off = on.channel.path.program_time_s, off.channel.path.program_time_s
    # the time-optimal plan of the same model is a lower bound (up to the last cycle)
    assert optimum - CYCLE_S <= t_on <= 1.01 * optimum, (t_on, optimum)
    # 120 buffered chords are 0.12 mm: LA_OFF must be able to stop within them
    assert t_off > 1.5 * t_on, (t_off, t_on)
    assert BUFFER_LIMITS_SPEED in [e.id for e in off.channel.errors.entries if e.warning]
    assert on.channel.errors.entries == ()
    # each programmed chord is one block (1 um chords are too short to be split)
    assert on.channel.block.block_count == off.channel.block.block_count == program.blocks + 1


# ------------------------------------------------------------------------ 2. METB

LONG_LINE = "LA_ON\nMETB={metb}\nN10 G1 X200 F12000\nLA_OFF\nN20 M30\n"


def test_metb_splits_a_long_line_without_changing_its_time(kernel) -> None:
    # 200 mm at 200 mm/s: ramps of 200/5000 = 40 ms each side
    expected_s = trapezoid_s(200.0, 200.0, A)
    off = run_from_origin(kernel, "N10 G1 X200 F12000\nN20 M30\n")
    assert_finished_at(off, (200.0, 0.0, 0.0))
    assert off.channel.block.block_count == 2
    assert abs(off.channel.path.program_time_s - expected_s) <= 2 * CYCLE_S
    counts, times = {}, {}
    for metb in (0.01, 0.02, 0.05):
        run = run_from_origin(kernel, LONG_LINE.format(metb=metb))
        assert_finished_at(run, (200.0, 0.0, 0.0))
        counts[metb] = run.channel.block.block_count
        times[metb] = run.channel.path.program_time_s
        # the sub-blocks pass through the block counter as blocks of their own
        assert counts[metb] == len(plan(LONG_LINE.format(metb=metb)).blocks) + 1
        assert float(np.max(speeds(run))) <= 200.0 * (1 + EPS)
    # ramp of 40 ms: METB 10 ms -> 3 ramp sub-blocks each side, 20 ms -> 1, 50 ms -> none
    assert counts == {0.01: 8, 0.02: 4, 0.05: 2}
    assert abs(times[0.01] - times[0.05]) <= CYCLE_S
    assert abs(times[0.01] - off.channel.path.program_time_s) <= 0.01 * off.channel.path.program_time_s
    assert abs(times[0.02] - off.channel.path.program_time_s) <= 0.01 * off.channel.path.program_time_s


@pytest.mark.parametrize("metb", [0.005, 0.01, 0.015])
def test_metb_sub_blocks_lie_on_the_line_in_order(metb) -> None:
    start, end = (0.0, 0.0, 0.0), (120.0, -90.0, 40.0)
    text = f"LA_ON\nMETB={metb}\nN10 G1 X120 Y-90 Z40 F12000\nLA_OFF\nM30\n"
    original = section_of(text)[0]
    blocks = plan(text).blocks
    assert len(blocks) > 2
    length = math.dist(start, end)
    u = tuple((e - s) / length for s, e in zip(start, end))
    acc = min(A / abs(c) for c in u)  # path acceleration of the line
    feed = original.motion.feed_mm_s
    assert feed == pytest.approx(200.0)
    previous_end, previous_t = start, 0.0
    for b in blocks:
        m = b.motion
        assert m.kind == MotionKind.LINEAR
        assert m.start_mm == previous_end  # contiguous, exactly
        d = [p - s for p, s in zip(m.end_mm, start)]
        t = sum(a * c for a, c in zip(d, u))  # distance along the line
        off_line = math.dist(m.end_mm, tuple(s + t * c for s, c in zip(start, u)))
        assert off_line <= 1e-9
        assert previous_t < t <= length + 1e-9
        assert b.source == original.source and b.number == original.number == 10
        previous_end, previous_t = m.end_mm, t
    assert blocks[0].motion.start_mm == start
    assert blocks[-1].motion.end_mm == end  # exactly the programmed end
    feeds = [b.motion.feed_mm_s for b in blocks]
    top = feeds.index(max(feeds))
    assert all(a < b for a, b in zip(feeds[:top], feeds[1:top + 1]))  # rises ...
    assert all(a > b for a, b in zip(feeds[top:], feeds[top + 1:]))  # ... then falls
    assert max(feeds) == pytest.approx(feed) and max(feeds) <= feed
    # every ramp sub-block changes the speed by at least a * METB: it lasts >= METB
    rising = [0.0, *feeds[:top + 1]]
    assert all(b - a >= acc * metb * (1 - 1e-9) for a, b in zip(rising, rising[1:]))
    falling = [*feeds[top:], 0.0]
    assert all(a - b >= acc * metb * (1 - 1e-9) for a, b in zip(falling, falling[1:]))
    # the last one stops at the section's end; the counter of what follows counts down
    assert blocks[-1].look_ahead.exit_mm_s == 0.0
    assert [b.look_ahead.blocks_after for b in blocks] == list(range(len(blocks) - 1, -1, -1))


def test_larger_metb_gives_fewer_sub_blocks() -> None:
    counts = [len(plan(LONG_LINE.format(metb=metb)).blocks)
              for metb in (0.002, 0.005, 0.01, 0.02, 0.05)]
    assert counts == sorted(counts, reverse=True) and counts[0] > counts[-1] == 1


# ------------------------------------------------------------- 3. sub-blocks of arcs

ARCS = {
    # G17 half circle, clockwise, about (0, 0), Z stays 3
    "G2 XY": ("G0 X-50 Y0 Z3\nLA_ON\nN10 G2 X50 Y0 I50 J0 F12000\nLA_OFF\nM30\n",
              (0, 1), (0.0, 0.0), 50.0, MotionKind.ARC_CW),
    # G18 quarter circle (centre Z0 X20), counter-clockwise in the Z/X plane, Y stays 7
    "G3 ZX": ("G0 X0 Y7 Z0\nLA_ON\nN10 G18 G3 X20 Z20 I20 K0 F12000\nLA_OFF\nM30\n",
              (2, 0), (0.0, 20.0), 20.0, MotionKind.ARC_CCW),
}


@pytest.mark.parametrize("case", ARCS, ids=list(ARCS))
def test_arc_sub_blocks_lie_on_the_circle(kernel, case) -> None:
    text, plane, center, radius, kind = ARCS[case]
    original = section_of(text)[0]
    assert original.motion.center_mm == pytest.approx(center)
    blocks = plan(text).blocks
    assert len(blocks) >= 5  # ramps of >= 40 ms at METB 10 ms
    p, q = plane
    fixed = [i for i in range(3) if i not in plane]
    previous = original.motion.start_mm
    for b in blocks:
        m = b.motion
        assert m.kind == kind and m.plane == plane and m.center_mm == original.motion.center_mm
        assert m.start_mm == previous
        assert math.hypot(m.end_mm[p] - center[0], m.end_mm[q] - center[1]) == \
            pytest.approx(radius, abs=1e-9)
        assert all(m.end_mm[i] == original.motion.start_mm[i] for i in fixed)
        previous = m.end_mm
    assert previous == original.motion.end_mm
    # the kernel runs the sub-blocks along the same circle to the programmed end
    run = run_from_origin(kernel, text)
    assert_finished_at(run, original.motion.end_mm)
    assert run.channel.block.block_count == len(blocks) + 2  # G0, sub-blocks, M30
    on_arc = [pos for pos, s in zip(positions(run), run.samples)
              if s.block_count >= 1 and s.state == ChannelState.ACTIVE]
    assert len(on_arc) > 100
    for pos in on_arc:
        assert math.hypot(pos[p] - center[0], pos[q] - center[1]) == \
            pytest.approx(radius, abs=1e-6)
        assert all(pos[i] == pytest.approx(original.motion.start_mm[i], abs=EPS)
                   for i in fixed)


# ------------------------------------------------------------ 4. METB must exceed the cycle

@pytest.mark.parametrize("text,line,column", [
    ("LA_ON\nMETB=0.001\nG1 X10 F600\nLA_OFF\nM30\n", 2, 1),  # equal to the cycle
    ("G1 X10 F600\nLA_ON\nG1 X20 METB=0.0005\nLA_OFF\nM30\n", 3, 8),  # inside a block
    ("LA_ON\nMETB=-0.5\nM30\n", 2, 1),
])
def test_metb_not_above_the_cycle_time_is_an_error(text, line, column) -> None:
    with pytest.raises(NcError) as info:
        decode(text)
    e = info.value
    assert (e.id, e.line, e.column) == (NcErrorId.VALUE_OUT_OF_RANGE, line, column), str(e)


def test_metb_just_above_the_cycle_time_is_accepted() -> None:
    mark = section_of("LA_ON\nMETB=0.0011\nG1 X10 F600\nLA_OFF\nM30\n")[0].look_ahead
    assert mark.metb_s == 0.0011


def test_metb_error_stops_the_kernel_run_at_its_line(kernel) -> None:
    run = run_from_origin(kernel, "G1 X10 F600\nLA_ON\nG1 X20 METB=0.001\nLA_OFF\nM30\n",
                          name="metb.nc")
    ch = run.channel
    assert ch.state == ChannelState.ERROR
    e = ch.errors.entries[0]
    assert (e.id, e.file, e.line, e.column) == (int(NcErrorId.VALUE_OUT_OF_RANGE), "metb.nc",
                                                3, 8), e
    assert "METB" in e.text
    assert run.positions_mm == pytest.approx((10.0, 0.0, 0.0), abs=EPS)  # N1 ran, N3 not


def test_configured_metb_must_exceed_the_cycle_time() -> None:
    raw = CONFIG.model_dump()
    raw["channels"][0]["la"]["metb_s"] = CONFIG.cycle_ms / 1000.0
    with pytest.raises(ValueError, match="METB"):
        type(CONFIG).model_validate(raw)


# ------------------------------------------------------------------------ 5. VFBT

def zigzag(rows: int = 10, width: float = 10.0, step: float = 2.0):
    """Rows of ``width`` along X joined by links of ``step`` in +Y: 90 degree corners.
    The text and the corner points."""
    lines, corners, y = [], [], 0.0
    for row in range(rows):
        x = width if row % 2 == 0 else 0.0
        lines += [f"X{x:g} Y{y:g}", f"X{x:g} Y{y + step:g}"]
        corners += [(x, y, 0.0), (x, y + step, 0.0)]
        y += step
    lines[0] = f"G1 {lines[0]} F6000"
    return "\n".join(lines) + "\n", corners[:-1]  # the last point is the end


def corner_minima(run, corners) -> list[float]:
    """The lowest sampled path speed within 0.5 mm of each corner."""
    pos, v = positions(run), speeds(run)
    return [float(np.min(v[np.linalg.norm(pos - np.array(c), axis=1) < 0.5]))
            for c in corners]


def test_vfbt_lowers_the_speed_at_corners_of_the_section(kernel) -> None:
    body, corners = zigzag()
    limit = corner_limit((1, 0, 0), (0, 1, 0))  # every corner turns one axis fully
    assert limit == pytest.approx(20.0)
    results = {}
    for vfbt in (1.0, 0.5):
        run = run_from_origin(kernel, f"LA_ON\nVFBT={vfbt}\n{body}LA_OFF\nM30\n")
        assert_finished_at(run, (0.0, 20.0, 0.0))
        minima = corner_minima(run, corners)
        # the path passes each corner at the limit x VFBT: the samples around it lie
        # at most one cycle of acceleration above it
        for m in minima:
            assert vfbt * limit - 1e-6 <= m <= vfbt * limit + A * CYCLE_S + 1e-6, minima
        results[vfbt] = (run.channel.path.program_time_s, float(np.mean(minima)))
    assert results[0.5][0] > results[1.0][0] + 0.02  # 19 slower corners
    assert 0.4 <= results[0.5][1] / results[1.0][1] <= 0.65


def test_vfbt_has_no_effect_outside_la_on(kernel) -> None:
    body, _ = zigzag()
    plain = run_from_origin(kernel, body + "M30\n")
    with_vfbt = run_from_origin(kernel, "VFBT=0.5\n" + body + "M30\n")
    la_on = run_from_origin(kernel, f"LA_ON\n{body}LA_OFF\nM30\n")
    for run in (plain, with_vfbt, la_on):
        assert_finished_at(run, (0.0, 20.0, 0.0))
    assert with_vfbt.channel.path.program_time_s == pytest.approx(plain.channel.path.program_time_s,
                                                             abs=1e-9)
    assert np.array_equal(motion(with_vfbt), motion(plain))
    # the whole zig-zag fits the buffer: LA_ON with VFBT=1 is exactly as fast
    assert abs(la_on.channel.path.program_time_s - plain.channel.path.program_time_s) <= CYCLE_S


# ------------------------------------------------------------------------ 6. BBTRC

# A keyhole: a neck 3 mm wide (X 20..23, Y 0..-5) into a chamber 23 x 20 mm. G41 with
# D2 (r = 2.5): the tool goes down the neck, around the chamber and up the neck again.
KEYHOLE = """\
N10 G41 D2 G1 X20 Y0 F3000
N20 Y-5
N30 X10
N40 Y-25
N50 X33
N60 Y-5
N70 X23
N80 Y0
N90 X40
N100 G40 X50
"""
R_TOOL = 2.5


def _on_arc(point, center, start_deg, end_deg) -> bool:
    """``point`` (on the circle) lies strictly inside the clockwise arc start -> end."""
    angle = math.degrees(math.atan2(point[1] - center[1], point[0] - center[0]))
    span = (start_deg - end_deg) % 360
    return 0 < (start_deg - angle) % 360 < span


def _circle_crossings(c1, c2, r):
    d = math.dist(c1, c2)
    mx, my = (c1[0] + c2[0]) / 2, (c1[1] + c2[1]) / 2
    h = math.sqrt(r * r - d * d / 4)
    ux, uy = (c2[0] - c1[0]) / d, (c2[1] - c1[1]) / d
    return [(mx - h * uy, my + h * ux), (mx + h * uy, my - h * ux)]


def test_keyhole_geometry_has_two_bottlenecks_the_ordinary_compensation_misses(kernel) -> None:
    assert TOOLS[2] == R_TOOL
    assert 23 - 20 < 2 * R_TOOL < 33 - 10  # the neck is too narrow, the chamber is not
    # outside corners get an arc of r about the corner, clockwise (right turns, G41);
    # it belongs to the following block: N20 (about (20,0), 90 -> 0 degrees), N30
    # (about (20,-5), 0 -> -90), N80 (about (23,-5), -90 -> -180), N90 (about (23,0),
    # 180 -> 90). N20's and N90's arcs cross, and N30's and N80's arcs.
    arcs = {20: ((20, 0), 90, 0), 30: ((20, -5), 0, -90),
            80: ((23, -5), -90, -180), 90: ((23, 0), 180, 90)}
    for first, second, expected in ((20, 90, (21.5, 2.0)), (30, 80, (21.5, -7.0))):
        (c1, s1, e1), (c2, s2, e2) = arcs[first], arcs[second]
        crossing = [p for p in _circle_crossings(c1, c2, R_TOOL)
                    if _on_arc(p, c1, s1, e1) and _on_arc(p, c2, s2, e2)]
        assert crossing == [pytest.approx(expected)]
    # without LA_ON, the compensation (which trims neighbours only) runs the program
    run = run_from_origin(kernel, KEYHOLE + "M30\n")
    assert_finished_at(run, (50.0, 0.0, 0.0))
    pos = positions(run)
    neck = pos[(pos[:, 1] < -EPS) & (pos[:, 1] > -5.0 + EPS)]
    # down at x = 22.5 and up at x = 20.5: the tool (r = 2.5) cuts both walls (20, 23)
    assert float(np.max(neck[:, 0])) == pytest.approx(20.0 + R_TOOL)
    assert float(np.min(neck[:, 0])) == pytest.approx(23.0 - R_TOOL)


@pytest.mark.parametrize("bbtrc,named,crossing,with_block", [
    (None, 20, "(21.5000, 2.0000)", "N90"),  # default 8: N20 reaches N90 (7 blocks on)
    (7, 20, "(21.5000, 2.0000)", "N90"),
    (6, 30, "(21.5000, -7.0000)", "N80"),  # N20 no longer reaches N90, N30 reaches N80
    (5, 30, "(21.5000, -7.0000)", "N80"),
])
def test_bbtrc_finds_the_bottleneck_and_stops_before_it(kernel, bbtrc, named, crossing,
                                                        with_block) -> None:
    head = "LA_ON\n" + (f"BBTRC={bbtrc}\n" if bbtrc else "")
    text = head + KEYHOLE + "LA_OFF\nM30\n"
    result = plan(text)
    assert result.error is not None and result.error.id == PathErrorId.COMP_BOTTLENECK
    assert result.error.block.number == named
    assert crossing in result.error.message and with_block in result.error.message
    assert [b.number for b in result.blocks] == [n for n in (10, 20) if n < named]
    run = run_from_origin(kernel, text, name="keyhole.nc")
    ch = run.channel
    assert ch.state == ChannelState.ERROR
    e = ch.errors.entries[0]
    line = next(n for n, t in enumerate(text.splitlines(), 1) if t.startswith(f"N{named} "))
    assert (e.id, e.file, e.line) == (BOTTLENECK, "keyhole.nc", line), e
    pos = positions(run)
    assert speeds(run)[-1] == 0.0
    if named == 20:
        # N10 ran (approach and the offset line y = 2.5, ended perpendicular at (20, 2.5));
        # nothing of N20, which starts with the arc about (20, 0)
        assert run.positions_mm == pytest.approx((20.0, R_TOOL, 0.0), abs=EPS)
        assert float(np.max(pos[:, 0])) <= 20.0 + EPS
        assert float(np.min(pos[:, 1])) >= -EPS
    else:
        # N20 ran down the neck on x = 22.5 to y = -5; nothing of N30 (arc about (20, -5))
        assert run.positions_mm == pytest.approx((20.0 + R_TOOL, -5.0, 0.0), abs=EPS)
        assert float(np.min(pos[:, 1])) >= -5.0 - EPS
        assert float(np.max(pos[:, 0])) <= 22.5 + EPS


@pytest.mark.parametrize("bbtrc", [1, 4])
def test_bbtrc_too_short_to_reach_the_crossing_runs_the_program(kernel, bbtrc) -> None:
    text = f"LA_ON\nBBTRC={bbtrc}\n" + KEYHOLE + "LA_OFF\nM30\n"
    assert plan(text).error is None
    run = run_from_origin(kernel, text)
    assert_finished_at(run, (50.0, 0.0, 0.0))
    assert run.channel.block.block_count == 11  # compensated blocks are never split


def test_bbtrc_ignores_moves_without_compensation() -> None:
    # after G40 the rapid at Z10 crosses the contour's offset line x = 17.5 (N20) in the
    # plane: not the compensated path, no bottleneck
    text = ("LA_ON\nN10 G41 D2 G1 X20 Y0 F3000\nN20 Y20\nN30 X0\nN40 G40 X-5 Y10\n"
            "N50 G0 Z10\nN60 X30 Y10\nLA_OFF\nM30\n")
    result = plan(text)
    assert result.error is None
    assert [b.number for b in result.blocks][-1] == 60
    # a tool radius of 0 compensates nothing: a programmed path that crosses itself
    text = ("LA_ON\nN10 G41 D0 G1 X10 Y0 F600\nN20 X10 Y10\nN30 X5 Y-5\nN40 X0 Y5\n"
            "N50 G40 X0 Y0\nLA_OFF\nM30\n")
    assert plan(text).error is None


def test_rapid_over_a_compensated_contour_runs_in_the_kernel(kernel) -> None:
    text = ("LA_ON\nN10 G41 D2 G1 X20 Y0 F3000\nN20 Y20\nN30 X0\nN40 G40 X-5 Y10\n"
            "N50 G0 Z10\nN60 X30 Y10\nLA_OFF\nM30\n")
    assert_finished_at(run_from_origin(kernel, text), (30.0, 10.0, 10.0))


# ------------------------------------------------------------ 7. a stop ends the section

def test_dwell_ends_the_section_and_the_path_stops_there(kernel) -> None:
    text = "LA_ON\nN10 G1 X50 F6000\nN20 G4 X0.1\nN30 G1 X100\nLA_OFF\nN40 M30\n"
    # the SDA hands over the section when the dwell block arrives, the rest after it
    planned = []
    collector = SectionCollector(lambda blocks: planned.append(blocks) or plan_section(
        blocks, DYNAMICS, buffer_blocks=BUFFER, cycle_s=CYCLE_S))
    handed = [collector.push(b) for b in decode(text)] + [collector.flush()]
    assert [[b.number for b in s] for s in planned] == [[10, 20], [30]]
    first = handed[1]  # what the dwell block released
    assert [b.number for b in first][-2:] == [10, 20] and first[-1].dwell_s == 0.1
    assert first[-2].look_ahead.exit_mm_s == 0.0  # N10's last sub-block stops
    run = run_from_origin(kernel, text)
    assert_finished_at(run, (100.0, 0.0, 0.0))
    pos, v = positions(run)[:, 0], speeds(run)
    at_stop = np.flatnonzero(pos == 50.0)
    assert len(at_stop) >= 100 and np.all(v[at_stop] <= 1e-9)  # 0.1 s standing at X50
    assert np.all(np.diff(at_stop) == 1)
    assert np.all(pos[:at_stop[0]] < 50.0) and np.all(pos[at_stop[-1] + 1:] > 50.0)
    # two rest-to-rest moves plus the dwell (without the stop it would be one 100 mm move)
    expected = 2 * trapezoid_s(50.0, 100.0, A) + 0.1
    assert abs(run.channel.path.program_time_s - expected) <= 4 * CYCLE_S


def test_m0_inside_a_section_stops_and_start_continues(kernel) -> None:
    kernel.command(ResetChannel(0, True))
    kernel.mdi("G90 G40 G0 X0 Y0 Z0")
    kernel.start("LA_ON\nG1 X50 F12000\nM0\nX100\nLA_OFF\nM30\n", record=True)
    snap = kernel.wait_for(lambda s: s.channels[0].program.waiting_for_start)
    ch = snap.channels[0]
    assert ch.axes[0].position_mm == pytest.approx(50.0, abs=EPS)
    assert ch.path.path_velocity_mm_s == 0.0
    assert kernel.command(StartProgram(0, True)) is None
    run = kernel.wait()
    assert_finished_at(run, (100.0, 0.0, 0.0))
    v = speeds(run)
    assert np.all(np.abs(np.diff(v)) <= A * CYCLE_S * (1 + 1e-6))


# ------------------------------------------------ 8. feed override and single block

def fine_line(step_mm: float = 0.02, count: int = 5000, feed: int = 12000) -> str:
    """A straight line along X of ``count`` blocks of ``step_mm``: 120 buffered blocks
    (2.4 mm) allow sqrt(2 A 2.4) = 155 mm/s without LA_ON, F12000 is 200 mm/s."""
    lines = [f"X{step_mm * k:.2f}" for k in range(1, count + 1)]
    lines[0] = f"G1 {lines[0]} F{feed}"
    return "LA_ON\n" + "\n".join(lines) + "\nLA_OFF\nM30\n"


def assert_within_limits(run, speed_limit: float) -> None:
    pos, v = positions(run), speeds(run)
    assert float(np.max(v)) <= speed_limit * (1 + EPS)
    assert max_axis_speed(run) <= V * (1 + EPS)
    # a straight line along X: the axis (and path) acceleration is A everywhere
    vx = np.diff(pos[:, 0]) / CYCLE_S
    assert float(np.max(np.abs(np.diff(vx)))) <= A * CYCLE_S * (1 + 1e-6)
    assert float(np.max(np.abs(np.diff(v)))) <= A * CYCLE_S * (1 + 1e-6)


def test_feed_override_halves_the_speed_of_a_section(kernel) -> None:
    text = fine_line()
    full = run_from_origin(kernel, text)
    assert_finished_at(full, (100.0, 0.0, 0.0))
    assert_within_limits(full, 200.0)
    assert float(np.max(speeds(full))) == pytest.approx(200.0)  # beyond what 120 blocks allow
    kernel.command(ResetChannel(0, True))
    kernel.mdi("G90 G40 G0 X0 Y0 Z0")
    assert kernel.command(SetFeedOverride(0, 500)) is None
    half = kernel.run(text, record=True)
    assert_finished_at(half, (100.0, 0.0, 0.0))
    assert_within_limits(half, 100.0)
    ratio = half.channel.path.program_time_s / full.channel.path.program_time_s
    assert 1.9 <= ratio <= 2.05, ratio


def test_feed_override_changed_at_full_speed_stays_within_limits(kernel) -> None:
    kernel.command(ResetChannel(0, True))
    kernel.mdi("G90 G40 G0 X0 Y0 Z0")
    kernel.start(fine_line(), record=True)
    kernel.wait_for(lambda s: s.channels[0].path.path_velocity_mm_s >= 199.0)
    assert kernel.command(SetFeedOverride(0, 300)) is None
    kernel.wait_for(lambda s: s.channels[0].path.path_velocity_mm_s <= 60.0 + EPS)
    assert kernel.command(SetFeedOverride(0, 1000)) is None
    run = kernel.wait()
    assert_finished_at(run, (100.0, 0.0, 0.0))
    assert_within_limits(run, 200.0)


def test_single_block_stops_at_every_sub_block_end(kernel) -> None:
    text = LONG_LINE.format(metb=0.01)
    ends = [b.motion.end_mm[0] for b in plan(text).blocks]
    assert ends == pytest.approx([0.25, 1.0, 2.25, 197.75, 199.0, 199.75, 200.0])
    kernel.command(ResetChannel(0, True))
    kernel.mdi("G90 G40 G0 X0 Y0 Z0")
    assert kernel.command(SetSingleBlock(0, True)) is None
    kernel.start(text, record=True)
    stops = []
    for _ in range(len(ends) + 2):
        snap = kernel.wait_for(lambda s: s.channels[0].program.waiting_for_start
                               or s.channels[0].state == READY)
        ch = snap.channels[0]
        if ch.state == READY:
            break
        assert ch.path.path_velocity_mm_s == 0.0
        stops.append(ch.axes[0].position_mm)
        assert kernel.command(StartProgram(0, True)) is None
    run = kernel.wait()
    assert_finished_at(run, (200.0, 0.0, 0.0))
    assert stops == pytest.approx(ends, abs=EPS)


# ------------------------------------------------------- 9. LA_ON while G41 is active

G41_THEN_LA_ON = ("N10 G41 D2 G1 X100 Y0 F12000\nLA_ON\nN20 X150\nN30 Y100\nN40 X0\n"
                  "LA_OFF\nN50 G40 Y0\nN60 M30\n")


def test_la_on_while_compensation_holds_a_block_passes_unplanned(kernel) -> None:
    calls = []
    collector = SectionCollector(lambda blocks: calls.append(blocks) or plan_section(
        blocks, DYNAMICS, buffer_blocks=BUFFER, cycle_s=CYCLE_S))
    blocks = decode(G41_THEN_LA_ON)
    assert [b.look_ahead is not None for b in blocks] == [False, True, True, True, False,
                                                          False]
    handed = []
    for b in blocks:
        if b.look_ahead is None and not collector.open:
            collector.note(b)
            handed.append(b)
        else:
            handed += collector.push(b)
    handed += collector.flush()
    assert calls == []  # nothing planned
    assert all(h is b for h, b in zip(handed, blocks, strict=True))  # unchanged, no splits
    la_on = run_from_origin(kernel, G41_THEN_LA_ON)
    plain = run_from_origin(kernel, G41_THEN_LA_ON.replace("LA_ON\n", "").replace(
        "LA_OFF\n", ""))
    for run in (la_on, plain):
        assert_finished_at(run, (0.0, 0.0, 0.0))
        assert run.channel.block.block_count == 6
    assert abs(la_on.channel.path.program_time_s - plain.channel.path.program_time_s) <= CYCLE_S


# ------------------------------------- block rate: bare blocks take a buffer slot each

def duplicated_chords(count: int = 3000) -> str:
    """1 um chords along X, each end point programmed twice (a zero-length block after
    every chord, as CAM output often has): half of the blocks do not move."""
    lines = []
    for k in range(1, count + 1):
        lines += [f"X{k * 0.001:.3f}"] * 2
    lines[0] = f"G1 {lines[0]} F6000"
    return "\n".join(lines) + "\n"


def test_zero_length_blocks_in_a_section_keep_the_path_within_its_limits(kernel) -> None:
    body = duplicated_chords()
    on = run_from_origin(kernel, "LA_ON\n" + body + "LA_OFF\nM30\n")
    off = run_from_origin(kernel, body + "M30\n")
    for run in (on, off):
        assert_finished_at(run, (3.0, 0.0, 0.0))
        assert_within_limits(run, 100.0)
    assert on.channel.path.program_time_s < 0.7 * off.channel.path.program_time_s
    # 120 slots hold 60 chords: the path may pass 119 slots, 59.5 chords, per cycle;
    # each chord stands for itself and the zero-length blocks on both sides
    assert float(np.max(speeds(on))) <= 0.001 * (BUFFER - 1) / 3 / CYCLE_S * (1 + EPS)


def test_bare_blocks_filling_the_buffer_make_the_section_stop() -> None:
    # a 30-block buffer: 40 zero-length blocks after N10 leave nothing to move behind it
    text = "LA_ON\nN10 G1 X50 F6000\n" + "X50\n" * 40 + "N20 X100\nLA_OFF\nM30\n"

    def exit_of_n10(buffer_blocks: int) -> float:
        return [b for b in plan(text, buffer_blocks).blocks if b.number == 10][-1] \
            .look_ahead.exit_mm_s

    assert exit_of_n10(30) == 0.0
    assert exit_of_n10(120) == pytest.approx(100.0)  # 40 bare blocks leave room in 120
    with KernelHarness(config=machine_with_buffer("FCT_LOOK_AHEAD_LOW")) as harness:
        run = harness.run(text, record=True)
    assert_finished_at(run, (100.0, 0.0, 0.0))
    assert_within_limits(run, 100.0)
    pos, v = positions(run)[:, 0], speeds(run)
    assert np.any(pos == 50.0) and np.all(v[pos == 50.0] <= 1e-9)  # stopped at N10's end


def test_compensated_chords_keep_the_path_within_its_limits(kernel) -> None:
    # G41 holds the last compensated block back: one buffer slot has no segment yet
    lines = [f"X{k * 0.001:.3f}" for k in range(1, 3001)]
    lines[0] = f"G41 D1 G1 {lines[0]} F12000"
    text = "G0 X-1\nLA_ON\n" + "\n".join(lines) + "\nG40 X3.5\nLA_OFF\nM30\n"
    run = run_from_origin(kernel, text)
    assert_finished_at(run, (3.5, 0.0, 0.0))
    # path acceleration: A along the chords, A / |u_y| on the departure from (3, 1) to
    # (3.5, 0), u = (0.5, -1) / |(0.5, -1)|; the path speed never jumps
    departure_acc = A * math.hypot(0.5, 1.0)
    assert float(np.max(np.abs(np.diff(speeds(run))))) <= departure_acc * CYCLE_S * (1 + 1e-6)
    assert float(np.max(speeds(run))) <= 0.001 * (BUFFER - 2) / CYCLE_S * (1 + EPS)
