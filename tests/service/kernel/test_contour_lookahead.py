"""Contour look-ahead (FCT-C40) in the real kernel on the virtual clock.

Every expected value is computed here from the programmed contour by hand: the offset
lines and arcs of tool radius compensation, the connecting arcs at outside corners, the
lengths, start positions (sums of earlier lengths), radii, swept angles and the angles
between neighbouring elements. The kernel's answer must match field by field.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import NamedTuple

import pytest

from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.channel_mode import ChannelState
from cnc_objects.service.kernel.commands import (
    Feedhold,
    RefusalReason,
    ResetChannel,
    SetContourRequest,
    SetContourSemaphore,
    SetSingleBlock,
    StartProgram,
)
from cnc_objects.service.kernel.contour_lookahead import RESPONSE_BLOCKS
from cnc_objects.service.kernel.state import ContourElement
from tests.support.kernel import KernelHarness

INCR = 10_000.0  # 0.1 um per mm
PI = math.pi
LINEAR, CIRCULAR, LOG_ON, LOG_PARAM, LOG_OFF = 1, 2, 3, 4, 5


class Expected(NamedTuple):
    """One expected entry in mm and rad (converted to HLI units when compared)."""

    block_type: int
    block_number: int
    block_count_r: int
    length: float  # mm, or the PARAM value for types 3..5
    programmed_radius_mm: float = 0.0
    compensated_radius_mm: float = 0.0
    circle_angle: float = 0.0
    tangent_variation: float = 0.0


def angle(u: tuple[float, float], v: tuple[float, float]) -> float:
    """Angle between two plane directions (any length), in [0, pi]."""
    cross = u[0] * v[1] - u[1] * v[0]
    dot = u[0] * v[0] + u[1] * v[1]
    return abs(math.atan2(cross, dot))


def with_starts(first_start_mm: float, entries: list[Expected]) -> list[tuple[Expected, float]]:
    """Each entry with its start position: the sum of the lengths of the earlier motion
    elements (LOG entries take no path)."""
    out, s = [], first_start_mm
    for e in entries:
        out.append((e, s))
        if e.block_type in (LINEAR, CIRCULAR):
            s += e.length
    return out


def assert_entries(actual: tuple[ContourElement, ...], expected: list[tuple[Expected, float]]):
    assert len(actual) == len(expected), [a.block_type for a in actual]
    for k, (got, (want, start_mm)) in enumerate(zip(actual, expected, strict=True)):
        where = f"entry {k} ({got})"
        assert got.block_type == want.block_type, where
        assert got.block_number == want.block_number, where
        assert got.block_count_r == want.block_count_r, where
        assert got.start_position == pytest.approx(start_mm * INCR, abs=1e-3), where
        motion = want.block_type in (LINEAR, CIRCULAR)
        length = want.length * INCR if motion else want.length
        assert got.length == pytest.approx(length, abs=1e-3), where
        assert got.programmed_radius == pytest.approx(want.programmed_radius_mm * INCR,
                                                      abs=1e-3), where
        assert got.compensated_radius == pytest.approx(want.compensated_radius_mm * INCR,
                                                       abs=1e-3), where
        assert got.circle_angle == pytest.approx(want.circle_angle, abs=1e-9), where
        assert got.length_min == 0.0, where
        assert got.tangent_variation == pytest.approx(want.tangent_variation, abs=1e-9), where


def request(kernel: KernelHarness, start: float, length: float = 0.0, channel: int = 0):
    """Write the request, set the semaphore; the response of the published snapshot."""
    assert kernel.command(SetContourRequest(channel, "start_position", start)) is None
    assert kernel.command(SetContourRequest(channel, "length", length)) is None
    assert kernel.command(SetContourSemaphore(channel, True)) is None
    unit = kernel.kernel.snapshot.channels[channel].contour
    assert unit.semaphor is False  # the CNC answered and reset it
    return unit.response


@pytest.fixture(autouse=True)
def fresh_channel(kernel):
    kernel.command(ResetChannel(0, True))
    kernel.mdi("G90 G40 G0 X0 Y0 Z0")
    yield


# --- G41 (D1, r = 1): selection, tangent arc, inside corner, outside corner, G40 ---------
# the worked example of docs/contour-lookahead.md
G41_PROGRAM = (Path(__file__).resolve().parents[3] / "docs" / "examples"
               / "contour-lookahead.nc").read_text(encoding="utf-8")


def g41_expected() -> list[tuple[Expected, float]]:
    r = 1.0
    # N20 from (-10,0) to (0,0), tool left (+Y): approach (-10,0)->(-10,1), offset y = 1.
    # N40: ccw arc centre (20,10) R10; the tool on the left is inside: radius 10 - r.
    # N50/N60: left turn with the tool on the left: inside corner, trimmed at (29,29).
    # N60/N70: right turn: outside corner, connecting arc r around (0,30), cw, -pi/2.
    # N80 (G40): from the offset end (-1,50), perpendicular, to (0,60).
    entries = [
        Expected(LOG_ON, 10, 2, 1.5),
        Expected(LINEAR, 20, 3, r, tangent_variation=angle((-1, 0), (0, 1))),  # after N05
        Expected(LINEAR, 20, 3, 10.0, tangent_variation=PI / 2),
        Expected(LINEAR, 30, 4, 20.0),
        Expected(CIRCULAR, 40, 5, (10 - r) * PI / 2, 10.0, 10 - r, PI / 2),
        Expected(LINEAR, 50, 6, 29.0 - 10.0),
        Expected(LOG_PARAM, 55, 7, 7.0),
        Expected(LINEAR, 60, 8, 29.0, tangent_variation=PI / 2),
        Expected(CIRCULAR, 70, 9, r * PI / 2, 0.0, r, -PI / 2),
        Expected(LINEAR, 70, 9, 20.0),
        Expected(LINEAR, 80, 10, math.hypot(1, 10), tangent_variation=angle((0, 1), (1, 10))),
        Expected(LOG_OFF, 90, 11, 9.0),
    ]
    return with_starts(10.0, entries)  # N05 covered 10 mm before LOG ON


# --- G42 (D2, r = 2.5): cw arc with the tool inside, outside corner of a left turn -------
G42_PROGRAM = """\
N10 #CONTOUR LOOKAHEAD LOG ON
N20 G42 D2 G1 X0 Y20 F1200
N30 G2 X20 Y20 I10 J0
N35 #CONTOUR LOOKAHEAD LOG [PARAM=-2]
N40 G1 Y0
N50 X40
N60 G40 X50
N70 #CONTOUR LOOKAHEAD LOG OFF
M30
"""


def g42_expected() -> list[tuple[Expected, float]]:
    r = 2.5
    # N20 from (0,0) up, tool right (+X): approach (0,0)->(2.5,0), offset x = 2.5.
    # N30: cw arc centre (10,20) R10 over the top; the tool on the right is inside: 10 - r.
    # N40 down at x = 17.5; N40/N50 is a left turn with the tool right: outside corner,
    # connecting arc r around (20,0) from (17.5,0) to (20,-2.5), ccw, +pi/2.
    # N60 (G40): from (40,-2.5) to (50,0).
    entries = [
        Expected(LOG_ON, 10, 1, 0.0),
        Expected(LINEAR, 20, 2, r),  # the first motion of the run: nothing before it
        Expected(LINEAR, 20, 2, 20.0, tangent_variation=PI / 2),
        Expected(CIRCULAR, 30, 3, (10 - r) * PI, 10.0, 10 - r, -PI),
        Expected(LOG_PARAM, 35, 4, -2.0),
        Expected(LINEAR, 40, 5, 20.0),
        Expected(CIRCULAR, 50, 6, r * PI / 2, 0.0, r, PI / 2),
        Expected(LINEAR, 50, 6, 20.0),
        Expected(LINEAR, 60, 7, math.hypot(10, r), tangent_variation=angle((1, 0), (10, r))),
        Expected(LOG_OFF, 70, 8, 0.0),
    ]
    return with_starts(0.0, entries)


def test_every_field_of_a_g41_contour(kernel) -> None:
    run = kernel.run(G41_PROGRAM)
    assert run.channel.state == ChannelState.READY, run.channel.errors.entries
    expected = g41_expected()
    assert_entries(request(kernel, 0), expected)
    unit = kernel.kernel.snapshot.channels[0].contour
    assert unit.count_logged_blocks == len(expected)
    assert unit.log_active is False
    end_mm = expected[-1][1]  # LOG OFF sits at the end of the path
    assert unit.max_dist_prog_start_01um == pytest.approx(end_mm * INCR, abs=1e-3)
    assert run.channel.path.dist_prog_start_01um == pytest.approx(end_mm * INCR, abs=1e-3)


def test_every_field_of_a_g42_contour(kernel) -> None:
    run = kernel.run(G42_PROGRAM)
    assert run.channel.state == ChannelState.READY, run.channel.errors.entries
    assert_entries(request(kernel, 0), g42_expected())


def test_mode_1_from_the_middle_and_past_the_end(kernel) -> None:
    kernel.run(G41_PROGRAM)
    expected = g41_expected()
    assert_entries(request(kernel, 5), expected[5:])
    assert_entries(request(kernel, 11), expected[11:])
    assert request(kernel, 12) == ()  # nothing from there on: block_type 0 at once
    assert_entries(request(kernel, 2), expected[2:])  # going back is allowed


@pytest.mark.parametrize(("window_mm", "first", "last"), [
    ((21.0, 20.0), 3, 4),  # starts exactly at N30: N30 and the N40 arc (starts at 41)
    ((21.5, 19.5), 4, 4),  # cuts N30 (started before): only the arc starting at 41
    ((0.0, 10.5), None, None),  # N05 and the approach line start at 0 and 10
])
def test_mode_2_windows_by_path_distance(kernel, window_mm, first, last) -> None:
    kernel.run(G41_PROGRAM)
    expected = g41_expected()
    start, length = window_mm
    reply = request(kernel, start * INCR, length * INCR)
    if first is None:
        assert [e.block_number for e in reply] == [5, 20]
        assert reply[0].start_position == 0.0 and reply[0].length == pytest.approx(10 * INCR)
        return
    motion = [(e, s) for e, s in expected if e.block_type in (LINEAR, CIRCULAR)]
    wanted = [(e, s) for e, s in expected[first:last + 1] if (e, s) in motion]
    assert_entries(reply, wanted)


def test_requests_that_cannot_be_answered_are_refused(kernel) -> None:
    kernel.command(SetContourRequest(0, "start_position", 1.5))
    kernel.command(SetContourRequest(0, "length", 0.0))
    refusal = kernel.command(SetContourSemaphore(0, True))
    assert refusal.reason == RefusalReason.INVALID_VALUE and "index" in refusal.message
    kernel.command(SetContourRequest(0, "length", -5.0))
    refusal = kernel.command(SetContourSemaphore(0, True))
    assert refusal.reason == RefusalReason.INVALID_VALUE and "positive length" in refusal.message
    refusal = kernel.command(SetContourRequest(0, "length", math.nan))
    assert refusal.reason == RefusalReason.INVALID_VALUE
    # channel 2 of the default machine has no FCT_CONTOUR_LAH
    refusal = kernel.command(SetContourSemaphore(1, True))
    assert refusal.reason == RefusalReason.NOT_SUPPORTED and "FCT_CONTOUR_LAH" in refusal.message


# --- real-time loops ---------------------------------------------------------------------
BODY = """\
N80 G1 X14 Y4
N90 X14 Y0
N100 X10 Y0
"""
BODY_LENGTH = math.hypot(4, 4) + 4 + 4


def rt_program(inside: bool, passes: int = 5) -> str:
    on, off = "#CONTOUR LOOKAHEAD LOG ON [PARAM=1]", "#CONTOUR LOOKAHEAD LOG OFF [PARAM=8]"
    loop = (f"N60 #RT WHILE [V.L.I < {passes}]\nN65 V.L.I = V.L.I + 1\n"
            + (f"N70 {on}\n" if inside else "") + BODY
            + (f"N130 {off}\n" if inside else "") + "N140 #RT ENDWHILE\n")
    return ("#VAR\nV.L.I = 0\n#ENDVAR\nN10 G1 X10 F600\n"
            + ("" if inside else f"N50 {on}\n") + loop
            + ("" if inside else f"N150 {off}\n") + "N160 G1 X10 Y-10\nM30\n")


def body(first_variation: float, start_count: int) -> list[Expected]:
    """The three lines of the body; ``start_count`` is N80's block count."""
    return [
        Expected(LINEAR, 80, start_count, math.hypot(4, 4), tangent_variation=first_variation),
        Expected(LINEAR, 90, start_count + 1, 4.0, tangent_variation=3 * PI / 4),
        Expected(LINEAR, 100, start_count + 2, 4.0, tangent_variation=PI / 2),
    ]


