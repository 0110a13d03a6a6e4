"""The planning model: element limits, junction rule, backward/forward passes."""

from __future__ import annotations

import math
import random

import pytest

from cnc_objects.service.kernel.path import plan_profile, plan_time_optimal
from cnc_objects.service.kernel.path.geometry import Arc, Line
from cnc_objects.service.kernel.path.limits import corner_limit_mm_s, element_limits
from cnc_objects.service.kernel.path.planner import LookAhead
from cnc_objects.service.kernel.path.segments import PathPreparation, Segment

from .programs import DYN, DYN_MIXED, dwell, line, polyline, trapezoid_time


def test_line_limits_per_axis() -> None:
    lim = element_limits(Line((0, 0, 0), (3, 4, 0)), 1000.0, DYN_MIXED)
    assert lim.axis_speed_mm_s == pytest.approx(min(300 / 0.6, 200 / 0.8))  # 250
    assert lim.speed_mm_s == pytest.approx(250.0)
    assert lim.acc_mm_s2 == pytest.approx(min(4000 / 0.6, 2500 / 0.8))  # 3125
    assert element_limits(Line((0, 0, 0), (3, 4, 0)), 100.0, DYN_MIXED).speed_mm_s == 100.0
    rapid = element_limits(Line((0, 0, 0), (0, 0, -5)), math.inf, DYN_MIXED)
    assert rapid.speed_mm_s == rapid.axis_speed_mm_s == 100.0  # Z alone


def test_arc_limits() -> None:
    arc = Arc.from_points((10, 0, 0), (-10, 0, 0), (0, 0), (0, 1), True)
    lim = element_limits(arc, 1000.0, DYN_MIXED)
    acc = min(4000, 2500) / math.sqrt(2)
    assert lim.acc_mm_s2 == pytest.approx(acc)
    assert lim.speed_mm_s == pytest.approx(min(300, 200, math.sqrt(10 * acc)))
    big = Arc.from_points((1000, 0, 0), (-1000, 0, 0), (0, 0), (0, 1), True)
    assert element_limits(big, 1000.0, DYN_MIXED).speed_mm_s == pytest.approx(200.0)


def test_corner_limit() -> None:
    jumps = [30.0, 20.0, 10.0]
    assert corner_limit_mm_s((1, 0, 0), (0, 1, 0), jumps) == pytest.approx(20.0)
    assert corner_limit_mm_s((1, 0, 0), (1, 0, 0), jumps) == math.inf
    assert corner_limit_mm_s((1, 0, 0), (-1, 0, 0), jumps) == pytest.approx(15.0)
    s = math.sqrt(0.5)
    assert corner_limit_mm_s((1, 0, 0), (s, 0, s), jumps) == pytest.approx(
        min(30 / (1 - s), 10 / s))


def _segments(blocks, dynamics=DYN):
    prep = PathPreparation(dynamics, blocks[0].motion.start_mm)
    return [s for b in blocks for s in prep.prepare(b) if isinstance(s, Segment)]


def _reference_exits(segs, jumps):
    """Straightforward backward pass over a list (independent of LookAhead)."""
    exits = [0.0] * len(segs)
    entry_next = 0.0
    for j in range(len(segs) - 1, -1, -1):
        s = segs[j]
        if j == len(segs) - 1:
            ex = 0.0
        else:
            ex = min(corner_limit_mm_s(s.tangent_end, segs[j + 1].tangent_start, jumps),
                     s.speed_mm_s, segs[j + 1].speed_mm_s, entry_next)
        exits[j] = ex
        entry_next = min(s.speed_mm_s, math.sqrt(ex * ex + 2 * s.acc_mm_s2 * s.length_mm))
    return exits


def test_incremental_backward_pass_equals_full_pass() -> None:
    rng = random.Random(7)
    pts = [(0.0, 0.0, 0.0)]
    for _ in range(150):
        x, y, z = pts[-1]
        pts.append((x + rng.uniform(-3, 3), y + rng.uniform(-3, 3), z + rng.uniform(-0.5, 0.5)))
    blocks = [line(a, b, rng.choice([20.0, 80.0, 300.0])) for a, b in zip(pts, pts[1:])]
    segs = _segments(blocks, DYN_MIXED)
    jumps = [d.vel_jump_mm_s for d in DYN_MIXED]
    la = LookAhead(jumps)
    for k, seg in enumerate(segs, start=1):
        la.append(seg)
        if k % 3 == 0 or k == len(segs):  # several appends per pass, as in a cycle
            la.update()
            assert [s.exit_mm_s for s in la] == _reference_exits(segs[:k], jumps)


