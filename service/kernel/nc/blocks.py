"""What the decoder hands to path preparation: decoded blocks in absolute coordinates.

This is the contract between the SDA task (``service.kernel.nc``) and the GEO task
(``service.kernel.path``). Positions are in mm in the channel's axis order (index 0 is
the channel's first axis); every value is already evaluated (no variables, no
expressions, no incremental coordinates).
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import IntEnum


class MotionKind(IntEnum):
    """Interpolation of a motion block (G0..G3)."""

    RAPID = 0  # G0: straight line at the axes' limits (no F)
    LINEAR = 1  # G1
    ARC_CW = 2  # G2: clockwise seen from the positive normal of the plane
    ARC_CCW = 3  # G3


class Compensation(IntEnum):
    """Tool radius compensation in effect for a motion block (G40..G42)."""

    OFF = 40  # G40
    LEFT = 41  # G41: tool left of the contour, seen in the direction of motion
    RIGHT = 42  # G42


class StopKind(IntEnum):
    """Why the path must stop at the end of a block (besides dwell and program end)."""

    NONE = 0  # no stop: the path may run through
    PROGRAMMED = 1  # M0: stop, wait for START
    OPTIONAL = 2  # M1: optional stop; this kernel always stops (no optional-stop switch)
    PROGRAM_END = 3  # M2 / M30: end of the main program


class AxisExchangeKind(IntEnum):
    """Direction of an axis exchange (#AX RELEASE / #AX REQUEST)."""

    RELEASE = 1  # the axes leave the channel (back to the axis management)
    REQUEST = 2  # the axes (re)join the channel


@dataclass(frozen=True, slots=True)
class SourceRef:
    """Where a block came from: file name, 1-based line and column, byte offset of the line."""

    file: str
    line: int
    column: int = 1
    offset: int = 0


@dataclass(frozen=True, slots=True)
class Motion:
    """A straight line or a circular arc, in absolute mm.

    Arcs lie in the plane of axes ``plane`` = (p, q) (G17: X,Y; G18: Z,X; G19: Y,Z, as
    channel axis indices); ``center_mm`` is the centre in (p, q). Axes outside the plane
    do not move in an arc block (no helix). A full circle has ``start_mm == end_mm``.
    """

    kind: MotionKind
    start_mm: tuple[float, ...]
    end_mm: tuple[float, ...]
    feed_mm_s: float  # programmed path feed F (mm/min / 60); math.inf for G0
    plane: tuple[int, int] = (0, 1)
    center_mm: tuple[float, float] | None = None  # arcs only
    compensation: Compensation = Compensation.OFF
    tool_radius_mm: float = 0.0  # radius of the active D; used when compensation is on


@dataclass(frozen=True, slots=True)
class AxisExchange:
    """#AX RELEASE / #AX REQUEST: channel axis indices (0-based) leaving or (re)joining the channel."""

    kind: AxisExchangeKind
    axes: tuple[int, ...]  # channel axis indices, in programmed order, without duplicates


@dataclass(frozen=True, slots=True)
class Block:
    """One decoded NC block: optional motion plus what happens at its end.

    ``number`` is the programmed N number (None when the block has none). A block with
    ``motion`` None, no dwell and no stop is technology only (M/S/T output) and does not
    interrupt the path. A block with ``axis_exchange`` has no motion and stops the
    path: an axis changes hands only at standstill.
    """

    source: SourceRef
    number: int | None = None
    motion: Motion | None = None
    dwell_s: float = 0.0  # G4: wait this long after the block (path speed 0)
    stop: StopKind = StopKind.NONE
    m_functions: tuple[int, ...] = ()  # M words other than the program-flow ones
    spindle_speed_rpm: float | None = None  # S
    tool: int | None = None  # T
    manual: bool = False  # decoded from a manual (MDI) block
    axis_exchange: AxisExchange | None = None  # #AX RELEASE / #AX REQUEST

    @property
    def needs_stop(self) -> bool:
        """True when the path speed must be 0 at the end of this block."""
        return (self.dwell_s > 0.0 or self.stop != StopKind.NONE
                or self.axis_exchange is not None)