def test_log_inside_a_real_time_loop_gives_the_body_once_with_the_entry(kernel) -> None:
    run = kernel.run(rt_program(inside=True))
    assert run.channel.state == ChannelState.READY, run.channel.errors.entries
    entry = angle((1, 0), (1, 1))  # from N10 (+X) into N80
    # blocks: N10 = 1, LOG ON (pass 1) = 2, N80.. = 3..5, LOG OFF = 6
    expected = with_starts(10.0, [Expected(LOG_ON, 70, 2, 1.0), *body(entry, 3),
                                  Expected(LOG_OFF, 130, 6, 8.0)])
    assert_entries(request(kernel, 0), expected)


def test_log_around_a_real_time_loop_gives_three_transitions(kernel) -> None:
    run = kernel.run(rt_program(inside=False, passes=5))
    assert run.channel.state == ChannelState.READY, run.channel.errors.entries
    entry = angle((1, 0), (1, 1))  # start of loop: from N10 into N80
    loop = angle((-1, 0), (1, 1))  # loop to loop: from N100 (-X) into N80
    # blocks: N10 = 1, LOG ON = 2, passes of three blocks: 3..5, 6..8, .., 15..17
    first = with_starts(10.0, [Expected(LOG_ON, 50, 2, 1.0), *body(entry, 3)])
    second = with_starts(10.0 + BODY_LENGTH, body(loop, 6))
    last = with_starts(10.0 + 4 * BODY_LENGTH, body(loop, 15))  # the fifth pass
    off = with_starts(10.0 + 5 * BODY_LENGTH, [Expected(LOG_OFF, 150, 18, 8.0)])
    assert_entries(request(kernel, 0), first + second + last + off)


