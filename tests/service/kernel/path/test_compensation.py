"""Tool radius compensation: offset contours, corners, approach/departure, errors."""

from __future__ import annotations

import math

import pytest

from cnc_objects.service.kernel.nc.blocks import Compensation
from cnc_objects.service.kernel.path import AxisDynamics, PathError, PathErrorId, PathExecutor
from cnc_objects.service.kernel.path.geometry import Arc, Line
from cnc_objects.service.kernel.path.segments import PathPreparation, Segment

from .programs import DT, DYN, arc, distance_to_contour, line, run, technology

G41, G42 = Compensation.LEFT, Compensation.RIGHT
R = 5.0
START = (-20.0, -20.0, 0.0)


def square_program(comp, ccw=True, r=R, size=50.0):
    """Lead-in (G40), square with compensation, lead-out (G40)."""
    s = size
    corners = [(0, 0, 0), (s, 0, 0), (s, s, 0), (0, s, 0), (0, 0, 0)]
    if not ccw:
        corners = corners[::-1]
    blocks = [line(START, (0, 0, 0))]
    blocks += [line(a, b, comp=comp, r=r) for a, b in zip(corners, corners[1:])]
    blocks.append(line((0, 0, 0), START))
    contour = [("line", a[:2], b[:2]) for a, b in zip(corners, corners[1:])]
    return blocks, contour


def prepare(blocks):
    prep = PathPreparation(DYN, blocks[0].motion.start_mm)
    items = [i for b in blocks for i in prep.prepare(b)] + prep.flush()
    return [i for i in items if isinstance(i, Segment)]


def compensated_elements(blocks):
    """Elements of the compensated part: without lead-in, approach, departure."""
    segs = prepare(blocks)
    return [s.element for s in segs if s.block is not blocks[0] and s.block is not blocks[-1]][1:]


def samples(element, n=25):
    return [element.point_at(element.length_mm * k / n) for k in range(n + 1)]


def assert_offset(elements, contour, r=R):
    """Every sampled point is ``r`` from the contour.

    The contours are closed but compensation is switched on and off at the closing
    point (perpendicular approach/departure), so the first element is measured against
    the contour without its last element and the last one without its first element.
    """
    for k, e in enumerate(elements):
        near = contour
        if k == 0:
            near = contour[:-1]
        elif k == len(elements) - 1:
            near = contour[1:]
        for p in samples(e):
            assert distance_to_contour(p[:2], near) == pytest.approx(r, abs=1e-9)


@pytest.mark.parametrize("comp, ccw, outside", [
    (G41, True, False),   # tool left of a ccw square: inside, corners by intersection
    (G42, True, True),    # tool right of a ccw square: outside, arcs at corners
    (G41, False, True),   # tool left of a cw square: outside contour, arcs at corners
    (G42, False, False),
])
def test_square_gives_the_offset_square(comp, ccw, outside) -> None:
    blocks, contour = square_program(comp, ccw)
    elements = compensated_elements(blocks)
    arcs = [e for e in elements if isinstance(e, Arc)]
    lines = [e for e in elements if isinstance(e, Line)]
    if outside:
        assert len(arcs) == 3 and len(lines) == 4  # the closing corner is left by G40
        for a in arcs:
            assert a.radius_mm == pytest.approx(R)
            assert abs(a.sweep_rad) == pytest.approx(math.pi / 2)
            assert (a.center[0], a.center[1]) in [(50, 0), (50, 50), (0, 50), (0, 0)]
        assert all(ln.length_mm == pytest.approx(50.0) for ln in lines)
    else:
        assert not arcs and len(lines) == 4
        corners = {tuple(round(c, 9) for c in ln.end_mm[:2]) for ln in lines[:3]}
        assert corners <= {(5.0, 5.0), (45.0, 5.0), (45.0, 45.0), (5.0, 45.0)}
        assert [ln.length_mm for ln in lines] == pytest.approx([45.0, 40.0, 40.0, 45.0])
    assert_offset(elements, contour)


def test_approach_and_departure_are_perpendicular() -> None:
    blocks, _ = square_program(G42)
    segs = prepare(blocks)
    approach = segs[1].element
    assert approach.start_mm == (0.0, 0.0, 0.0) and approach.end_mm == pytest.approx((0, -R, 0))
    assert segs[1].block is blocks[1]  # the approach belongs to the first G42 block
    departure = segs[-1].element
    assert departure.start_mm == pytest.approx((-R, 0.0, 0.0))  # perpendicular at the end
    assert departure.end_mm == START


