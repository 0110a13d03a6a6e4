"""Path elements: straight lines and circular arcs in absolute mm over all channel axes.

An element is parametrised by its arc length ``s_mm`` in [0, length_mm]:
``point_at(s_mm)`` returns the position of every channel axis. Arcs are evaluated from
the angle (centre + radius * (cos, sin)), never from chords, so every sample lies on
the circle. Axes outside an arc's plane move linearly with the angle from their start to
their end value: an arc whose end differs there is a helix (issue 39), and its length
is the length along the helix, sqrt(plane arc length^2 + rise^2), as ISG's feed refers
to the path of all main axes (#FGROUP default).

Angles are measured in the plane (p, q) from the p axis towards the q axis; a positive
sweep is counter-clockwise seen from the plane's positive normal (G3), negative is
clockwise (G2). A full circle has a sweep of +-2*pi.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from .errors import PathError, PathErrorId

TWO_PI = 2.0 * math.pi
ARC_RADIUS_TOLERANCE_MM = 0.01  # allowed difference of start and end radius of a programmed arc
FULL_CIRCLE_TOLERANCE_MM = 1e-9  # start and end closer than this in the plane: full circle

Point = tuple[float, ...]


def with_plane(base_mm: Sequence[float], plane: tuple[int, int], p: float, q: float) -> Point:
    """``base_mm`` with the plane coordinates replaced by (p, q)."""
    out = list(base_mm)
    out[plane[0]] = p
    out[plane[1]] = q
    return tuple(out)


FEED_AXES = 3
"""The default feed group: the channel's main axes (indices 0, 1, 2)."""


class Line:
    """A straight line from ``start_mm`` to ``end_mm`` (any number of axes).

    Its length, along which the programmed feed acts, is measured over the feed group:
    ISG's default feed group is the channel's three main axes; every other axis (a
    rotary axis, a fourth linear axis) is a tracking axis that reaches its end together
    with them (infosys.beckhoff.com tf5200_programming_manual/207471243.html, #FGROUP;
    P-CHAN-00011). A line that moves tracking axes only is measured over them (F in
    degrees/min for a rotary axis, G94). ``direction`` is the axes' motion per mm of
    path: a unit vector when only main axes move, longer when tracking axes move too.
    """

    __slots__ = ("start_mm", "end_mm", "length_mm", "direction", "_pairs")

    def __init__(self, start_mm: Sequence[float], end_mm: Sequence[float]) -> None:
        start, end = tuple(start_mm), tuple(end_mm)
        self.start_mm: Point = start
        self.end_mm: Point = end
        length = math.dist(start, end)
        if len(start) > FEED_AXES and length > 0.0:
            main = math.dist(start[:FEED_AXES], end[:FEED_AXES])
            if main > 0.0:
                length = main
        self.length_mm = length
        inv = 1.0 / length if length > 0.0 else 0.0
        self.direction: Point = tuple([(e - s) * inv for s, e in zip(start, end)])
        self._pairs = tuple(zip(start, self.direction))

    @property
    def tangent_start(self) -> Point:
        """Unit tangent at the start (the direction)."""
        return self.direction

    @property
    def tangent_end(self) -> Point:
        """Unit tangent at the end (the direction)."""
        return self.direction

    def point_at(self, s_mm: float) -> Point:
        """Position after ``s_mm`` along the line; the end points are returned exactly."""
        if s_mm >= self.length_mm:
            return self.end_mm
        if s_mm <= 0.0:
            return self.start_mm
        return tuple([p + u * s_mm for p, u in self._pairs])

    def extent_mm(self) -> tuple[Point, Point]:
        """Per-axis minimum and maximum over the element."""
        return (tuple(map(min, self.start_mm, self.end_mm)),
                tuple(map(max, self.start_mm, self.end_mm)))

    def __repr__(self) -> str:
        return f"Line({self.start_mm} -> {self.end_mm})"