def test_a_loop_of_two_passes_has_two_transitions(kernel) -> None:
    kernel.run(rt_program(inside=False, passes=2))
    reply = request(kernel, 0)
    assert [e.block_type for e in reply] == [LOG_ON] + [LINEAR] * 6 + [LOG_OFF]


# --- CLEAR, #DISTANCE PROG START CLEAR ----------------------------------------------------
CLEAR_PROGRAM = """\
N10 #CONTOUR LOOKAHEAD LOG ON
N20 G1 X10 F600
N30 #CONTOUR LOOKAHEAD LOG OFF
N40 #CONTOUR LOOKAHEAD LOG ON [PARAM=2]
N50 G1 X20
N60 #CONTOUR LOOKAHEAD LOG CLEAR
N70 G1 X30
N80 #CONTOUR LOOKAHEAD LOG ON [PARAM=3]
N90 G1 X40
N100 #CONTOUR LOOKAHEAD LOG OFF
M30
"""


def test_only_the_first_area_until_clear_which_flushes_and_waits(kernel) -> None:
    seen: list[tuple[float, int, float]] = []

    def watch(snap) -> bool:
        ch = snap.channels[0]
        if ch.state == ChannelState.ACTIVE:
            seen.append((ch.path.dist_prog_start_01um / INCR, ch.contour.count_logged_blocks,
                         ch.path.path_velocity_mm_s))
        return False

    kernel.watch(watch)
    run = kernel.run(CLEAR_PROGRAM)
    kernel.wait_for(lambda snap: True)  # stop watching
    assert run.channel.state == ChannelState.READY, run.channel.errors.entries
    # before the path reaches CLEAR at 20 mm the log holds the first area only: the
    # second LOG ON (N40) was ignored, and nothing after CLEAR was prepared
    before = [count for dist, count, _ in seen if dist < 20.0 - 1e-9]
    assert before and set(before) == {3}
    # the path stood still at CLEAR (flush and wait): speed 0 at 20 mm
    assert any(abs(dist - 20.0) < 1e-9 and v == 0.0 for dist, _, v in seen)
    # after CLEAR the new area: LOG ON (N80), N90, LOG OFF
    # blocks: N10..N50 = 1..5, CLEAR = 6, N70 = 7
    expected = with_starts(30.0, [Expected(LOG_ON, 80, 8, 3.0), Expected(LINEAR, 90, 9, 10.0),
                                  Expected(LOG_OFF, 100, 10, 0.0)])
    assert_entries(request(kernel, 0), expected)


