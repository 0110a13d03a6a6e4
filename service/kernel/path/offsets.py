"""Offset curves of lines and arcs in a plane: offsetting, intersecting, trimming.

The geometry under tool radius compensation (``compensation.py``). Everything works
on the in-plane coordinates (p, q) of the element's plane; the coordinates of the
other axes are carried along unchanged (a trimmed line keeps the values of the other
axes at its programmed ends, so consecutive elements stay connected).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from .errors import PathError, PathErrorId
from .geometry import Arc, Element, Line, with_plane

MIN_LENGTH_MM = 1e-9  # elements shorter than this are dropped (their block end is kept)
ON_ELEMENT_TOLERANCE_MM = 1e-7  # an intersection may lie this far outside an element


def plane_point(point: Sequence[float], plane: tuple[int, int]) -> tuple[float, float]:
    """The in-plane coordinates (p, q) of a point."""
    return point[plane[0]], point[plane[1]]


def plane_tangent(tangent: Sequence[float], plane: tuple[int, int]) -> tuple[float, float]:
    """The in-plane direction of a tangent, normalised; PathError without motion in the
    plane."""
    tp, tq = tangent[plane[0]], tangent[plane[1]]
    norm = math.hypot(tp, tq)
    if norm <= 1e-12:
        raise PathError(PathErrorId.COMP_NO_PLANE_MOTION,
                        "tool radius compensation needs motion in the plane")
    return tp / norm, tq / norm


def offset_element(element: Element, plane: tuple[int, int], side: float,
                   radius_mm: float) -> Element:
    """``element`` moved by ``radius_mm`` to its left (side +1) or right (side -1)."""
    if isinstance(element, Line):
        tp, tq = plane_tangent(element.direction, plane)
        np_, nq = -tq * side * radius_mm, tp * side * radius_mm
        s, e = element.start_mm, element.end_mm
        return Line(with_plane(s, plane, s[plane[0]] + np_, s[plane[1]] + nq),
                    with_plane(e, plane, e[plane[0]] + np_, e[plane[1]] + nq))
    if element.plane != plane:
        raise PathError(PathErrorId.COMP_PLANE_CHANGE,
                        "arc plane differs from the compensation plane")
    toward_center = 1.0 if element.sweep_rad > 0.0 else -1.0  # left of a ccw arc is inside
    delta = -side * toward_center * radius_mm
    r0, r1 = element.radius_mm + delta, element.end_radius_mm + delta
    if min(r0, r1) <= 1e-9:
        raise PathError(PathErrorId.COMP_ARC_RADIUS,
                        f"arc radius {element.radius_mm:.4f} mm is not larger than the tool "
                        f"radius {radius_mm:.4f} mm on the inside of the arc")
    return Arc(plane, element.center, r0, element.start_angle_rad, element.sweep_rad,
               element.start_mm, r1)


def line_circle(
    p0: tuple[float, float], d: tuple[float, float], center: tuple[float, float],
    radius: float,
) -> list[tuple[float, float]]:
    """Points where the line through ``p0`` with unit direction ``d`` meets the circle."""
    fx, fy = p0[0] - center[0], p0[1] - center[1]
    b = fx * d[0] + fy * d[1]
    c = fx * fx + fy * fy - radius * radius
    disc = b * b - c
    if disc < 0.0:
        if disc < -1e-9 * max(1.0, radius * radius):
            return []
        disc = 0.0
    root = math.sqrt(disc)
    return [(p0[0] + t * d[0], p0[1] + t * d[1]) for t in (-b - root, -b + root)]


def circle_circle(
    c1: tuple[float, float], r1: float, c2: tuple[float, float], r2: float,
) -> list[tuple[float, float]]:
    """Points where two circles meet (none for concentric circles)."""
    dx, dy = c2[0] - c1[0], c2[1] - c1[1]
    dist = math.hypot(dx, dy)
    if dist <= 1e-12:
        return []
    a = (r1 * r1 - r2 * r2 + dist * dist) / (2.0 * dist)
    h2 = r1 * r1 - a * a
    if h2 < 0.0:
        if h2 < -1e-9 * max(1.0, r1 * r1):
            return []
        h2 = 0.0
    h = math.sqrt(h2)
    mx, my = c1[0] + a * dx / dist, c1[1] + a * dy / dist
    return [(mx + h * dy / dist, my - h * dx / dist), (mx - h * dy / dist, my + h * dx / dist)]


def line_and_arc(first: Element, second: Element) -> tuple[Line, Arc]:
    """The two elements as (line, arc); ValueError unless one is a line, one an arc."""
    if isinstance(first, Line) and isinstance(second, Arc):
        return first, second
    if isinstance(first, Arc) and isinstance(second, Line):
        return second, first
    raise ValueError(f"a line and an arc expected, got {first!r} and {second!r}")


def intersect(first: Element, second: Element, plane: tuple[int, int],
              near: tuple[float, float]) -> tuple[float, float] | None:
    """Intersection of the two elements' carrier lines/circles in the plane nearest to
    ``near``."""
    if isinstance(first, Line) and isinstance(second, Line):
        p1, p2 = plane_point(first.start_mm, plane), plane_point(second.start_mm, plane)
        d1, d2 = plane_tangent(first.direction, plane), plane_tangent(second.direction, plane)
        cross = d1[0] * d2[1] - d1[1] * d2[0]
        if abs(cross) <= 1e-15:
            return None
        t = ((p2[0] - p1[0]) * d2[1] - (p2[1] - p1[1]) * d2[0]) / cross
        return p1[0] + t * d1[0], p1[1] + t * d1[1]
    if isinstance(first, Arc) and isinstance(second, Arc):
        candidates = circle_circle(first.center, first.radius_mm, second.center,
                                   second.radius_mm)
    else:
        line, arc = line_and_arc(first, second)
        candidates = line_circle(plane_point(line.start_mm, plane),
                                 plane_tangent(line.direction, plane), arc.center,
                                 arc.radius_mm)
    if not candidates:
        return None
    return min(candidates, key=lambda x: math.hypot(x[0] - near[0], x[1] - near[1]))


def _violation(block_hint: str) -> PathError:
    return PathError(PathErrorId.COMP_CONTOUR_VIOLATION,
                     f"element too short for the tool radius at an inside corner ({block_hint})")


def trim_end(element: Element, point: tuple[float, float], plane: tuple[int, int]) -> Element:
    """``element`` ending at the in-plane ``point`` (which must lie on it)."""
    if isinstance(element, Line):
        tp, tq = plane_tangent(element.direction, plane)
        s = element.start_mm
        along = (point[0] - s[plane[0]]) * tp + (point[1] - s[plane[1]]) * tq
        full = ((element.end_mm[plane[0]] - s[plane[0]]) * tp
                + (element.end_mm[plane[1]] - s[plane[1]]) * tq)
        if along <= MIN_LENGTH_MM or along > full + ON_ELEMENT_TOLERANCE_MM:
            raise _violation("end of the previous element")
        return Line(s, with_plane(element.end_mm, plane, *point))
    angle = math.atan2(point[1] - element.center[1], point[0] - element.center[0])
    off = element.angle_offset(angle, at_end=True)
    span = abs(element.sweep_rad)
    if (off * element.radius_mm <= MIN_LENGTH_MM
            or (off - span) * element.radius_mm > ON_ELEMENT_TOLERANCE_MM):
        raise _violation("end of the previous arc")
    off = min(off, span)
    frac = off / span
    r1 = element.radius_mm + (element.end_radius_mm - element.radius_mm) * frac
    sign = 1.0 if element.sweep_rad > 0.0 else -1.0
    return Arc(plane, element.center, element.radius_mm, element.start_angle_rad, sign * off,
               element.start_mm, r1)


def trim_start(element: Element, point: tuple[float, float], plane: tuple[int, int]) -> Element:
    """``element`` starting at the in-plane ``point`` (which must lie on it)."""
    if isinstance(element, Line):
        tp, tq = plane_tangent(element.direction, plane)
        e = element.end_mm
        left = (e[plane[0]] - point[0]) * tp + (e[plane[1]] - point[1]) * tq
        full = ((e[plane[0]] - element.start_mm[plane[0]]) * tp
                + (e[plane[1]] - element.start_mm[plane[1]]) * tq)
        if left <= MIN_LENGTH_MM or left > full + ON_ELEMENT_TOLERANCE_MM:
            raise _violation("start of the next element")
        return Line(with_plane(element.start_mm, plane, *point), e)
    angle = math.atan2(point[1] - element.center[1], point[0] - element.center[0])
    span = abs(element.sweep_rad)
    off = element.angle_offset(angle)
    if off > math.pi and (2.0 * math.pi - off) * element.radius_mm <= ON_ELEMENT_TOLERANCE_MM:
        off = 0.0  # a hair before the start: rounding
    if (span - off) * element.radius_mm <= MIN_LENGTH_MM:
        raise _violation("start of the next arc")
    sign = 1.0 if element.sweep_rad > 0.0 else -1.0
    frac = off / span
    r0 = element.radius_mm + (element.end_radius_mm - element.radius_mm) * frac
    base = with_plane(element.start_mm, plane, *point)
    return Arc(plane, element.center, r0, element.start_angle_rad + sign * off,
               sign * (span - off), base, element.end_radius_mm)
