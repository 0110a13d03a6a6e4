"""PathExecutor end to end: timing, limits, block ends, holds, stops, errors."""

from __future__ import annotations

import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from cnc_objects.service.kernel.nc.blocks import StopKind
from cnc_objects.service.kernel.path import (
    AxisDynamics,
    PathError,
    PathErrorId,
    PathExecutor,
    Waiting,
    plan_time_optimal,
)

from .programs import (
    DT,
    DYN,
    DYN_MIXED,
    arc,
    check_axis_limits,
    dwell,
    line,
    polyline,
    run,
    stop,
    technology,
    trapezoid_time,
)

ORIGIN = (0.0, 0.0, 0.0)


def executor(start=ORIGIN, dynamics=DYN, **kw) -> PathExecutor:
    return PathExecutor(dynamics, start, cycle_s=DT, **kw)


def finish_cycle(trace, block) -> int:
    """1-based cycle in which ``block`` was reported finished."""
    for k, res in enumerate(trace.results, start=1):
        if any(b is block for b in res.finished):
            return k
    raise AssertionError("block never finished")


# -- machining time against closed forms --------------------------------------------


@pytest.mark.parametrize("length, feed", [(100.0, 100.0), (0.3, 100.0), (250.0, 400.0)])
def test_single_line_time_is_the_trapezoid(length, feed) -> None:
    blk = line(ORIGIN, (length, 0, 0), feed)
    trace = run(executor(), [blk])
    expected = trapezoid_time(length, 5000.0, feed, 0.0, 0.0)
    elapsed = finish_cycle(trace, blk) * DT
    assert expected - 1e-9 <= elapsed < expected + DT  # within one cycle (one stop)
    assert trace.positions[-1] == (length, 0.0, 0.0)


def test_collinear_lines_are_one_trapezoid() -> None:
    xs = [0.0, 3.0, 10.0, 10.5, 40.0, 41.0, 100.0]
    blocks = polyline([(x, 0, 0) for x in xs], 120.0)
    trace = run(executor(), blocks)
    expected = trapezoid_time(100.0, 5000.0, 120.0, 0.0, 0.0)
    elapsed = finish_cycle(trace, blocks[-1]) * DT
    assert expected - 1e-9 <= elapsed < expected + DT
    assert [r.path_velocity_mm_s for r in trace.results].count(0.0) == 1  # no stop on the way


def test_diagonal_line_uses_the_axis_derived_acceleration() -> None:
    # direction (0.6, 0.8, 0) with DYN_MIXED: a = min(4000/0.6, 2500/0.8) = 3125,
    # speed cap min(300/0.6, 200/0.8) = 250 < F
    blk = line(ORIGIN, (60, 80, 0), 1000.0)
    trace = run(executor(dynamics=DYN_MIXED), [blk])
    expected = trapezoid_time(100.0, 3125.0, 250.0, 0.0, 0.0)
    assert expected - 1e-9 <= finish_cycle(trace, blk) * DT < expected + DT


def test_square_corner_speed_from_the_velocity_jump() -> None:
    pts = [ORIGIN, (50, 0, 0), (50, 50, 0), (0, 50, 0), ORIGIN]
    blocks = polyline(pts, 100.0)
    trace = run(executor(), blocks)
    # dV 50 mm/s on X and Y, tangents change by 1 on both: corners at 50 mm/s
    expected = (trapezoid_time(50, 5000, 100, 0, 50) + 2 * trapezoid_time(50, 5000, 100, 50, 50)
                + trapezoid_time(50, 5000, 100, 50, 0))
    elapsed = finish_cycle(trace, blocks[-1]) * DT
    assert expected - 1e-9 <= elapsed < expected + DT
    for blk in blocks[:-1]:  # at each corner the speed is 50 mm/s
        k = finish_cycle(trace, blk)
        speeds = [trace.results[k - 2].path_velocity_mm_s, trace.results[k - 1].path_velocity_mm_s]
        assert min(speeds) <= 50.0 + 5000 * DT and max(speeds) >= 50.0 - 5000 * DT


def test_time_matches_the_whole_program_plan_with_dwell_and_stops() -> None:
    blocks = [line(ORIGIN, (30, 0, 0)), line((30, 0, 0), (30, 20, 0)), dwell(0.1234),
              line((30, 20, 0), (0, 20, 5)), stop(StopKind.PROGRAMMED),
              line((0, 20, 5), ORIGIN, 50.0)]
    trace = run(executor(), blocks)
    optimal = plan_time_optimal(blocks, DYN)
    stops = 3  # dwell, M0, end (the M0 wait takes one cycle of standing before resume)
    assert optimal - 1e-9 <= trace.cycles * DT <= optimal + (stops + 1) * DT


