"""Test programs as data (decoded blocks) and a runner that records every cycle.

The closed-form helpers here are written independently of the planner so the tests
compare the executor against the model, not against itself.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

from cnc_objects.service.kernel.nc.blocks import Block, Compensation, Motion, MotionKind, SourceRef, StopKind
from cnc_objects.service.kernel.path import AxisDynamics, PathExecutor, StepResult

DT = 0.001
DYN = (AxisDynamics(500.0, 5000.0, 50.0),) * 3
# axes with different limits, so that the per-axis rules matter
DYN_MIXED = (AxisDynamics(300.0, 4000.0, 30.0), AxisDynamics(200.0, 2500.0, 20.0),
             AxisDynamics(100.0, 1500.0, 10.0))

_line_no = 0


def _src() -> SourceRef:
    global _line_no
    _line_no += 1
    return SourceRef("test.nc", _line_no)


def line(start, end, feed_mm_s: float = 100.0, *, comp: Compensation = Compensation.OFF,
         r: float = 0.0, rapid: bool = False, plane=(0, 1), **block_kw) -> Block:
    """A G1 (or G0) block."""
    kind = MotionKind.RAPID if rapid else MotionKind.LINEAR
    motion = Motion(kind, tuple(map(float, start)), tuple(map(float, end)),
                    math.inf if rapid else feed_mm_s, plane=plane, compensation=comp,
                    tool_radius_mm=r)
    return Block(_src(), block_kw.pop("number", None), motion, **block_kw)


def arc(start, end, center, *, ccw: bool, feed_mm_s: float = 100.0,
        comp: Compensation = Compensation.OFF, r: float = 0.0, plane=(0, 1), **block_kw) -> Block:
    """A G2 (ccw False) or G3 block."""
    motion = Motion(MotionKind.ARC_CCW if ccw else MotionKind.ARC_CW,
                    tuple(map(float, start)), tuple(map(float, end)), feed_mm_s, plane=plane,
                    center_mm=tuple(map(float, center)), compensation=comp, tool_radius_mm=r)
    return Block(_src(), block_kw.pop("number", None), motion, **block_kw)


def polyline(points: Sequence[Sequence[float]], feed_mm_s: float = 100.0, **kw) -> list[Block]:
    """Lines through ``points``."""
    return [line(a, b, feed_mm_s, **kw) for a, b in zip(points, points[1:])]


def dwell(seconds: float) -> Block:
    """G4."""
    return Block(_src(), dwell_s=seconds)


def stop(kind: StopKind = StopKind.PROGRAMMED) -> Block:
    """M0 / M1 / M30 alone."""
    return Block(_src(), stop=kind)


def technology(*m: int) -> Block:
    """An M-function block without motion."""
    return Block(_src(), m_functions=tuple(m))


@dataclass
class Trace:
    """Everything recorded while running a program."""

    positions: list[tuple[float, ...]] = field(default_factory=list)  # [0] = start
    results: list[StepResult] = field(default_factory=list)
    finished: list[Block] = field(default_factory=list)
    junction_cycles: set[int] = field(default_factory=set)  # cycles (1-based) with a block end

    @property
    def cycles(self) -> int:
        return len(self.results)


def run(ex: PathExecutor, blocks: Sequence[Block], *, override: float | Callable[[int], float] = 1.0,
        max_cycles: int = 200_000, on_cycle: Callable[[int, PathExecutor, StepResult], None] | None = None,
        resume_stops: bool = True) -> Trace:
    """Feed ``blocks`` as slots free up, close, step until idle; record every cycle."""
    trace = Trace(positions=[ex.position_mm])
    k, n = 0, len(blocks)
    closed = False
    for cycle in range(1, max_cycles + 1):
        while k < n and ex.free_slots() > 0:
            ex.push(blocks[k])
            k += 1
        if k == n and not closed:
            ex.close()
            closed = True
        ov = override(cycle) if callable(override) else override
        res = ex.step(ov)
        trace.results.append(res)
        trace.positions.append(res.position_mm)
        if res.finished:
            trace.finished.extend(res.finished)
            trace.junction_cycles.add(cycle)
        if on_cycle is not None:
            on_cycle(cycle, ex, res)
        if resume_stops and res.stopped_at is not None:
            ex.resume()
        if closed and ex.idle:
            return trace
    raise AssertionError(f"program did not finish within {max_cycles} cycles")


def check_axis_limits(trace: Trace, dynamics: Sequence[AxisDynamics], dt: float = DT,
                      exclude: set[int] | None = None, rel_tol: float = 1e-6) -> tuple[float, float]:
    """Assert per-axis speed and acceleration (finite differences of cycle positions)
    within the limits; junction cycles (a block end passed) and their neighbours are
    excluded from the acceleration check. Returns the largest speed and acceleration
    ratios to the limits seen."""
    excluded = set(exclude or ())
    for c in trace.junction_cycles:
        excluded.update((c, c + 1))
    pos = trace.positions
    vel = [[(b - a) / dt for a, b in zip(p0, p1)] for p0, p1 in zip(pos, pos[1:])]
    max_v = max_a = 0.0
    for k, v in enumerate(vel, start=1):  # vel[k-1] is the mean speed during cycle k
        for i, d in enumerate(dynamics):
            ratio = abs(v[i]) / d.vel_max_mm_s
            max_v = max(max_v, ratio)
            assert ratio <= 1.0 + rel_tol, f"axis {i} speed {v[i]} in cycle {k}"
    for k in range(1, len(vel)):  # acceleration at the end of cycle k
        if k in excluded or k + 1 in excluded:
            continue
        for i, d in enumerate(dynamics):
            acc = (vel[k][i] - vel[k - 1][i]) / dt
            ratio = abs(acc) / d.acc_max_mm_s2
            max_a = max(max_a, ratio)
            assert ratio <= 1.0 + rel_tol, f"axis {i} acceleration {acc} after cycle {k}"
    return max_v, max_a


def trapezoid_time(length: float, acc: float, vmax: float, v0: float, v1: float) -> float:
    """Time of a trapezoid (or triangle) profile from v0 to v1, independent closed form."""
    d_acc = (vmax ** 2 - v0 ** 2) / (2 * acc)
    d_dec = (vmax ** 2 - v1 ** 2) / (2 * acc)
    if d_acc + d_dec <= length:
        return (vmax - v0) / acc + (length - d_acc - d_dec) / vmax + (vmax - v1) / acc
    vp = math.sqrt(acc * length + (v0 ** 2 + v1 ** 2) / 2)
    return (vp - v0) / acc + (vp - v1) / acc


def distance_to_contour(point: tuple[float, float], contour: Sequence[tuple]) -> float:
    """Distance of an XY point to a contour of ("line", a, b) and ("arc", a, b, c, ccw)."""
    best = math.inf
    px, py = point
    for item in contour:
        if item[0] == "line":
            (ax, ay), (bx, by) = item[1], item[2]
            dx, dy = bx - ax, by - ay
            t = max(0.0, min(1.0, ((px - ax) * dx + (py - ay) * dy) / (dx * dx + dy * dy)))
            best = min(best, math.hypot(px - ax - t * dx, py - ay - t * dy))
        else:
            _, a, b, c, ccw = item
            radius = math.hypot(a[0] - c[0], a[1] - c[1])
            a0 = math.atan2(a[1] - c[1], a[0] - c[0])
            a1 = math.atan2(b[1] - c[1], b[0] - c[0])
            sweep = (a1 - a0) % (2 * math.pi) if ccw else (a0 - a1) % (2 * math.pi)
            if a == b:
                sweep = 2 * math.pi  # full circle
            ang = math.atan2(py - c[1], px - c[0])
            off = (ang - a0) % (2 * math.pi) if ccw else (a0 - ang) % (2 * math.pi)
            if off <= sweep:
                best = min(best, abs(math.hypot(px - c[0], py - c[1]) - radius))
            best = min(best, math.hypot(px - a[0], py - a[1]), math.hypot(px - b[0], py - b[1]))
    return best