def test_executed_path_keeps_the_tool_radius_from_the_contour() -> None:
    blocks, contour = square_program(G42)
    segs = prepare(blocks)
    lead_in = segs[0].length_mm + segs[1].length_mm
    lead_out = segs[-1].length_mm
    total = sum(s.length_mm for s in segs)
    trace = run(PathExecutor(DYN, START, cycle_s=DT), blocks)
    checked = 0
    for res in trace.results:
        if lead_in + 1e-6 < res.distance_mm < total - lead_out - 1e-6:
            assert distance_to_contour(res.position_mm[:2], contour) == pytest.approx(R, abs=1e-9)
            checked += 1
    assert checked > 1000
    assert trace.finished == blocks
    assert trace.results[-1].distance_mm == pytest.approx(total)


def rounded_contour(comp, r=R):
    """A slot: two lines joined by tangent half circles, plus a sharp arc corner."""
    blocks = [
        line(START, (0, 0, 0)),
        line((0, 0, 0), (40, 0, 0), comp=comp, r=r),
        arc((40, 0, 0), (40, 30, 0), (40, 15), ccw=True, comp=comp, r=r),  # tangent
        line((40, 30, 0), (0, 30, 0), comp=comp, r=r),
        arc((0, 30, 0), (0, 0, 0), (-5, 15), ccw=True, comp=comp, r=r),  # not tangent
        line((0, 0, 0), START),
    ]
    contour = [("line", (0, 0), (40, 0)), ("arc", (40, 0), (40, 30), (40, 15), True),
               ("line", (40, 30), (0, 30)), ("arc", (0, 30), (0, 0), (-5, 15), True)]
    return blocks, contour


@pytest.mark.parametrize("comp", [G41, G42])
def test_contour_with_arcs_gives_the_offset_contour(comp) -> None:
    blocks, contour = rounded_contour(comp)
    elements = compensated_elements(blocks)
    arcs = [e for e in elements if isinstance(e, Arc) and e.center != (0.0, 30.0)
            and e.center != (0.0, 0.0) and e.center != (40.0, 0.0) and e.center != (40.0, 30.0)]
    radii = sorted(round(a.radius_mm, 9) for a in arcs)
    big = math.hypot(5, 15)  # radius of the second arc
    if comp == G41:  # left of ccw arcs: inside, radius - r
        assert radii == pytest.approx(sorted([15 - R, big - R]))
    else:
        assert radii == pytest.approx(sorted([15 + R, big + R]))
    for a in arcs:
        assert a.center in [(40.0, 15.0), (-5.0, 15.0)]
    assert_offset(elements, contour)


def test_arc_smaller_than_the_tool_on_the_inside_is_an_error() -> None:
    blocks = [line(START, (0, 0, 0)), line((0, 0, 0), (10, 0, 0), comp=G41, r=R),
              arc((10, 0, 0), (10, 6, 0), (10, 3), ccw=True, comp=G41, r=R)]
    prep = PathPreparation(DYN, START)
    prep.prepare(blocks[0])
    prep.prepare(blocks[1])
    with pytest.raises(PathError) as err:
        prep.prepare(blocks[2])
    assert err.value.id == PathErrorId.COMP_ARC_RADIUS and err.value.block is blocks[2]
    # the same arc on the outside is fine
    outside = arc((10, 0, 0), (10, 6, 0), (10, 3), ccw=True, comp=G42, r=R)
    prep = PathPreparation(DYN, (10, 0, 0))
    assert prep.prepare(outside)


def test_element_too_short_at_an_inside_corner_is_an_error() -> None:
    # ccw contour with a 2 mm step; G41 keeps the tool inside: r = 5 cannot follow it
    pts = [(0, 0, 0), (50, 0, 0), (50, 2, 0), (60, 2, 0)]
    blocks = [line(START, pts[0])] + [line(a, b, comp=G41, r=R) for a, b in zip(pts, pts[1:])]
    prep = PathPreparation(DYN, START)
    with pytest.raises(PathError) as err:
        for b in blocks:
            prep.prepare(b)
    assert err.value.id == PathErrorId.COMP_CONTOUR_VIOLATION


def test_deselection_in_an_arc_is_an_error() -> None:
    blocks = [line(START, (0, 0, 0)), line((0, 0, 0), (10, 0, 0), comp=G41, r=R),
              arc((10, 0, 0), (20, 0, 0), (15, 0), ccw=True)]
    prep = PathPreparation(DYN, START)
    prep.prepare(blocks[0])
    prep.prepare(blocks[1])
    with pytest.raises(PathError) as err:
        prep.prepare(blocks[2])
    assert err.value.id == PathErrorId.COMP_DESELECT_ON_ARC