def test_unbounded_buffer_reaches_the_optimal_time_on_short_segments() -> None:
    pts = [(20 * math.cos(k * 0.01), 20 * math.sin(k * 0.01), 0.0) for k in range(400)]
    blocks = polyline(pts, 150.0)
    trace = run(executor(pts[0], buffer_blocks=1000), blocks)
    optimal = plan_time_optimal(blocks, DYN)
    assert optimal - 1e-9 <= trace.cycles * DT < optimal + DT


# -- limits ---------------------------------------------------------------------------

def _mixed_program():
    return [
        line(ORIGIN, (40, 10, 0), 200.0),
        line((40, 10, 0), (40, 10, -5), 50.0),
        arc((40, 10, -5), (60, 10, -5), (50, 10), ccw=True, feed_mm_s=250.0),
        arc((60, 10, -5), (70, 10, -5), (65, 10), ccw=False, feed_mm_s=250.0),
        line((70, 10, -5), (70, 40, -5), 300.0),
        arc((70, 40, -5), (70, 40, -5), (60, 40), ccw=True, feed_mm_s=300.0),  # full circle
        line((70, 40, -5), (0, 0, 0), rapid=True),
    ]


def _arc_program():
    return [arc((10, 0, 0), (10, 0, 0), (0, 0), ccw=True, feed_mm_s=400.0),
            arc((10, 0, 0), (-10, 0, 0), (0, 0), ccw=False, feed_mm_s=400.0),
            arc((-10, 0, 0), (-12, 0, 0), (-11, 0), ccw=True, feed_mm_s=400.0)]


PROGRAMS = {
    "lines": lambda: polyline([ORIGIN, (30, 0, 0), (30, 25, 3), (5, 40, 3), (5, 40, -4),
                               (60, 0, 0)], 250.0),
    "arcs": _arc_program,
    "mixed": _mixed_program,
}


@pytest.mark.parametrize("override", [0.5, 1.0, 1.5])
@pytest.mark.parametrize("name", sorted(PROGRAMS))
def test_axis_limits_hold_inside_blocks(name, override) -> None:
    blocks = PROGRAMS[name]()
    trace = run(executor(blocks[0].motion.start_mm, DYN_MIXED), blocks, override=override)
    max_v, max_a = check_axis_limits(trace, DYN_MIXED)
    assert max_a > 0.7  # the limits are used (arcs: tangential A/sqrt(2) at least)
    assert trace.positions[-1] == pytest.approx(blocks[-1].motion.end_mm, abs=1e-12)


def test_axis_limits_hold_with_override_changes_and_feedhold() -> None:
    blocks = _mixed_program()
    holds = {}

    def on_cycle(cycle, ex, res):
        if cycle == 150:
            ex.hold()
            holds["at"] = res.position_mm
        if cycle == 400:
            assert res.path_velocity_mm_s == 0.0 and ex.holding
            ex.resume()

    def override(cycle):
        return 1.5 if cycle < 300 else (0.3 if cycle < 600 else 1.0)

    trace = run(executor(dynamics=DYN_MIXED), blocks, override=override, on_cycle=on_cycle)
    check_axis_limits(trace, DYN_MIXED)
    assert trace.positions[-1] == pytest.approx(ORIGIN, abs=1e-12)
    assert list(trace.finished) == blocks


@settings(max_examples=15, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(st.tuples(st.floats(-20, 20), st.floats(-20, 20), st.floats(-3, 3)),
                min_size=2, max_size=8),
       st.floats(20, 400), st.sampled_from([0.5, 1.0, 1.3]))
def test_random_polylines_respect_the_limits(points, feed, override) -> None:
    pts = [ORIGIN] + [tuple(p) for p in points]
    pts = [p for k, p in enumerate(pts) if k == 0 or math.dist(p, pts[k - 1]) > 1e-3]
    if len(pts) < 2:
        return
    blocks = polyline(pts, feed)
    trace = run(executor(dynamics=DYN_MIXED), blocks, override=override)
    check_axis_limits(trace, DYN_MIXED)
    assert trace.finished == blocks
    assert trace.positions[-1] == pts[-1]
    if override == 1.0:
        optimal = plan_time_optimal(blocks, DYN_MIXED)
        assert optimal - 1e-9 <= trace.cycles * DT < optimal + DT


