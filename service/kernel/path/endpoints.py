"""Software limits of block end points, for runs that only output end points.

The syntax check and the dry run (MACHINE_LOCK) interpolate to block end points only,
but a block that would leave a software limit switch must still stop them with an
error, including an arc whose bulge crosses a limit while both of its ends are inside.
``first_violation`` screens a run of plain motion records (``nc.check.PointBatch``) at
once: the box of all end points (``min``/``max`` over the columns, in C), and for each
arc the box of its full circle. Only when the screening finds a suspect is the batch
checked record by record, exactly as the path preparation checks an element
(``limits.check_software_limits`` on the same ``Line`` / ``Arc``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from ..nc.blocks import MotionKind
from .errors import PathError
from .geometry import ARC_RADIUS_TOLERANCE_MM, Arc, Element, Line
from .limits import SW_LIMIT_TOLERANCE_MM, check_software_limits

Limits = Sequence[tuple[float, float]]
#: (line index, MotionKind, end point, arc centre (p, q) or None): nc.check.PointBatch
Record = tuple[int, MotionKind, tuple[float, ...], tuple[float, float] | None]


def first_violation(start_mm: Sequence[float], records: Sequence[Record],
                    plane: tuple[int, int] | None,
                    sw_limits_mm: Limits) -> tuple[int, PathError] | None:
    """The first record of ``records`` (``(line, kind, end, centre)`` as in ``PointBatch``,
    the first starting at ``start_mm``) that leaves the limits, with the error; None
    when all stay inside."""
    if not records:
        return None
    if _inside(start_mm, records, plane, sw_limits_mm):
        return None
    position = start_mm
    for k, record in enumerate(records):
        error = _exact(position, record, plane, sw_limits_mm)
        if error is not None:
            return k, error
        position = record[2]
    return None


def _inside(start_mm: Sequence[float], records: Sequence[Record], plane: tuple[int, int] | None,
            sw_limits_mm: Limits) -> bool:
    """True when every end point and every arc's full circle is inside the limits."""
    tol = SW_LIMIT_TOLERANCE_MM
    ends = [r[2] for r in records]
    for column, (lo, hi) in zip(zip(*ends), sw_limits_mm):
        if min(column) < lo - tol or max(column) > hi + tol:
            return False
    arcs = [(k, centre) for k, (_, _, _, centre) in enumerate(records)
            if type(centre) is tuple]
    if not arcs or plane is None:
        return True
    p, q = plane
    lo_p, hi_p = sw_limits_mm[p]
    lo_q, hi_q = sw_limits_mm[q]
    lo_p, hi_p, lo_q, hi_q = lo_p - tol, hi_p + tol, lo_q - tol, hi_q + tol
    sqrt = math.sqrt
    for k, (cp, cq) in arcs:
        start = records[k - 1][2] if k else start_mm
        dp, dq = start[p] - cp, start[q] - cq
        # the end lies within the arc tolerance of the circle through the start
        r = sqrt(dp * dp + dq * dq) + ARC_RADIUS_TOLERANCE_MM
        if cp - r < lo_p or cp + r > hi_p or cq - r < lo_q or cq + r > hi_q:
            return False
    return True


def _exact(start: Sequence[float], record: Record, plane: tuple[int, int] | None,
           sw_limits_mm: Limits) -> PathError | None:
    """The limit error of one record, checked as the path preparation checks it."""
    _, kind, end, centre = record
    element: Element
    try:
        if type(centre) is tuple and plane is not None:
            element = Arc.from_points(start, end, centre, plane, kind == MotionKind.ARC_CCW)
        else:
            element = Line(start, end)
        check_software_limits(element, sw_limits_mm)
    except PathError as error:
        return error
    return None