class Arc:
    """A circular arc in the plane of axes ``plane`` = (p, q).

    Built from centre, radius, start angle and signed sweep; ``base_mm`` supplies the
    coordinates of the axes outside the plane. ``end_radius_mm`` (default: the radius)
    lets a programmed arc whose end lies a little off the circle (within
    ``ARC_RADIUS_TOLERANCE_MM``) end exactly at its programmed end: the radius then
    changes linearly with the angle. For a consistent arc the two radii are equal and
    every point is exactly on the circle.

    ``end_base_mm`` (default: ``base_mm``) gives the end values of the axes outside the
    plane; where they differ the arc is a helix: those axes move linearly with the
    angle (``rise`` holds (axis, start, change) per moving axis, empty for a plane arc).
    """

    __slots__ = ("plane", "center", "radius_mm", "end_radius_mm", "start_angle_rad",
                 "sweep_rad", "length_mm", "plane_length_mm", "rise", "start_mm", "end_mm",
                 "_base", "_k", "_dr")

    def __init__(self, plane: tuple[int, int], center_pq: Sequence[float], radius_mm: float,
                 start_angle_rad: float, sweep_rad: float, base_mm: Sequence[float],
                 end_radius_mm: float | None = None,
                 end_base_mm: Sequence[float] | None = None) -> None:
        self.plane = (int(plane[0]), int(plane[1]))
        self.center = (float(center_pq[0]), float(center_pq[1]))
        self.radius_mm = float(radius_mm)
        self.end_radius_mm = self.radius_mm if end_radius_mm is None else float(end_radius_mm)
        self.start_angle_rad = float(start_angle_rad)
        self.sweep_rad = float(sweep_rad)
        self.plane_length_mm = plane_length = (0.5 * (self.radius_mm + self.end_radius_mm)
                                               * abs(self.sweep_rad))
        self._base = list(base_mm)
        rise: tuple[tuple[int, float, float], ...] = ()
        if end_base_mm is not None:
            p, q = self.plane
            rise = tuple((i, float(b), float(e) - float(b))
                         for i, (b, e) in enumerate(zip(self._base, end_base_mm))
                         if i != p and i != q and e != b)
        self.rise = rise
        self.length_mm = (math.sqrt(plane_length * plane_length
                                    + sum(d * d for _, _, d in rise))
                          if rise else plane_length)
        self._k = self.sweep_rad / self.length_mm if self.length_mm > 0.0 else 0.0  # rad per mm
        self._dr = ((self.end_radius_mm - self.radius_mm) / self.length_mm
                    if self.length_mm > 0.0 else 0.0)  # radius change per mm
        self.start_mm = self._point(self.start_angle_rad, self.radius_mm)
        self.end_mm = self._point(self.start_angle_rad + self.sweep_rad, self.end_radius_mm)

    @classmethod
    def from_points(cls, start_mm: Sequence[float], end_mm: Sequence[float],
                    center_pq: Sequence[float], plane: tuple[int, int], ccw: bool) -> Arc:
        """The arc of a G2/G3 block; a full circle when start and end coincide in the plane.

        Raises PathError ARC_CENTER for a zero radius and ARC_END_RADIUS when the end is
        farther than ``ARC_RADIUS_TOLERANCE_MM`` off the circle through the start.
        """
        p, q = plane
        cp, cq = float(center_pq[0]), float(center_pq[1])
        sp, sq = start_mm[p] - cp, start_mm[q] - cq
        ep, eq = end_mm[p] - cp, end_mm[q] - cq
        r0, r1 = math.hypot(sp, sq), math.hypot(ep, eq)
        if r0 <= 1e-9 or r1 <= 1e-9:
            raise PathError(PathErrorId.ARC_CENTER,
                            f"arc centre ({cp:.4f}, {cq:.4f}) coincides with its start or end")
        if abs(r1 - r0) > ARC_RADIUS_TOLERANCE_MM:
            raise PathError(PathErrorId.ARC_END_RADIUS,
                            f"arc end radius {r1:.4f} mm differs from start radius {r0:.4f} mm "
                            f"by more than {ARC_RADIUS_TOLERANCE_MM} mm")
        a0, a1 = math.atan2(sq, sp), math.atan2(eq, ep)
        full = (math.hypot(end_mm[p] - start_mm[p], end_mm[q] - start_mm[q])
                <= FULL_CIRCLE_TOLERANCE_MM)
        if full:
            sweep = TWO_PI
        else:
            sweep = (a1 - a0) % TWO_PI if ccw else (a0 - a1) % TWO_PI
        helix = any(e != s for i, (s, e) in enumerate(zip(start_mm, end_mm))
                    if i != p and i != q)
        arc = (Helix if helix else cls)(plane, (cp, cq), r0, a0, sweep if ccw else -sweep,
                                        start_mm, r0 if full else r1,
                                        end_mm if helix else None)
        arc.start_mm = tuple(float(x) for x in start_mm)
        arc.end_mm = tuple(float(x) for x in end_mm)  # on the circle up to rounding
        return arc

    def _point(self, angle: float, radius: float) -> Point:
        out = self._base[:]
        out[self.plane[0]] = self.center[0] + radius * math.cos(angle)
        out[self.plane[1]] = self.center[1] + radius * math.sin(angle)
        return tuple(out)

    @property
    def ccw(self) -> bool:
        """True for a counter-clockwise arc (G3)."""
        return self.sweep_rad > 0.0

    @property
    def end_angle_rad(self) -> float:
        """Angle of the end point."""
        return self.start_angle_rad + self.sweep_rad

    def point_at(self, s_mm: float) -> Point:
        """Position after ``s_mm`` along the arc, computed from the angle."""
        if s_mm >= self.length_mm:
            return self.end_mm
        if s_mm <= 0.0:
            return self.start_mm
        angle = self.start_angle_rad + self._k * s_mm
        radius = self.radius_mm + self._dr * s_mm
        out = self._base[:]
        out[self.plane[0]] = self.center[0] + radius * math.cos(angle)
        out[self.plane[1]] = self.center[1] + radius * math.sin(angle)
        return tuple(out)

    def tangent_at_angle(self, angle: float) -> Point:
        """Unit tangent (direction of motion) at ``angle``, over all axes."""
        out = [0.0] * len(self._base)
        sign = 1.0 if self.sweep_rad > 0.0 else -1.0
        out[self.plane[0]] = -sign * math.sin(angle)
        out[self.plane[1]] = sign * math.cos(angle)
        return tuple(out)

    @property
    def tangent_start(self) -> Point:
        """Unit tangent at the start."""
        return self.tangent_at_angle(self.start_angle_rad)

    @property
    def tangent_end(self) -> Point:
        """Unit tangent at the end."""
        return self.tangent_at_angle(self.end_angle_rad)

    def angle_offset(self, angle: float, *, at_end: bool = False) -> float:
        """How far (rad, >= 0, in the direction of motion) ``angle`` lies after the start.

        Result in [0, 2*pi); with ``at_end`` in (0, 2*pi] so that the end of a full
        circle is 2*pi rather than 0.
        """
        sign = 1.0 if self.sweep_rad > 0.0 else -1.0
        off = ((angle - self.start_angle_rad) * sign) % TWO_PI
        if at_end and off <= 1e-12:
            off += TWO_PI
        return off

    def extent_mm(self) -> tuple[Point, Point]:
        """Per-axis minimum and maximum over the arc, including its extreme points."""
        points = [self.start_mm, self.end_mm]
        span = abs(self.sweep_rad)
        for k in range(4):
            angle = k * 0.5 * math.pi
            off = self.angle_offset(angle)
            if off <= span:
                frac = off / span if span > 0.0 else 0.0
                radius = self.radius_mm + (self.end_radius_mm - self.radius_mm) * frac
                if self.rise:  # the unwrapped angle: a helix places its rising axes by it
                    angle = self.start_angle_rad + (off if self.sweep_rad > 0.0 else -off)
                points.append(self._point(angle, radius))
        return (tuple(map(min, *points)), tuple(map(max, *points)))

    def __repr__(self) -> str:
        return (f"Arc(plane={self.plane}, center={self.center}, r={self.radius_mm}, "
                f"start={self.start_angle_rad:.6f}, sweep={self.sweep_rad:.6f})")