def test_infeed_without_plane_motion_is_an_error() -> None:
    prep = PathPreparation(DYN, (0, 0, 0))
    with pytest.raises(PathError) as err:
        prep.prepare(line((0, 0, 0), (0, 0, -5), comp=G41, r=R))
    assert err.value.id == PathErrorId.COMP_NO_PLANE_MOTION


def test_streaming_holds_one_block_and_close_releases_it() -> None:
    blocks, _ = square_program(G41)
    tech = technology(8)
    ex = PathExecutor(DYN, START, cycle_s=DT, buffer_blocks=10)
    ex.push(blocks[0])
    ex.push(blocks[1])  # held back: its end depends on the next block
    ex.push(tech)  # held with it
    assert ex.free_slots() == 7
    finished = []
    for _ in range(2000):
        finished += ex.step(1.0).finished
    # the lead-in and the approach ran, then the path waits for look-ahead
    assert finished == [blocks[0]] and ex.position_mm == pytest.approx((0.0, R, 0.0))
    assert not ex.idle
    ex.close()
    for _ in range(2000):
        finished += ex.step(1.0).finished
    assert finished == [blocks[0], blocks[1], tech] and ex.idle
    assert ex.position_mm == pytest.approx((50.0, R, 0.0))  # ends perpendicular


def test_software_limit_of_a_held_block_names_that_block() -> None:
    ex = PathExecutor(DYN, START, cycle_s=DT, sw_limits_mm=[(-30, 52), (-30, 100), (-10, 10)])
    blocks, _ = square_program(G42)  # outside offset reaches x = 55
    ex.push(blocks[0])
    ex.push(blocks[1])
    with pytest.raises(PathError) as err:
        ex.push(blocks[2])
    assert err.value.id == PathErrorId.SW_LIMIT_MAX
    assert err.value.block is blocks[1] or err.value.block is blocks[2]
    assert max(p[0] for p in run(ex, []).positions) <= 52.0


def test_compensation_with_different_axis_order() -> None:
    """G18-like plane (Z, X): offsets happen in the plane, Y stays."""
    dyn = (AxisDynamics(500, 5000, 50),) * 3
    plane = (2, 0)
    blocks = [line((0, 7, 0), (0, 7, 10), comp=G41, r=2.0, plane=plane),
              line((0, 7, 10), (10, 7, 10), comp=G41, r=2.0, plane=plane)]
    prep = PathPreparation(dyn, (0, 7, 0))
    items = [i for b in blocks for i in prep.prepare(b)] + prep.flush()
    segs = [i for i in items if isinstance(i, Segment)]
    # motion +Z (p axis); left in the (Z, X) plane is +X... rotated: n = (-t_q, t_p) = (0, 1)
    # so the first line is offset to X = +2, then meets the second (along +X, offset to Z = 8)
    assert segs[1].element.start_mm == pytest.approx((2.0, 7.0, 0.0))
    assert segs[1].element.end_mm == pytest.approx((2.0, 7.0, 8.0))
    assert all(s.element.start_mm[1] == 7.0 and s.element.end_mm[1] == 7.0 for s in segs)


@pytest.mark.parametrize("comp, radius", [(G41, 20.0 - 3.0), (G42, 20.0 + 3.0)])
def test_full_circle_is_offset_to_a_full_circle(comp, radius) -> None:
    blocks = [line((0, -30, 0), (20, 0, 0)),
              arc((20, 0, 0), (20, 0, 0), (0, 0), ccw=True, comp=comp, r=3.0),
              line((20, 0, 0), (0, -30, 0))]
    circle = compensated_elements(blocks)
    assert len(circle) == 1 and isinstance(circle[0], Arc)
    assert circle[0].radius_mm == pytest.approx(radius)
    assert circle[0].sweep_rad == pytest.approx(2 * math.pi)
    trace = run(PathExecutor(DYN, (0, -30, 0), cycle_s=DT), blocks)
    length = circle[0].length_mm  # the block also holds the approach line before it
    on_circle = [r.position_mm for r in trace.results
                 if r.current is blocks[1] and 0.0 < r.remaining_in_block_mm < length - 1e-9]
    assert len(on_circle) > 500
    for p in on_circle:
        assert math.hypot(p[0], p[1]) == pytest.approx(radius, abs=1e-9)
