"""Arc geometry in the working plane: centre from I/J/K offsets or from a radius R.

Coordinates are (p, q) in the plane's axis order (G17: X,Y; G18: Z,X; G19: Y,Z).
Clockwise (G2) and counter-clockwise (G3) are seen from the positive plane normal, so
in (p, q) coordinates "left of the chord" is the side the centre of a G3 arc with
R > 0 lies on. A negative R selects the other centre: the arc longer than 180 degrees.
The fast path of the decoder repeats ``centre_from_offsets`` inline; both must stay the
same arithmetic.
"""

from __future__ import annotations

import math

from .errors import NcErrorId
from .variables import VariableFault

ARC_TOLERANCE_MM = 1e-3  # largest allowed difference of start and end radius


def centre_from_offsets(
    sp: float, sq: float, ep: float, eq: float, oi: float, oj: float
) -> tuple[float, float]:
    """Centre = start + (oi, oj); the end point must lie on the same circle."""
    cp = sp + oi
    cq = sq + oj
    r_start = math.hypot(oi, oj)
    if r_start == 0.0:
        raise VariableFault(NcErrorId.ARC_RADIUS_ZERO, "arc centre is the start point (radius 0)")
    r_end = math.hypot(ep - cp, eq - cq)
    if abs(r_start - r_end) > ARC_TOLERANCE_MM:
        raise VariableFault(
            NcErrorId.ARC_RADIUS_DIFFERENCE,
            f"arc end point is not on the circle (radius {r_start:.3f} vs {r_end:.3f})",
        )
    return cp, cq


def centre_from_radius(
    sp: float, sq: float, ep: float, eq: float, radius: float, ccw: bool
) -> tuple[float, float]:
    """Centre of the arc of ``radius`` from start to end (R < 0: the arc > 180 degrees)."""
    dp = ep - sp
    dq = eq - sq
    chord = math.hypot(dp, dq)
    if chord == 0.0:
        raise VariableFault(
            NcErrorId.ARC_FULL_CIRCLE_WITH_R,
            "a full circle cannot be programmed with R; use I/J/K",
        )
    r = abs(radius)
    if r == 0.0:
        raise VariableFault(NcErrorId.ARC_RADIUS_ZERO, "arc radius R0")
    half = chord / 2.0
    if half > r + ARC_TOLERANCE_MM:
        raise VariableFault(
            NcErrorId.ARC_RADIUS_TOO_SMALL,
            f"radius {r:.3f} is too small for the distance {chord:.3f} to the end point",
        )
    h = math.sqrt(max(r * r - half * half, 0.0))
    side = 1.0 if ccw else -1.0  # +1: left of the chord
    if radius < 0.0:
        side = -side
    # left normal of the chord direction (dp, dq) is (-dq, dp)
    return sp + dp / 2.0 - side * h * dq / chord, sq + dq / 2.0 + side * h * dp / chord
