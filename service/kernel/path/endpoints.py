"""Software limits of block end points, for runs that only output end points.

The syntax check and the dry run (MACHINE_LOCK) interpolate to block end points only,
but a block that would leave a software limit switch must still stop them with an
error, including an arc whose bulge crosses a limit while both of its ends are inside.
``first_violation`` checks a run of plain motion records (``nc.check.PointBatch``) at
once: every end point, and for arcs the box of their full circle; only an arc whose
circle box crosses a limit is checked exactly, as the path preparation does
(``limits.check_software_limits`` on the arc element). numpy does the screening, so
the check costs a few array operations per batch rather than Python per line.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..nc.blocks import MotionKind
from .errors import PathError
from .geometry import Arc, Line
from .limits import SW_LIMIT_TOLERANCE_MM, check_software_limits

Limits = Sequence[tuple[float, float]]


def first_violation(start_mm: Sequence[float], records: list, plane: tuple[int, int] | None,
                    sw_limits_mm: Limits) -> tuple[int, PathError] | None:
    """The first record of ``records`` (``(line, kind, end, centre)`` as in ``PointBatch``,
    the first starting at ``start_mm``) that leaves the limits, with the error; None
    when all stay inside."""
    if not records:
        return None
    lows = np.array([lo for lo, _ in sw_limits_mm]) - SW_LIMIT_TOLERANCE_MM
    highs = np.array([hi for _, hi in sw_limits_mm]) + SW_LIMIT_TOLERANCE_MM
    ends = np.array([r[2] for r in records], dtype=float)
    suspects = np.flatnonzero(((ends < lows) | (ends > highs)).any(axis=1))
    first = int(suspects[0]) if suspects.size else len(records)
    if plane is not None:
        arcs = np.fromiter((type(r[3]) is tuple for r in records[:first]), bool, first)
        if arcs.any():
            first = min(first, _first_arc_suspect(start_mm, records, ends, arcs, plane,
                                                  lows, highs))
    for k in range(first, len(records)):
        error = _exact(start_mm if k == 0 else records[k - 1][2], records[k], plane,
                       sw_limits_mm)
        if error is not None:
            return k, error
    return None


def _first_arc_suspect(start_mm, records, ends, arcs, plane, lows, highs) -> int:
    """Index of the first arc whose full-circle box leaves the limits (len if none)."""
    p, q = plane
    index = np.flatnonzero(arcs)
    starts = np.vstack((np.asarray(start_mm, dtype=float)[None, :], ends[:-1]))[index]
    centres = np.array([records[k][3] for k in index], dtype=float)
    r0 = np.hypot(starts[:, p] - centres[:, 0], starts[:, q] - centres[:, 1])
    r1 = np.hypot(ends[index, p] - centres[:, 0], ends[index, q] - centres[:, 1])
    radius = np.maximum(r0, r1)
    out = ((centres[:, 0] - radius < lows[p]) | (centres[:, 0] + radius > highs[p])
           | (centres[:, 1] - radius < lows[q]) | (centres[:, 1] + radius > highs[q]))
    hits = np.flatnonzero(out)
    return int(index[hits[0]]) if hits.size else len(records)


def _exact(start: Sequence[float], record: tuple, plane: tuple[int, int] | None,
           sw_limits_mm: Limits) -> PathError | None:
    """The limit error of one record, checked as the path preparation checks it."""
    _, kind, end, centre = record
    try:
        if type(centre) is tuple and plane is not None:
            element = Arc.from_points(start, end, centre, plane, kind == MotionKind.ARC_CCW)
        else:
            element = Line(start, end)
        check_software_limits(element, sw_limits_mm)
    except PathError as error:
        return error
    return None