class Helix(Arc):
    """An arc whose axes outside the plane move linearly with the angle (issue 39).

    A subclass, so that plane arcs keep their evaluation without a test per cycle: the
    plane part is the arc's, the rising axes (``rise``) stand at start + change *
    s / length; the tangent's plane part is scaled by plane length / length, the rising
    axes add their constant share change / length.
    """

    __slots__ = ()

    def _point(self, angle: float, radius: float) -> Point:
        out = list(Arc._point(self, angle, radius))
        frac = (angle - self.start_angle_rad) / self.sweep_rad if self.sweep_rad else 0.0
        for i, b, d in self.rise:
            out[i] = b + d * frac
        return tuple(out)

    def point_at(self, s_mm: float) -> Point:
        """Position after ``s_mm`` along the helix."""
        if s_mm >= self.length_mm:
            return self.end_mm
        if s_mm <= 0.0:
            return self.start_mm
        out = list(Arc.point_at(self, s_mm))
        frac = s_mm / self.length_mm
        for i, b, d in self.rise:
            out[i] = b + d * frac
        return tuple(out)

    def tangent_at_angle(self, angle: float) -> Point:
        """Unit tangent at ``angle``: the arc's, leaning by the rise."""
        out = [0.0] * len(self._base)
        scale = (1.0 if self.sweep_rad > 0.0 else -1.0) * self.plane_length_mm / self.length_mm
        out[self.plane[0]] = -scale * math.sin(angle)
        out[self.plane[1]] = scale * math.cos(angle)
        for i, _b, d in self.rise:
            out[i] = d / self.length_mm
        return tuple(out)

    def __repr__(self) -> str:
        return f"Helix({Arc.__repr__(self)[4:-1]}, rise={self.rise})"


Element = Line | Arc
