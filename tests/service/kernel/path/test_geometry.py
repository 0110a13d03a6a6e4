"""Lines and arcs: lengths, points exactly on the circle, tangents, extreme points."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from cnc_objects.service.kernel.path.errors import PathError, PathErrorId
from cnc_objects.service.kernel.path.geometry import Arc, Line

PLANES = [(0, 1), (2, 0), (1, 2)]  # G17, G18, G19


def test_line_length_points_and_tangent() -> None:
    ln = Line((1.0, 2.0, 3.0), (4.0, 6.0, 3.0))
    assert ln.length_mm == 5.0
    assert ln.point_at(0.0) == (1.0, 2.0, 3.0)
    assert ln.point_at(5.0) == (4.0, 6.0, 3.0)  # end point exactly
    assert ln.point_at(2.5) == pytest.approx((2.5, 4.0, 3.0), abs=1e-12)
    assert ln.tangent_start == ln.tangent_end == pytest.approx((0.6, 0.8, 0.0))


@settings(max_examples=60, deadline=None)
@given(
    cx=st.floats(-500, 500), cy=st.floats(-500, 500), z=st.floats(-100, 100),
    radius=st.floats(0.01, 1000), a0=st.floats(-math.pi, math.pi),
    sweep=st.floats(0.001, 2 * math.pi - 0.001), ccw=st.booleans(), plane=st.sampled_from(PLANES),
)
def test_arc_samples_lie_on_the_circle(cx, cy, z, radius, a0, sweep, ccw, plane) -> None:
    p, q = plane
    other = 3 - p - q
    a1 = a0 + (sweep if ccw else -sweep)

    def point(angle):
        pt = [0.0, 0.0, 0.0]
        pt[p], pt[q], pt[other] = cx + radius * math.cos(angle), cy + radius * math.sin(angle), z
        return tuple(pt)

    arc = Arc.from_points(point(a0), point(a1), (cx, cy), plane, ccw)
    assert arc.length_mm == pytest.approx(radius * sweep, rel=1e-9)
    for k in range(101):
        pt = arc.point_at(arc.length_mm * k / 100)
        assert abs(math.hypot(pt[p] - cx, pt[q] - cy) - radius) <= 1e-9
        assert pt[other] == z
    mid = arc.point_at(arc.length_mm / 2)
    expected = point(a0 + (sweep if ccw else -sweep) / 2)
    assert mid == pytest.approx(expected, abs=1e-9)


@pytest.mark.parametrize("ccw", [True, False])
def test_full_circle(ccw) -> None:
    start = (15.0, 5.0, 1.0)
    arc = Arc.from_points(start, start, (10.0, 5.0), (0, 1), ccw)
    assert arc.sweep_rad == pytest.approx(2 * math.pi if ccw else -2 * math.pi)
    assert arc.length_mm == pytest.approx(2 * math.pi * 5.0)
    assert arc.point_at(arc.length_mm / 2) == pytest.approx((5.0, 5.0, 1.0), abs=1e-12)
    quarter = arc.point_at(arc.length_mm / 4)
    assert quarter == pytest.approx((10.0, 10.0 if ccw else 0.0, 1.0), abs=1e-12)
    assert arc.point_at(arc.length_mm) == start


def test_arc_tangents_follow_the_direction_of_motion() -> None:
    ccw = Arc.from_points((10.0, 0.0, 0.0), (0.0, 10.0, 0.0), (0.0, 0.0), (0, 1), True)
    assert ccw.tangent_start == pytest.approx((0.0, 1.0, 0.0), abs=1e-12)
    assert ccw.tangent_end == pytest.approx((-1.0, 0.0, 0.0), abs=1e-12)
    cw = Arc.from_points((10.0, 0.0, 0.0), (0.0, -10.0, 0.0), (0.0, 0.0), (0, 1), False)
    assert cw.tangent_start == pytest.approx((0.0, -1.0, 0.0), abs=1e-12)
    assert cw.length_mm == pytest.approx(math.pi * 5.0)


def test_arc_extent_includes_extreme_points() -> None:
    # from 45 deg to 135 deg ccw passes the top of the circle
    r = 10.0
    s = (r * math.cos(math.pi / 4), r * math.sin(math.pi / 4), 0.0)
    e = (-s[0], s[1], 0.0)
    lows, highs = Arc.from_points(s, e, (0.0, 0.0), (0, 1), True).extent_mm()
    assert highs[1] == pytest.approx(10.0)
    assert lows[1] == pytest.approx(s[1])
    # the same points clockwise go round the bottom
    lows, highs = Arc.from_points(s, e, (0.0, 0.0), (0, 1), False).extent_mm()
    assert lows[1] == pytest.approx(-10.0) and lows[0] == pytest.approx(-10.0)
    assert highs[0] == pytest.approx(10.0)


def test_arc_errors() -> None:
    with pytest.raises(PathError) as err:
        Arc.from_points((0.0, 0.0, 0.0), (1.0, 1.0, 0.0), (0.0, 0.0), (0, 1), True)
    assert err.value.id == PathErrorId.ARC_CENTER
    with pytest.raises(PathError) as err:
        Arc.from_points((10.0, 0.0, 0.0), (0.0, 10.5, 0.0), (0.0, 0.0), (0, 1), True)
    assert err.value.id == PathErrorId.ARC_END_RADIUS
    assert "50011" in str(err.value)


def test_arc_end_slightly_off_the_circle_ends_exactly_at_the_programmed_end() -> None:
    end = (0.0, 10.004, 0.0)  # 4 um off, within tolerance
    arc = Arc.from_points((10.0, 0.0, 0.0), end, (0.0, 0.0), (0, 1), True)
    assert arc.point_at(arc.length_mm) == end
    near_end = arc.point_at(arc.length_mm * (1 - 1e-9))
    assert math.dist(near_end, end) < 1e-6  # no jump at the end