def test_clear_inside_a_real_time_loop_is_error_22073(kernel) -> None:
    run = kernel.run("N10 G1 X10 F600\nN20 #RT WHILE [TRUE]\n"
                     "N30   #CONTOUR LOOKAHEAD LOG CLEAR\nN40 #RT ENDWHILE\nM30\n")
    assert run.channel.state == ChannelState.ERROR
    error = run.channel.errors.entries[0]
    assert (error.id, error.line, error.column) == (22073, 3, 7)
    assert run.positions_mm[0] == pytest.approx(10.0)  # the block before it ran


def test_distance_prog_start_clear_restarts_the_distance(kernel) -> None:
    run = kernel.run("N10 #CONTOUR LOOKAHEAD LOG ON\nN20 G1 X10 F600\n"
                     "N30 #DISTANCE PROG START CLEAR\nN40 G1 X15\n"
                     "N50 #CONTOUR LOOKAHEAD LOG OFF\nM30\n")
    assert run.channel.path.dist_prog_start_01um == pytest.approx(5.0 * INCR)
    reply = request(kernel, 0)
    assert [(e.block_number, e.start_position / INCR) for e in reply] == [
        (10, 0.0), (20, 0.0), (40, 0.0), (50, 5.0)]


# --- limits, enabling, reading while running ----------------------------------------------
def test_the_log_keeps_contour_lookahead_log_max_entries_and_warns() -> None:
    config = build_config({"channels": [
        {**build_config().model_dump()["channels"][0], "contour_lookahead_log_max": 4}]})
    program = ("N10 #CONTOUR LOOKAHEAD LOG ON\n"
               + "".join(f"N{20 + k} G1 X{k + 1} F6000\n" for k in range(10))
               + "N99 #CONTOUR LOOKAHEAD LOG OFF\nM30\n")
    with KernelHarness(config=config) as harness:
        run = harness.run(program)
        assert run.channel.state == ChannelState.READY  # a warning does not stop it
        warning = run.channel.errors.entries[0]
        assert warning.warning and warning.id == 22074 and "P-CHAN-00658" in warning.text
        assert (warning.file, warning.line) == ("test.nc", 5)  # N23: the fifth entry
        reply = request(harness, 0)
        assert [e.block_number for e in reply] == [10, 20, 21, 22]
        assert harness.kernel.snapshot.channels[0].contour.count_logged_blocks == 4


