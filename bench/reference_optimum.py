"""Reference: the time-optimal machining time of a program under the kernel's planning model.

Written separately from the planner it checks (it imports nothing from
``cnc_objects.service.kernel``), from this statement of the model:

Axes i have the limits V_i (velocity, mm/s), A_i (acceleration, mm/s^2) and dV_i
(velocity jump permitted at a block junction, mm/s). The programmed feed F is in
mm/min (``feed_mm_min``; math.inf means G0, rapid traverse).

* Line with unit direction u: path speed cap = min(F/60, min_i V_i/|u_i|), path
  acceleration a = min_i A_i/|u_i|, both over the axes with u_i != 0.
* Arc in the plane of axes (p, q), radius R: a = min(A_p, A_q)/sqrt(2) (tangential
  acceleration), cap = min(F/60, V_p, V_q, sqrt(R a)).
* Junction of element j with element j+1, unit tangents u_in (end of j) and u_out
  (start of j+1): speed <= min_i dV_i/|u_out,i - u_in,i| over the axes whose tangent
  component changes, and <= cap_j and cap_j+1.
* Speed 0 at the start and at the end of the program. Zero-length elements are left
  out (they neither take time nor make a junction).
* One backward pass over the whole program: exit_j = min(junction_j, entry_j+1), 0 for
  the last element; entry_j = min(cap_j, sqrt(exit_j^2 + 2 a_j L_j)). Then a forward
  pass: in_j = out_j-1 (0 for the first), out_j = min(exit_j, sqrt(in_j^2 + 2 a_j L_j)).
* Each element is a trapezoid (or triangle) in time with acceleration a_j:
  peak^2 = a L + (in^2 + out^2)/2; if peak <= cap the time is (2 peak - in - out)/a,
  else (2 cap - in - out)/a + (L - (2 cap^2 - in^2 - out^2)/(2 a))/cap.
* The optimum is the (math.fsum) sum of the element times.

``plan`` gives the per-element result, ``optimum_time_s`` the total and ``speed_at``
the optimal path speed at given path distances (for plots). Pure Python except
``speed_at`` (numpy); about 250,000 elements plan in a few seconds.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import KW_ONLY, dataclass

import numpy as np

from cnc_objects.service.config import build_config
from cnc_objects.service.machine_config import MachineConfig

SQRT2 = math.sqrt(2.0)
FULL_CIRCLE_TOLERANCE_MM = 1e-9  # an arc whose end is this close to its start is a full circle
TWO_PI = 2.0 * math.pi

Point = tuple[float, ...]


@dataclass(frozen=True, slots=True)
class AxisLimit:
    """Dynamic limits of one channel axis."""

    vel_max_mm_s: float  # V_i
    acc_max_mm_s2: float  # A_i
    vel_jump_mm_s: float  # dV_i, permitted velocity jump at a junction


def axis_limits(config: MachineConfig | None = None, channel: int = 0) -> tuple[AxisLimit, ...]:
    """The limits of the axes of channel index ``channel`` (in the channel's axis order)
    as written in ``config`` (default: ``build_config()``, the default machine)."""
    if config is None:
        config = build_config()
    return tuple(AxisLimit(a.limits.vel_max_mm_s, a.limits.acc_max_mm_s2, a.limits.vel_jump_mm_s)
                 for a in config.channels[channel].axes)


@dataclass(frozen=True, slots=True)
class Line:
    """A straight line (G0 when ``feed_mm_min`` is math.inf, else G1), in mm."""

    start: Point
    end: Point
    feed_mm_min: float


@dataclass(frozen=True, slots=True)
class Arc:
    """A circular arc (G2: ``ccw`` False, G3: True) in the plane of axes ``plane``.

    ``center`` is the centre in the plane's coordinates (p, q); the axes outside the
    plane do not move. ``end == start`` (in the plane) is a full circle.
    """

    start: Point
    end: Point
    center: tuple[float, float]
    _: KW_ONLY
    plane: tuple[int, int] = (0, 1)
    ccw: bool
    feed_mm_min: float


Element = Line | Arc


@dataclass(frozen=True, slots=True)
class PlannedElement:
    """One element of the optimal plan (zero-length elements have none)."""

    index: int  # position of the element in the list given to ``plan``
    start_mm: float  # path distance at the element's start
    length_mm: float
    acc_mm_s2: float  # a
    cap_mm_s: float  # speed limit of the element
    v_in_mm_s: float
    v_peak_mm_s: float  # highest speed within the element
    v_out_mm_s: float
    time_s: float


@dataclass(frozen=True, slots=True)
class _Prepared:
    """Geometry and limits of one element, as the passes need them."""

    index: int
    length_mm: float
    acc_mm_s2: float
    cap_mm_s: float
    tangent_start: Point
    tangent_end: Point


def _feed_mm_s(feed_mm_min: float) -> float:
    if not feed_mm_min > 0.0:
        raise ValueError(f"feed {feed_mm_min} mm/min must be > 0")
    return feed_mm_min / 60.0


def _prepare_line(index: int, line: Line, limits: Sequence[AxisLimit]) -> _Prepared | None:
    length = math.dist(line.start, line.end)
    if length == 0.0:
        return None
    inv = 1.0 / length
    direction = tuple([(e - s) * inv for s, e in zip(line.start, line.end)])
    cap = _feed_mm_s(line.feed_mm_min)
    acc = math.inf
    # comparisons rather than min(): this loop runs for every axis of every element
    for u, lim in zip(direction, limits):
        if u != 0.0:
            au = abs(u)
            speed = lim.vel_max_mm_s / au
            if speed < cap:
                cap = speed
            speed = lim.acc_max_mm_s2 / au
            if speed < acc:
                acc = speed
    return _Prepared(index, length, acc, cap, direction, direction)


def _arc_tangent(angle_rad: float, ccw: bool, plane: tuple[int, int], axes: int) -> Point:
    """Unit direction of motion at ``angle_rad`` (measured from the p axis towards q)."""
    sign = 1.0 if ccw else -1.0
    out = [0.0] * axes
    out[plane[0]] = -sign * math.sin(angle_rad)
    out[plane[1]] = sign * math.cos(angle_rad)
    return tuple(out)


def _arc_sweep_rad(arc: Arc, start_rad: float, end_rad: float) -> float:
    """Swept angle (> 0) from start to end in the arc's sense; 2 pi for a full circle."""
    p, q = arc.plane
    if math.hypot(arc.end[p] - arc.start[p], arc.end[q] - arc.start[q]) <= FULL_CIRCLE_TOLERANCE_MM:
        return TWO_PI
    return (end_rad - start_rad) % TWO_PI if arc.ccw else (start_rad - end_rad) % TWO_PI


def _prepare_arc(index: int, arc: Arc, limits: Sequence[AxisLimit]) -> _Prepared:
    p, q = arc.plane
    cp, cq = arc.center
    radius = math.hypot(arc.start[p] - cp, arc.start[q] - cq)
    if radius == 0.0:
        raise ValueError(f"arc {index}: centre on the start point")
    start_rad = math.atan2(arc.start[q] - cq, arc.start[p] - cp)
    end_rad = math.atan2(arc.end[q] - cq, arc.end[p] - cp)
    sweep = _arc_sweep_rad(arc, start_rad, end_rad)
    acc = min(limits[p].acc_max_mm_s2, limits[q].acc_max_mm_s2) / SQRT2
    cap = min(_feed_mm_s(arc.feed_mm_min), limits[p].vel_max_mm_s, limits[q].vel_max_mm_s,
              math.sqrt(radius * acc))
    signed_end = start_rad + (sweep if arc.ccw else -sweep)
    axes = len(arc.start)
    return _Prepared(index, radius * sweep, acc, cap,
                     _arc_tangent(start_rad, arc.ccw, arc.plane, axes),
                     _arc_tangent(signed_end, arc.ccw, arc.plane, axes))


def _prepare(elements: Sequence[Element], limits: Sequence[AxisLimit]) -> list[_Prepared]:
    out = []
    for index, element in enumerate(elements):
        if len(element.start) != len(limits) or len(element.end) != len(limits):
            raise ValueError(f"element {index} has {len(element.end)} axes, "
                             f"the limits {len(limits)}")
        if isinstance(element, Arc):
            out.append(_prepare_arc(index, element, limits))
        else:
            prepared = _prepare_line(index, element, limits)
            if prepared is not None:  # zero length: no element, no junction
                out.append(prepared)
    return out


def junction_limit_mm_s(tangent_in: Point, tangent_out: Point, vel_jumps_mm_s: Sequence[float]
                        ) -> float:
    """min_i dV_i/|u_out,i - u_in,i| over the axes whose component changes (inf if none)."""
    limit = math.inf
    for t_in, t_out, jump in zip(tangent_in, tangent_out, vel_jumps_mm_s):
        change = abs(t_out - t_in)
        if change > 0.0:
            speed = jump / change
            if speed < limit:
                limit = speed
    return limit


def _exit_speeds(segs: list[_Prepared], limits: Sequence[AxisLimit]) -> list[float]:
    """Backward pass: the highest exit speed of every element from which all later
    constraints can still be met by braking."""
    jumps = [lim.vel_jump_mm_s for lim in limits]
    n = len(segs)
    exits = [0.0] * n
    next_entry = 0.0
    for j in range(n - 1, -1, -1):
        seg = segs[j]
        if j == n - 1:
            exit_ = 0.0  # the program ends with a stop
        else:
            nxt = segs[j + 1]
            exit_ = min(junction_limit_mm_s(seg.tangent_end, nxt.tangent_start, jumps),
                        seg.cap_mm_s, nxt.cap_mm_s, next_entry)
        exits[j] = exit_
        braked = math.sqrt(exit_ * exit_ + 2.0 * seg.acc_mm_s2 * seg.length_mm)
        next_entry = braked if braked < seg.cap_mm_s else seg.cap_mm_s
    return exits


def element_time_s(length_mm: float, acc_mm_s2: float, cap_mm_s: float, v_in_mm_s: float,
                   v_out_mm_s: float) -> tuple[float, float]:
    """(peak speed, time) of the trapezoid (or triangle) over one element."""
    a, vi, vo = acc_mm_s2, v_in_mm_s, v_out_mm_s
    peak = math.sqrt(a * length_mm + 0.5 * (vi * vi + vo * vo))
    if peak <= cap_mm_s:
        return peak, (2.0 * peak - vi - vo) / a
    cruise_mm = length_mm - (2.0 * cap_mm_s * cap_mm_s - vi * vi - vo * vo) / (2.0 * a)
    # cruise_mm > 0 when peak > cap; the test only absorbs rounding right at peak == cap
    cruise_s = cruise_mm / cap_mm_s if cruise_mm > 0.0 else 0.0
    return cap_mm_s, (2.0 * cap_mm_s - vi - vo) / a + cruise_s


def plan(elements: Sequence[Element], limits: Sequence[AxisLimit] | None = None
         ) -> list[PlannedElement]:
    """The optimal plan of ``elements`` (default limits: ``axis_limits()``)."""
    limits = axis_limits() if limits is None else tuple(limits)
    segs = _prepare(elements, limits)
    exits = _exit_speeds(segs, limits)
    out = []
    v_in = distance = 0.0
    for seg, exit_ in zip(segs, exits):  # forward pass
        v_out = min(exit_, math.sqrt(v_in * v_in + 2.0 * seg.acc_mm_s2 * seg.length_mm))
        peak, time_s = element_time_s(seg.length_mm, seg.acc_mm_s2, seg.cap_mm_s, v_in, v_out)
        out.append(PlannedElement(seg.index, distance, seg.length_mm, seg.acc_mm_s2,
                                  seg.cap_mm_s, v_in, peak, v_out, time_s))
        distance += seg.length_mm
        v_in = v_out
    return out


def optimum_time_s(elements: Sequence[Element], limits: Sequence[AxisLimit] | None = None
                   ) -> float:
    """Time-optimal machining time (s) of ``elements`` (default limits: ``axis_limits()``)."""
    return math.fsum(p.time_s for p in plan(elements, limits))


def speed_at(planned: Sequence[PlannedElement], distance_mm: np.ndarray) -> np.ndarray:
    """Optimal path speed (mm/s) at the path distances ``distance_mm`` (clipped to the path).

    Within an element v(s) = min(sqrt(v_in^2 + 2 a s), cap, sqrt(v_out^2 + 2 a (L - s))).
    At a junction the speed is continuous, so which of the two elements a distance on
    the boundary is given to does not matter.
    """
    distance = np.asarray(distance_mm, dtype=float)
    if not planned:
        return np.zeros_like(distance)
    start = np.fromiter((p.start_mm for p in planned), float, len(planned))
    length = np.fromiter((p.length_mm for p in planned), float, len(planned))
    acc = np.fromiter((p.acc_mm_s2 for p in planned), float, len(planned))
    cap = np.fromiter((p.cap_mm_s for p in planned), float, len(planned))
    v_in = np.fromiter((p.v_in_mm_s for p in planned), float, len(planned))
    v_out = np.fromiter((p.v_out_mm_s for p in planned), float, len(planned))
    k = np.clip(np.searchsorted(start, distance, side="right") - 1, 0, len(planned) - 1)
    s = np.clip(distance - start[k], 0.0, length[k])
    accel = np.sqrt(v_in[k] ** 2 + 2.0 * acc[k] * s)
    brake = np.sqrt(v_out[k] ** 2 + 2.0 * acc[k] * (length[k] - s))
    return np.minimum(np.minimum(accel, cap[k]), brake)