def test_pass_stops_early_on_a_long_program() -> None:
    """Appending to a long buffer of short segments touches only the stopping distance."""
    pts = [(0.05 * k, 0.0, 0.0) for k in range(2001)]
    segs = _segments(polyline(pts, 100.0))
    la = LookAhead([50.0] * 3)
    for seg in segs[:1999]:
        la.append(seg)
    la.update()
    before = [(s.exit_mm_s, s.entry_mm_s) for s in segs[:1999]]
    la.append(segs[1999])
    la.update()
    changed = sum(b != (s.exit_mm_s, s.entry_mm_s) for b, s in zip(before, segs[:1999]))
    stop_distance = 100.0 ** 2 / (2 * 5000.0)  # 1 mm = 20 segments
    assert 0 < changed <= stop_distance / 0.05 + 2


def test_time_of_one_line_is_the_trapezoid() -> None:
    blocks = [line((0, 0, 0), (100, 0, 0), 100.0)]
    assert plan_time_optimal(blocks, DYN) == pytest.approx(trapezoid_time(100, 5000, 100, 0, 0))
    short = [line((0, 0, 0), (0.5, 0, 0), 100.0)]  # triangle
    assert plan_time_optimal(short, DYN) == pytest.approx(2 * math.sqrt(0.5 / 5000))


def test_square_plan_uses_the_velocity_jump_at_corners() -> None:
    pts = [(0, 0, 0), (50, 0, 0), (50, 50, 0), (0, 50, 0), (0, 0, 0)]
    plan = plan_profile(polyline(pts, 100.0), DYN)
    assert [p.exit_mm_s for p in plan] == pytest.approx([50.0, 50.0, 50.0, 0.0])
    expected = (trapezoid_time(50, 5000, 100, 0, 50) + 2 * trapezoid_time(50, 5000, 100, 50, 50)
                + trapezoid_time(50, 5000, 100, 50, 0))
    assert plan_time_optimal(polyline(pts, 100.0), DYN) == pytest.approx(expected)


def test_plan_is_consistent() -> None:
    """Every element's entry and exit are mutually reachable and below its limits."""
    rng = random.Random(3)
    pts = [(0.0, 0.0, 0.0)]
    for _ in range(200):
        x, y, z = pts[-1]
        pts.append((x + rng.uniform(-2, 2), y + rng.uniform(-2, 2), z))
    blocks = polyline(pts, 150.0)
    plan = plan_profile(blocks, DYN_MIXED)
    segs = _segments(blocks, DYN_MIXED)
    prev_exit = 0.0
    for p, s in zip(plan, segs):
        assert p.entry_mm_s == prev_exit
        two_al = 2 * s.acc_mm_s2 * s.length_mm
        assert p.exit_mm_s ** 2 <= p.entry_mm_s ** 2 + two_al + 1e-9
        assert p.entry_mm_s ** 2 <= p.exit_mm_s ** 2 + two_al + 1e-9
        assert p.peak_mm_s <= s.speed_mm_s + 1e-12
        prev_exit = p.exit_mm_s
    assert plan[-1].exit_mm_s == 0.0


def test_dwell_and_stops_in_the_plan() -> None:
    blocks = [line((0, 0, 0), (10, 0, 0)), dwell(0.5), line((10, 0, 0), (20, 0, 0))]
    plan = plan_profile(blocks, DYN)
    assert plan[0].exit_mm_s == 0.0  # the dwell needs a stop
    assert plan_time_optimal(blocks, DYN) == pytest.approx(
        2 * trapezoid_time(10, 5000, 100, 0, 0) + 0.5)


def test_streamed_buffer_plans_like_the_whole_program() -> None:
    """Backward pass incrementally, forward pass on demand: equal to ``plan_profile``."""
    rng = random.Random(11)
    pts = [(0.0, 0.0, 0.0)]
    for _ in range(120):
        x, y, z = pts[-1]
        pts.append((x + rng.uniform(-4, 4), y + rng.uniform(-4, 4), z + rng.uniform(-1, 1)))
    blocks = polyline(pts, 200.0)
    la = LookAhead([d.vel_jump_mm_s for d in DYN_MIXED])
    for seg in _segments(blocks, DYN_MIXED):
        la.append(seg)
    streamed = [(v_in, v_out) for _, v_in, v_out in la.forward(0.0)]
    whole = [(p.entry_mm_s, p.exit_mm_s) for p in plan_profile(blocks, DYN_MIXED)]
    assert streamed == whole