def test_override_above_100_percent_never_exceeds_axis_limits() -> None:
    blk = line(ORIGIN, (0, 0, 50), 90.0)  # Z: V = 100 mm/s in DYN_MIXED
    trace = run(executor(dynamics=DYN_MIXED), [blk], override=2.0)
    assert max(r.path_velocity_mm_s for r in trace.results) == pytest.approx(100.0)
    check_axis_limits(trace, DYN_MIXED)


# -- block ends -----------------------------------------------------------------------

def test_several_block_ends_per_cycle() -> None:
    pts = [(0.01 * k, 0.0, 0.0) for k in range(1001)]  # 0.01 mm blocks at 200 mm/s
    blocks = polyline(pts, 200.0)
    blocks.insert(500, technology(8))
    trace = run(executor(buffer_blocks=190), blocks)
    assert max(len(r.finished) for r in trace.results) >= 15
    assert trace.finished == blocks  # each exactly once, in order
    assert trace.results[-1].distance_mm == pytest.approx(10.0)


def test_same_program_gives_identical_cycles() -> None:
    def once():
        return run(executor(dynamics=DYN_MIXED), _mixed_program(), override=0.9).positions
    assert once() == once()


def test_step_result_fields_during_a_block() -> None:
    blocks = [line(ORIGIN, (10, 0, 0), 100.0, number=10), line((10, 0, 0), (10, 5, 0), 50.0)]
    ex = executor()
    for b in blocks:
        ex.push(b)
    ex.close()
    res = ex.step(1.0)
    assert res.current is blocks[0] and res.programmed_velocity_mm_s == 100.0
    assert res.path_velocity_mm_s == pytest.approx(5.0)
    assert res.remaining_in_block_mm == pytest.approx(10.0 - 0.0025)
    assert res.distance_mm == pytest.approx(0.0025) and res.stopped_at is None
    rapid = executor()
    rapid.push(line(ORIGIN, (10, 0, 0), rapid=True))
    assert rapid.step(1.0).programmed_velocity_mm_s == 500.0  # G0: axis limit


# -- feedhold, single block, dwell, stops ---------------------------------------------

def test_feedhold_decelerates_within_limits_and_resume_reaches_the_end() -> None:
    blk = line(ORIGIN, (100, 0, 0), 200.0)
    positions_at_hold = []

    def on_cycle(cycle, ex, res):
        if cycle == 200:
            ex.hold()
        if ex.holding and res.path_velocity_mm_s == 0.0 and not positions_at_hold:
            positions_at_hold.append((cycle, res.position_mm))
        if cycle == 300:
            assert res.path_velocity_mm_s == 0.0
            ex.resume()

    trace = run(executor(), [blk], on_cycle=on_cycle)
    stopped_cycle, stopped_pos = positions_at_hold[0]
    assert stopped_cycle - 200 <= math.ceil(200.0 / 5000.0 / DT) + 1  # 40 cycles of braking
    assert trace.positions[250] == stopped_pos  # standing while held
    assert trace.positions[-1] == (100.0, 0.0, 0.0)
    check_axis_limits(trace, DYN)
    # the hold costs exactly the standing time plus the lost acceleration/braking time
    assert trace.cycles * DT > trapezoid_time(100, 5000, 200, 0, 0) + 0.05


def test_single_block_stops_at_each_block_end() -> None:
    pts = [ORIGIN, (10, 0, 0), (10, 10, 0), (0, 10, 0)]
    blocks = polyline(pts, 100.0)
    ex = executor()
    ex.single_block = True
    for b in blocks:
        ex.push(b)
    ex.close()
    done = []
    for _ in range(5000):
        res = ex.step(1.0)
        done.extend(res.finished)
        if ex.waiting == Waiting.SINGLE_BLOCK:
            assert res.path_velocity_mm_s == 0.0
            assert res.position_mm == blocks[len(done) - 1].motion.end_mm
            for _ in range(10):  # stays there until resume
                assert ex.step(1.0).position_mm == res.position_mm
            ex.resume()
        if ex.idle:
            break
    assert done == blocks


