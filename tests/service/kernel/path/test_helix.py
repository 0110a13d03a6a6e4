"""Helical interpolation (issue 39): G2/G3 whose axis outside the plane moves.

Hand values: a helix of radius R, sweep theta and rise dz has the length
sqrt((R*theta)^2 + dz^2); at the angle phi travelled from the start the rising axis
stands at z0 + dz * phi / theta.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import pytest

from cnc_objects.service.kernel.nc.blocks import Compensation
from cnc_objects.service.kernel.path import AxisDynamics, PathError, PathErrorId, PathExecutor
from cnc_objects.service.kernel.path.geometry import Arc
from cnc_objects.service.kernel.path.limits import element_limits

from .programs import DT, DYN, arc, check_axis_limits, line, run, trapezoid_time

ORIGIN = (0.0, 0.0, 0.0)


def executor(start: tuple[float, ...] = ORIGIN,
             dynamics: Any = DYN) -> PathExecutor:
    return PathExecutor(dynamics, start, cycle_s=DT)


def finish_cycle(trace: Any, block: Any) -> int:
    for k, res in enumerate(trace.results, start=1):
        if any(b is block for b in res.finished):
            return k
    raise AssertionError("block never finished")


def travelled(point: Sequence[float], centre: Sequence[float], start_angle: float,
              ccw: bool) -> float:
    """Angle (rad, >= 0) from ``start_angle`` to ``point`` in the direction of motion."""
    angle = math.atan2(point[1] - centre[1], point[0] - centre[0])
    return float(((angle - start_angle) if ccw else (start_angle - angle)) % (2.0 * math.pi))


def test_helix_geometry_by_hand() -> None:
    # G17 G2 from (10, 0, 0) to (0, -10, -5) around (0, 0): a quarter turn clockwise
    element = Arc.from_points((10.0, 0.0, 0.0), (0.0, -10.0, -5.0), (0.0, 0.0), (0, 1),
                              ccw=False)
    quarter = 10.0 * math.pi / 2.0
    assert element.length_mm == pytest.approx(math.hypot(quarter, 5.0), rel=1e-12)
    assert element.plane_length_mm == pytest.approx(quarter, rel=1e-12)
    for frac in (0.0, 0.25, 0.5, 0.75, 1.0):
        x, y, z = element.point_at(frac * element.length_mm)
        phi = frac * math.pi / 2.0  # clockwise from the +X axis
        assert (x, y, z) == pytest.approx((10.0 * math.cos(phi), -10.0 * math.sin(phi),
                                           -5.0 * frac), abs=1e-9)
    assert element.end_mm == (0.0, -10.0, -5.0)
    t = element.tangent_start  # unit: plane share quarter/L, Z share -5/L
    assert math.fsum(c * c for c in t) == pytest.approx(1.0, rel=1e-12)
    assert t == pytest.approx((0.0, -quarter / element.length_mm, -5.0 / element.length_mm))
    low, high = element.extent_mm()
    assert low == pytest.approx((0.0, -10.0, -5.0)) and high == pytest.approx((10.0, 0.0, 0.0))


def test_helix_runs_on_the_helix_every_cycle_and_takes_the_hand_time() -> None:
    # G17 G3 X-10 Y0 Z-6 I-10 J0 from (10, 0, 0): half a turn ccw, 6 mm down, F 50 mm/s
    centre, radius, dz, feed = (0.0, 0.0), 10.0, -6.0, 50.0
    blk = arc((10, 0, 0), (-10, 0, dz), centre, ccw=True, feed_mm_s=feed)
    trace = run(executor((10.0, 0.0, 0.0)), [blk])
    theta = math.pi
    length = math.hypot(radius * theta, dz)
    for point in trace.positions:
        phi = travelled(point, centre, 0.0, ccw=True)
        if point == trace.positions[-1]:
            phi = theta  # the end: -pi folds to pi
        assert math.hypot(point[0], point[1]) == pytest.approx(radius, abs=1e-9)
        assert point[2] == pytest.approx(dz * phi / theta, abs=1e-9)
    assert trace.positions[-1] == pytest.approx((-10.0, 0.0, dz), abs=1e-12)
    # path time: a trapezoid over the helix length; acceleration by hand from the axes:
    # plane share c = R*theta/L: min(A_x, A_y)/sqrt(2)/c, Z share |dz|/L: A_z*L/|dz|
    c = radius * theta / length
    acc = min(5000.0 / math.sqrt(2.0) / c, 5000.0 * length / abs(dz))
    expected = trapezoid_time(length, acc, feed, 0.0, 0.0)
    assert expected - 1e-9 <= finish_cycle(trace, blk) * DT < expected + DT
    check_axis_limits(trace, DYN)


def test_full_turn_helix_and_thread_milling() -> None:
    # thread milling M10 x 1.5 inside: three full turns G2 I-4 Z-1.5 from (4, 0, 0)
    pitch, radius, feed = 1.5, 4.0, 20.0
    blocks, z = [], 0.0
    for _ in range(3):
        blocks.append(arc((radius, 0, z), (radius, 0, z - pitch), (0, 0), ccw=False,
                          feed_mm_s=feed))
        z -= pitch
    trace = run(executor((radius, 0.0, 0.0)), blocks)
    assert trace.positions[-1] == pytest.approx((radius, 0.0, -3 * pitch), abs=1e-12)
    turn = math.hypot(2.0 * math.pi * radius, pitch)
    total_phi = 0.0
    previous = trace.positions[0]
    for point in trace.positions[1:]:
        assert math.hypot(point[0], point[1]) == pytest.approx(radius, abs=1e-9)
        step = travelled(point, (0.0, 0.0), math.atan2(previous[1], previous[0]), ccw=False)
        total_phi += step if step < math.pi else 0.0
        # z falls by one pitch per turn, linearly with the angle
        assert point[2] == pytest.approx(-pitch * total_phi / (2.0 * math.pi), abs=1e-6)
        previous = point
    assert total_phi == pytest.approx(3 * 2.0 * math.pi, abs=1e-6)
    # tangent turns: no stop between the turns, so about L/F plus one ramp up and down
    ramp = feed / (5000.0 / math.sqrt(2.0) * turn / (2.0 * math.pi * radius))
    assert finish_cycle(trace, blocks[-1]) * DT == pytest.approx(3 * turn / feed + ramp,
                                                                 abs=2 * DT)
    check_axis_limits(trace, DYN)


def test_rising_axis_limits_the_helix_speed() -> None:
    # Z may move only 1 mm/s: a steep helix must not move Z faster than that
    dyn = (AxisDynamics(500.0, 5000.0, 50.0), AxisDynamics(500.0, 5000.0, 50.0),
           AxisDynamics(1.0, 5000.0, 50.0))
    blk = arc((10, 0, 0), (10, 0, -10), (0, 0), ccw=True, feed_mm_s=100.0)
    element = Arc.from_points((10.0, 0.0, 0.0), (10.0, 0.0, -10.0), (0.0, 0.0), (0, 1), True)
    limits = element_limits(element, 100.0, dyn)
    assert limits.speed_mm_s == pytest.approx(element.length_mm / 10.0, rel=1e-12)
    trace = run(executor((10.0, 0.0, 0.0), dynamics=dyn), [blk])
    check_axis_limits(trace, dyn)
    speeds_z = [abs(b[2] - a[2]) / DT for a, b in zip(trace.positions, trace.positions[1:])]
    assert max(speeds_z) <= 1.0 + 1e-6


def test_helix_end_off_the_circle_is_the_circle_error() -> None:
    ex = executor((10.0, 0.0, 0.0))
    with pytest.raises(PathError) as err:
        ex.push(arc((10, 0, 0), (0, 10.5, -5), (0, 0), ccw=True))
    assert err.value.id == PathErrorId.ARC_END_RADIUS


def test_helix_with_radius_compensation_is_refused() -> None:
    ex = executor((10.0, 0.0, 0.0))
    with pytest.raises(PathError) as err:
        ex.push(arc((10, 0, 0), (-10, 0, -5), (0, 0), ccw=True, comp=Compensation.LEFT, r=1.0))
    assert err.value.id == PathErrorId.COMP_HELIX
    ex.push(line((10, 0, 0), (10, 0, -5)))  # nothing was taken: the next block still fits
