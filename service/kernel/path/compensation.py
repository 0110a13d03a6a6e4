"""Tool radius compensation (G41/G42, cancelled by G40) for lines and arcs, streaming.

Each compensated element is offset by the tool radius r to the left (G41) or right
(G42) of the direction of motion, in the block's plane (axes outside the plane are not
offset). Consecutive offset elements are joined at the programmed corner point C:

* tangent transition: the offset elements already meet;
* inside corner (the tool is on the inside of the turn): both offset elements are
  trimmed to their intersection (line-line, line-arc, arc-arc; of two intersections
  the one nearest to C). An element the tool cannot follow (the intersection lies
  before its start, or none exists) raises PathError;
* outside corner (the tool is on the outside of the turn, including a reversal): a
  connecting arc of radius r around C is inserted. It belongs to the following block.

Approach and departure ("perpendicular" strategy):

* Selection: the first compensated block (G41/G42 after G40) is itself offset; a
  straight approach line, part of that block, leads from its programmed start (where
  the uncompensated tool stands) to the offset start point, i.e. the point at distance
  r perpendicular to the element at its start.
* Deselection: the compensated path ends at the offset end point of the last
  compensated element, perpendicular to it at its end. The next motion block (G40) is
  a straight line from there to its programmed end point. G40 in an arc block raises
  PathError COMP_DESELECT_ON_ARC. A change of side or radius while compensation stays
  on ends the previous element perpendicular and links to the next offset start with a
  straight line (part of the new block).
* End of data (``flush``) with compensation on: the last element ends perpendicular.

  As with every perpendicular strategy, on a closed contour whose closing corner is
  also the selection/deselection point, the start of the first and the end of the last
  offset element are not trimmed against each other: at an inside closing corner the
  tool reaches up to r into the neighbouring element there. Program the approach and
  departure away from such a corner (or on the extension of an element).

Streaming: an offset element can only be released when the next motion block is known
(its end may be trimmed), so one motion block (with the non-motion blocks that follow
it) is held back. The output is a list of ``Piece``s in path order.

Limitations: a compensated block must move in the plane (a pure infeed raises
COMP_NO_PLANE_MOTION); the plane may not change while compensation is on.
"""

from __future__ import annotations

from typing import NamedTuple

from ..nc.blocks import Block, Compensation
from .errors import PathError, PathErrorId
from .geometry import Arc, Element, Line
from .offsets import (
    MIN_LENGTH_MM,
    intersect,
    offset_element,
    plane_point,
    plane_tangent,
    trim_end,
    trim_start,
)

TANGENT_SIN = 1e-9  # |sin| of the corner angle below which a transition counts as tangent


class Piece(NamedTuple):
    """One output item: an element of the compensated path, or a bare block end.

    ``element`` None: the block has no motion left (non-motion block or degenerate
    element); ``ends_block``: the block ends at the end of this piece.
    """

    element: Element | None
    block: Block
    ends_block: bool


class _Pending(NamedTuple):
    """The held-back offset element and what belongs to it."""

    element: Element  # offset element; start final, end not yet
    programmed: Element  # the programmed element it was offset from
    block: Block
    side: float  # +1 left (G41), -1 right (G42)
    radius_mm: float
    plane: tuple[int, int]
    trailing: tuple[Block, ...]  # non-motion blocks that follow it


def _side(compensation: Compensation) -> float:
    return 1.0 if compensation == Compensation.LEFT else -1.0