def test_single_block_switched_on_while_moving_stops_where_it_still_can() -> None:
    # 0.5 mm blocks at 200 mm/s: braking takes 4 mm, so the stop lands several blocks later
    pts = [(0.5 * k, 0, 0) for k in range(61)]
    blocks = polyline(pts, 200.0)
    ex = executor(buffer_blocks=200)
    for b in blocks:
        ex.push(b)
    ex.close()
    for _ in range(100):
        ex.step(1.0)
    pos_before = ex.position_mm[0]
    assert ex.path_velocity_mm_s == pytest.approx(200.0)
    ex.single_block = True
    trace_v = []
    for _ in range(200):
        res = ex.step(1.0)
        trace_v.append(res.path_velocity_mm_s)
        if ex.waiting == Waiting.SINGLE_BLOCK:
            break
    assert ex.waiting == Waiting.SINGLE_BLOCK
    stop_x = ex.position_mm[0]
    assert stop_x == pytest.approx(round(stop_x / 0.5) * 0.5, abs=1e-12)  # at a block end
    brake = 200.0 ** 2 / (2 * 5000.0)
    assert pos_before + brake <= stop_x + 1e-9 < pos_before + brake + 0.5 + 200.0 * DT
    for a, b in zip(trace_v, trace_v[1:]):
        assert abs(b - a) <= 5000 * DT * (1 + 1e-9)


def test_dwell_stands_for_its_time_and_finishes_afterwards() -> None:
    d = dwell(0.05)
    blocks = [line(ORIGIN, (5, 0, 0)), d, line((5, 0, 0), (10, 0, 0))]
    trace = run(executor(), blocks)
    arrive = finish_cycle(trace, blocks[0])
    leave = finish_cycle(trace, d)
    assert 49 <= leave - arrive <= 51
    assert all(p == (5.0, 0.0, 0.0) for p in trace.positions[arrive:leave])
    assert trace.results[arrive + 10].current is d
    assert trace.finished == blocks


def test_programmed_stop_waits_and_is_reported_every_cycle() -> None:
    m0 = line((10, 0, 0), (20, 0, 0), stop=StopKind.PROGRAMMED)
    m30 = stop(StopKind.PROGRAM_END)
    blocks = [line(ORIGIN, (10, 0, 0)), m0, technology(3), line((20, 0, 0), (25, 0, 0)), m30]
    ex = executor()
    for b in blocks:
        ex.push(b)
    ex.close()
    results = [ex.step(1.0) for _ in range(1000)]
    waiting = [r for r in results if r.stopped_at is m0]
    assert len(waiting) > 500 and all(r.position_mm == (20.0, 0.0, 0.0) for r in waiting)
    assert all(r.path_velocity_mm_s == 0.0 for r in waiting)
    assert not ex.idle and ex.waiting == Waiting.PROGRAMMED_STOP
    ex.resume()
    results = [ex.step(1.0) for _ in range(1000)]
    assert results[-1].stopped_at is m30 and results[-1].position_mm == (25.0, 0.0, 0.0)
    finished = [b for r in results for b in r.finished]
    assert finished == blocks[2:]
    ex.resume()
    ex.step(1.0)
    assert ex.idle


def test_override_zero_stands_and_continues() -> None:
    ex = executor()
    ex.push(line(ORIGIN, (50, 0, 0)))
    ex.close()
    for _ in range(100):
        ex.step(1.0)
    for _ in range(100):
        res = ex.step(0.0)
    assert res.path_velocity_mm_s == 0.0
    assert ex.step(0.0).position_mm == res.position_mm
    for _ in range(2000):
        res = ex.step(1.0)
    assert res.position_mm == (50.0, 0.0, 0.0) and ex.idle


def test_stop_now_drops_everything() -> None:
    ex = executor(buffer_blocks=5)
    for b in polyline([ORIGIN, (10, 0, 0), (10, 10, 0), (0, 10, 0)], 100.0):
        ex.push(b)
    assert ex.free_slots() == 2
    for _ in range(50):
        ex.step(1.0)
    pos = ex.position_mm
    ex.stop_now()
    assert ex.idle and ex.free_slots() == 5
    res = ex.step(1.0)
    assert res.position_mm == pos and res.current is None and res.path_velocity_mm_s == 0.0
    ex.push(line(pos, (0, 0, 0)))  # a new program starts where the path stands
    ex.close()
    trace = run(ex, [])
    assert trace.positions[-1] == ORIGIN


# -- buffer and errors ----------------------------------------------------------------