def test_contour_commands_need_fct_contour_lah() -> None:
    base = build_config().model_dump()["channels"][0]
    config = build_config({"channels": [{**base, "interpolator_function": "FCT_IPO_DEFAULT"}]})
    with KernelHarness(config=config) as harness:
        run = harness.run("N10 G1 X1 F600\nN20 #CONTOUR LOOKAHEAD LOG ON\nM30\n")
        error = run.channel.errors.entries[0]
        assert (error.id, error.line, error.column) == (22070, 2, 5)
        assert "FCT_CONTOUR_LAH" in error.text
        harness.command(ResetChannel(0, True))
        run = harness.run("N10 G1 X1 F600\nN20 #DISTANCE PROG START CLEAR\nM30\n")
        assert run.channel.state == ChannelState.READY  # needs no function


def test_the_marked_area_is_there_before_it_runs_and_through_feedhold(kernel) -> None:
    program = ("N10 #CONTOUR LOOKAHEAD LOG ON\n"
               + "".join(f"N{20 + k} G1 X{10 * (k + 1)} F600\n" for k in range(8))
               + "N90 #CONTOUR LOOKAHEAD LOG OFF\nM30\n")
    kernel.start(program)
    snap = kernel.wait_for(lambda s: s.channels[0].path.dist_prog_start_01um > 0.0)
    assert snap.channels[0].path.dist_prog_start_01um < 10 * INCR  # still in the first element
    assert snap.channels[0].contour.count_logged_blocks == 10
    reply = request(kernel, 0)
    assert [e.block_type for e in reply] == [LOG_ON] + [LINEAR] * 8 + [LOG_OFF]
    max_before = kernel.kernel.snapshot.channels[0].contour.max_dist_prog_start_01um
    assert max_before == pytest.approx(80 * INCR)
    assert kernel.command(Feedhold(0, True)) is None
    held = kernel.wait_for(lambda s: s.channels[0].path.path_velocity_mm_s == 0.0)
    assert held.channels[0].state == ChannelState.HOLD
    assert held.channels[0].contour.max_dist_prog_start_01um == max_before  # feedhold: same
    assert [e.block_type for e in request(kernel, 0)] == [e.block_type for e in reply]
    assert kernel.command(StartProgram(0, True)) is None
    run = kernel.wait()
    assert run.channel.state == ChannelState.READY