class RadiusCompensator:
    """Turns programmed elements into the compensated path, one block at a time.

    ``push`` returns the pieces that are final now; ``flush`` releases what is held
    back. ``state``/``restore`` make a push transactional for the caller.
    """

    def __init__(self) -> None:
        self._pending: _Pending | None = None

    @property
    def state(self) -> _Pending | None:
        """Opaque, immutable state (for ``restore``)."""
        return self._pending

    def restore(self, state: _Pending | None) -> None:
        """Return to a state taken from ``state``."""
        self._pending = state

    @property
    def holding(self) -> int:
        """Number of blocks held back."""
        return 0 if self._pending is None else 1 + len(self._pending.trailing)

    def flush(self) -> list[Piece]:
        """Release the held element, ending perpendicular to its end."""
        pending, self._pending = self._pending, None
        return [] if pending is None else _emit(pending, pending.element)

    def push(self, block: Block, programmed: Element | None) -> list[Piece]:
        """Compensate ``block`` whose programmed geometry is ``programmed`` (None: no motion)."""
        pending = self._pending
        if programmed is None:
            if pending is not None:
                self._pending = pending._replace(trailing=pending.trailing + (block,))
                return []
            return [Piece(None, block, True)]
        motion = block.motion
        assert motion is not None
        radius = motion.tool_radius_mm
        if radius < 0.0:
            raise PathError(PathErrorId.COMP_RADIUS_NEGATIVE,
                            f"tool radius {radius} mm is negative")
        if motion.compensation == Compensation.OFF or radius == 0.0:
            return self._uncompensated(block, programmed)
        plane = motion.plane
        side = _side(motion.compensation)
        if pending is not None and pending.plane != plane:
            raise PathError(PathErrorId.COMP_PLANE_CHANGE,
                            "the plane changed while tool radius compensation is active")
        offset = offset_element(programmed, plane, side, radius)
        new = _Pending(offset, programmed, block, side, radius, plane, ())
        if pending is None:  # selection: approach perpendicular to the first element
            self._pending = new
            return _pieces(Line(programmed.start_mm, offset.start_mm), block, False)
        if pending.side != side or pending.radius_mm != radius:
            link = Line(pending.element.end_mm, offset.start_mm)
            out = _emit(pending, pending.element) + _pieces(link, block, False)
            self._pending = new
            return out
        out = self._corner(pending, new)
        return out

    def _uncompensated(self, block: Block, programmed: Element) -> list[Piece]:
        pending = self._pending
        if pending is None:
            return _pieces(programmed, block, True)
        if isinstance(programmed, Arc):
            raise PathError(PathErrorId.COMP_DESELECT_ON_ARC,
                            "G40 must be programmed in a straight block")
        out = _emit(pending, pending.element)
        departure = Line(pending.element.end_mm, programmed.end_mm)
        self._pending = None
        return out + _pieces(departure, block, True)

    def _corner(self, pending: _Pending, new: _Pending) -> list[Piece]:
        plane = new.plane
        t1 = plane_tangent(pending.programmed.tangent_end, plane)
        t2 = plane_tangent(new.programmed.tangent_start, plane)
        cross = t1[0] * t2[1] - t1[1] * t2[0]
        dot = t1[0] * t2[0] + t1[1] * t2[1]
        corner = plane_point(new.programmed.start_mm, plane)
        if abs(cross) <= TANGENT_SIN and dot > 0.0:  # tangent: offset ends meet
            out = _emit(pending, pending.element)
            self._pending = new
            return out
        inside = cross * new.side > 0.0 and abs(cross) > TANGENT_SIN
        if not inside:  # outside corner or reversal: arc of radius r around the corner
            start, end = pending.element.end_mm, new.element.start_mm
            arc = Arc.from_points(start, end, corner, plane, ccw=new.side < 0.0)
            out = _emit(pending, pending.element) + _pieces(arc, new.block, False)
            self._pending = new
            return out
        point = intersect(pending.element, new.element, plane, corner)
        if point is None:
            raise PathError(PathErrorId.COMP_NO_INTERSECTION,
                            "offset elements do not intersect at an inside corner")
        first = trim_end(pending.element, point, plane)
        second = trim_start(new.element, point, plane)
        out = _emit(pending, first)
        self._pending = new._replace(element=second)
        return out


def _pieces(element: Element, block: Block, ends_block: bool) -> list[Piece]:
    if element.length_mm <= MIN_LENGTH_MM:
        return [Piece(None, block, True)] if ends_block else []
    return [Piece(element, block, ends_block)]


def _emit(pending: _Pending, element: Element) -> list[Piece]:
    out = _pieces(element, pending.block, True)
    out.extend(Piece(None, b, True) for b in pending.trailing)
    return out