def test_buffer_full() -> None:
    ex = executor(buffer_blocks=3)
    blocks = polyline([(k, 0, 0) for k in range(6)], 100.0)
    for b in blocks[:3]:
        ex.push(b)
    assert ex.free_slots() == 0
    with pytest.raises(PathError) as err:
        ex.push(blocks[3])
    assert err.value.id == PathErrorId.BUFFER_FULL and err.value.block is blocks[3]


def test_software_limit_refuses_the_block_before_any_motion() -> None:
    limits = [(-1.0, 100.0), (-50.0, 50.0), (-20.0, 20.0)]
    ex = executor(sw_limits_mm=limits)
    bad = line(ORIGIN, (150, 0, 0))
    with pytest.raises(PathError) as err:
        ex.push(bad)
    assert err.value.id == PathErrorId.SW_LIMIT_MAX and err.value.block is bad
    assert "axis 1" in str(err.value) and "50101" in str(err.value)
    for _ in range(10):
        assert ex.step(1.0).position_mm == ORIGIN
    assert ex.idle


def test_software_limit_checks_the_extreme_points_of_arcs() -> None:
    limits = [(-100.0, 100.0), (-100.0, 30.0), (-20.0, 20.0)]
    ex = executor(sw_limits_mm=limits)
    good = line(ORIGIN, (20, 0, 0))
    ex.push(good)
    # semicircle from (20,0) to (-20,0) ccw around the origin reaches y = 20 ... fine
    ex.push(arc((20, 0, 0), (-20, 0, 0), (0, 0), ccw=True))
    # ... but one of radius 40 reaches y = 40 > 30, although both end points are inside
    bad = arc((-20, 0, 0), (60, 0, 0), (20, 0), ccw=False)
    with pytest.raises(PathError) as err:
        ex.push(bad)
    assert err.value.id == PathErrorId.SW_LIMIT_MAX
    ex.close()
    trace = run(ex, [])  # what was buffered before still runs
    assert trace.positions[-1] == pytest.approx((-20.0, 0.0, 0.0), abs=1e-12)
    assert max(p[1] for p in trace.positions) <= 20.0 + 1e-9


@pytest.mark.parametrize("block, error", [
    (line((1, 0, 0), (5, 0, 0)), PathErrorId.START_MISMATCH),
    (line(ORIGIN, (5, 0)), PathErrorId.AXIS_COUNT),
    (line(ORIGIN, (5, 0, 0), 0.0), PathErrorId.FEED_INVALID),
    (line(ORIGIN, (math.nan, 0, 0)), PathErrorId.NOT_FINITE),
    (arc(ORIGIN, (10, 0, 0), (5, 0), ccw=True, plane=(0, 0)), PathErrorId.PLANE_INVALID),
])
def test_invalid_blocks(block, error) -> None:
    ex = executor()
    with pytest.raises(PathError) as err:
        ex.push(block)
    assert err.value.id == error and err.value.block is block
    assert ex.free_slots() == 120


def test_constructor_validates() -> None:
    with pytest.raises(ValueError):
        PathExecutor(DYN, (0, 0), cycle_s=DT)
    with pytest.raises(ValueError):
        PathExecutor(DYN, ORIGIN, cycle_s=0.0)
    with pytest.raises(ValueError):
        AxisDynamics(0.0, 1.0, 1.0)


def test_feedhold_over_many_short_blocks_and_override_steps() -> None:
    pts = [(8 * math.cos(k * 0.02), 8 * math.sin(k * 0.02), 0.001 * k) for k in range(600)]
    blocks = polyline(pts, 250.0)
    held_at = []

    def on_cycle(cycle, ex, res):
        if cycle == 30:
            ex.hold()
        if ex.holding and res.path_velocity_mm_s == 0.0 and not held_at:
            held_at.append(res.finished)
        if cycle == 120:
            ex.resume()

    def override(cycle):
        return 1.4 if cycle < 200 else 0.6

    trace = run(executor(pts[0], DYN_MIXED), blocks, override=override, on_cycle=on_cycle)
    assert held_at, "the hold never came to a stop"
    check_axis_limits(trace, DYN_MIXED)
    assert trace.finished == blocks
    assert trace.positions[-1] == pts[-1]
    speeds = [r.path_velocity_mm_s for r in trace.results]
    assert all(v == 0.0 for v in speeds[80:120])  # standing while held
