"""Axis limits acting on path elements: dynamics (speed, acceleration, velocity jump) and
software limit switches.

The formulas here are the constraint part of the planning model described in
``planner.py``; they are evaluated once per element (or per junction), never per cycle.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import NamedTuple

from .errors import PathError, PathErrorId
from .geometry import Arc, Element, Line

SQRT2 = math.sqrt(2.0)
SW_LIMIT_TOLERANCE_MM = 1e-9  # rounding allowance at a software limit


@dataclass(frozen=True)
class AxisDynamics:
    """Dynamic limits of one channel axis."""

    vel_max_mm_s: float  # V_i: maximum axis velocity
    acc_max_mm_s2: float  # A_i: maximum axis acceleration
    vel_jump_mm_s: float  # dV_i: velocity jump the axis may take at a block transition

    def __post_init__(self) -> None:
        if not (self.vel_max_mm_s > 0.0 and self.acc_max_mm_s2 > 0.0 and self.vel_jump_mm_s >= 0.0):
            raise ValueError(f"invalid axis dynamics {self}")
        if not all(math.isfinite(x) for x in (self.vel_max_mm_s, self.acc_max_mm_s2,
                                              self.vel_jump_mm_s)):
            raise ValueError(f"axis dynamics must be finite: {self}")


class ElementLimits(NamedTuple):
    """Speed and acceleration limits of one element (before feed override)."""

    axis_speed_mm_s: float  # limit from the axes alone (what override may never exceed)
    speed_mm_s: float  # min(F, axis_speed_mm_s): the element's speed limit at 100 %
    acc_mm_s2: float  # path acceleration (and deceleration) of the element


def element_limits(element: Element, feed_mm_s: float,
                   dynamics: Sequence[AxisDynamics]) -> ElementLimits:
    """Limits of ``element`` at programmed feed ``feed_mm_s`` (math.inf for G0).

    Line, unit direction u: speed <= min_i V_i/|u_i|, acceleration <= min_i A_i/|u_i|
    over the axes with u_i != 0. Arc in plane (p, q), radius R: acceleration
    (tangential, and normal) <= min(A_p, A_q)/sqrt(2); speed <= min(V_p, V_q,
    sqrt(R * min(A_p, A_q)/sqrt(2))). For an arc whose radius changes a little from
    start to end (programmed end slightly off the circle) the smaller radius counts.

    Helix (issue 39): the plane takes the share c = plane length / length of the path
    speed and acceleration, so the plane limits above are divided by c (the helix's
    curvature R/(R^2+h^2), h = rise per radian, gives the same normal acceleration
    (v*c)^2/R); each rising axis i with constant share |u_i| = change_i / length adds
    speed <= V_i/|u_i| and acceleration <= A_i/|u_i|, as on a line.
    """
    if isinstance(element, Arc):
        p, q = element.plane
        acc = min(dynamics[p].acc_max_mm_s2, dynamics[q].acc_max_mm_s2) / SQRT2
        radius = min(element.radius_mm, element.end_radius_mm)
        axis_speed = min(dynamics[p].vel_max_mm_s, dynamics[q].vel_max_mm_s,
                         math.sqrt(radius * acc))
        if element.rise and element.plane_length_mm > 0.0:
            c = element.plane_length_mm / element.length_mm
            axis_speed /= c
            acc /= c
            for i, _b, d in element.rise:
                au = abs(d) / element.length_mm
                axis_speed = min(axis_speed, dynamics[i].vel_max_mm_s / au)
                acc = min(acc, dynamics[i].acc_max_mm_s2 / au)
    else:
        axis_speed = acc = math.inf
        for u, dyn in zip(element.direction, dynamics):
            if u != 0.0:
                au = abs(u)
                speed = dyn.vel_max_mm_s / au
                if speed < axis_speed:
                    axis_speed = speed
                speed = dyn.acc_max_mm_s2 / au
                if speed < acc:
                    acc = speed
    return ElementLimits(axis_speed, feed_mm_s if feed_mm_s < axis_speed else axis_speed, acc)


def corner_limit_mm_s(tangent_in: Sequence[float], tangent_out: Sequence[float],
                      vel_jump_mm_s: Sequence[float]) -> float:
    """Junction speed allowed by the axes' velocity jumps: min_i dV_i / |u_out,i - u_in,i|.

    Axes whose tangent component does not change do not limit (math.inf if none does).
    """
    limit = math.inf
    for t_in, t_out, jump in zip(tangent_in, tangent_out, vel_jump_mm_s):
        change = abs(t_out - t_in)
        if change > 0.0:
            speed = jump / change
            if speed < limit:
                limit = speed
    return limit


def check_software_limits(element: Element,
                          sw_limits_mm: Sequence[tuple[float, float]] | None) -> None:
    """Raise PathError SW_LIMIT_MIN/MAX if ``element`` (with an arc's extreme points)
    leaves the range [min, max] of an axis."""
    if sw_limits_mm is None:
        return
    if isinstance(element, Line):
        # a line lies between its end points: both within the limits, so is the line
        # (the common case, without building the extent; issue 37, short blocks)
        tol = SW_LIMIT_TOLERANCE_MM
        for (lo, hi), s, e in zip(sw_limits_mm, element.start_mm, element.end_mm):
            if not (lo - tol <= s <= hi + tol and lo - tol <= e <= hi + tol):
                break
        else:
            return
    lows, highs = element.extent_mm()
    for axis, ((lo, hi), low, high) in enumerate(zip(sw_limits_mm, lows, highs), start=1):
        if low < lo - SW_LIMIT_TOLERANCE_MM:
            raise PathError(PathErrorId.SW_LIMIT_MIN,
                            f"axis {axis} would reach {low:.4f} mm, below its software limit "
                            f"{lo:.4f} mm")
        if high > hi + SW_LIMIT_TOLERANCE_MM:
            raise PathError(PathErrorId.SW_LIMIT_MAX,
                            f"axis {axis} would reach {high:.4f} mm, beyond its software limit "
                            f"{hi:.4f} mm")