def test_response_size_and_fields_match_the_catalog_and_the_client() -> None:
    from cnc_objects.clients.channel_ops import CONTOUR_BLOCK_FIELDS as CLIENT_FIELDS
    from cnc_objects.clients.channel_ops import CONTOUR_RESPONSE_BLOCKS as CLIENT_BLOCKS
    from cnc_objects.objects.catalog import CONTOUR_BLOCK_FIELDS, CONTOUR_RESPONSE_BLOCKS

    assert RESPONSE_BLOCKS == CONTOUR_RESPONSE_BLOCKS == CLIENT_BLOCKS
    names = tuple(name for name, *_ in CONTOUR_BLOCK_FIELDS)
    assert names == CLIENT_FIELDS == ContourElement._fields


# --- found in review: compensation, buffer-sized mode 2, markers, distance epochs ------
def test_clear_with_radius_compensation_is_error_22072_and_nothing_jumps(kernel) -> None:
    run = kernel.run("N10 G41 D1 G1 X10 Y0 F600\nN20 X20\n"
                     "N25 #CONTOUR LOOKAHEAD LOG CLEAR\nN30 X30\nN40 G40 X40\nM30\n",
                     record=True)
    error = run.channel.errors.entries[0]
    assert (error.id, error.line, error.column) == (22072, 3, 5) and "G40" in error.text
    # the blocks before it ran to their end on the offset path, without a jump
    assert run.positions_mm[:2] == pytest.approx((20.0, 1.0))
    steps = [math.dist(a.positions_mm, b.positions_mm)
             for a, b in zip(run.samples, run.samples[1:])]
    assert max(steps) <= 10.0 * 0.001 + 1e-9  # F600 = 10 mm/s in 1 ms cycles


def test_mode_2_sees_every_element_still_in_the_look_ahead_buffer(kernel) -> None:
    squares = "".join("G1 Y10\nX10\nY0\nX0\n" for _ in range(40))  # 2 elements per corner
    kernel.start(f"N2 G41 D1 G1 X0 Y0.5 F600\n{squares}G40 G1 X-5 Y-5\nM30\n")
    snap = kernel.wait_for(lambda s: s.channels[0].path.dist_prog_start_01um > 0.0)
    ahead = snap.channels[0].contour.max_dist_prog_start_01um
    assert ahead > 1000 * INCR  # the buffer holds 120 blocks, far more elements than 128
    reply = request(kernel, 0.0, 12 * INCR)  # the first elements are still to come
    # the approach line (r = 1 mm), N2's offset line (0.5 mm), then the first square
    assert [e.start_position for e in reply][:3] == [0.0, 10000.0, 15000.0]
    kernel.command(ResetChannel(0, True))


def test_start_positions_are_exact_sums_of_the_lengths(kernel) -> None:
    kernel.run(G41_PROGRAM)
    motion = [e for e in request(kernel, 0) if e.block_type in (LINEAR, CIRCULAR)]
    for before, after in zip(motion, motion[1:]):
        assert after.start_position == before.start_position + before.length  # exactly


def test_loop_markers_are_no_blocks_of_the_path(kernel) -> None:
    """Single block stops at the same places with and without logging the loop."""
    def stops(log: bool) -> list[tuple[float, float, int]]:
        on, off = (("#CONTOUR LOOKAHEAD LOG ON\n", "#CONTOUR LOOKAHEAD LOG OFF\n") if log
                   else ("M8\n", "M9\n"))
        program = ("#VAR\nV.L.I = 0\n#ENDVAR\n" + on + "#RT WHILE [V.L.I < 3]\n"
                   "V.L.I = V.L.I + 1\nG91 G1 X1 F6000\nY1\n#RT ENDWHILE\n" + off + "M30\n")
        kernel.command(ResetChannel(0, True))
        kernel.mdi("G90 G0 X0 Y0")
        kernel.command(SetSingleBlock(0, True))
        kernel.start(program)
        seen = []
        while True:
            snap = kernel.wait_for(lambda s: s.channels[0].program.waiting_for_start
                                   or s.channels[0].state != ChannelState.ACTIVE)
            ch = snap.channels[0]
            if ch.state != ChannelState.ACTIVE:
                break
            seen.append((ch.axes[0].position_mm, ch.axes[1].position_mm, ch.block.block_count))
            # applied and published before it returns: a stop seen next is the next one
            assert kernel.command(StartProgram(0, True)) is None
        kernel.command(SetSingleBlock(0, False))
        return seen

    plain = stops(log=False)
    assert len(plain) == 8 and stops(log=True) == plain
    assert len(request(kernel, 0)) == 2 + 3 * 2  # ON, three passes of two lines, OFF


def test_mode_2_answers_in_the_distances_dist_prog_start_counts(kernel) -> None:
    lines = "".join(f"N{100 + k} X{k + 1}\n" for k in range(40))
    more = "".join(f"N{600 + k} X{41 + k}\n" for k in range(40))
    kernel.start(f"G90 G1 F600\n{lines}N500 #DISTANCE PROG START CLEAR\n{more}M30\n")
    kernel.wait_for(lambda s: s.channels[0].path.dist_prog_start_01um > 0.0)
    # before the path reaches the CLEAR: the elements of the first 40 mm
    assert [e.block_number for e in request(kernel, 0, 2.5 * INCR)] == [100, 101, 102]
    run = kernel.wait()
    assert run.channel.path.dist_prog_start_01um == pytest.approx(40 * INCR)
    # after it: the same window holds the elements after the CLEAR only
    assert [e.block_number for e in request(kernel, 0, 2.5 * INCR)] == [600, 601, 602]


def test_each_manual_block_start_begins_a_new_marked_area(kernel) -> None:
    loop = ("#VAR\nV.L.I = 0\n#ENDVAR\n#CONTOUR LOOKAHEAD LOG ON\n#RT WHILE [V.L.I < 5]\n"
            "V.L.I = V.L.I + 1\nG91 G1 X1 F6000\nY1\nX-1\nY-1\n#RT ENDWHILE\n"
            "#CONTOUR LOOKAHEAD LOG OFF\nG90\n")
    counts = []
    for _ in range(2):
        assert kernel.mdi(loop).channel.state == ChannelState.READY
        counts.append(kernel.kernel.snapshot.channels[0].contour.count_logged_blocks)
    assert counts == [2 + 3 * 4, 2 + 3 * 4]  # ON, three transitions of four lines, OFF


def test_mode_2_answers_the_elements_of_the_log_field_for_field(kernel) -> None:
    """Mode 2 makes its elements only when asked (issue 37, short blocks): each is the
    same, to the last bit, as the log's entry of that element (arcs of compensation,
    programmed radii and tangent variations included)."""
    kernel.run(G41_PROGRAM)
    logged = [e for e in request(kernel, 0) if e.block_type in (LINEAR, CIRCULAR)]
    assert len(logged) > 5
    for entry in logged:  # a window at the element's start: that element comes first
        reply = request(kernel, entry.start_position, 0.5)
        assert reply and reply[0] == entry
