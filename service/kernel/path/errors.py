"""Errors of path preparation: ISG-style numeric ids in 50000..50999 and ``PathError``.

Every refusal of a block (bad geometry, tool radius compensation that cannot be
computed, software limit, full buffer) raises ``PathError`` with an id from
``PathErrorId`` and, where known, the block it concerns. ``str(error)`` reads like an
ISG error line: ``path error 50101 SW_LIMIT_MAX: ... (N20, prog.nc:5)``.
"""

from __future__ import annotations

from enum import IntEnum

from ..nc.blocks import Block


class PathErrorId(IntEnum):
    """Numeric ids of path preparation errors (ISG style, 50000..50999)."""

    AXIS_COUNT = 50001  # the motion has a different number of axes than the channel
    NOT_FINITE = 50002  # a coordinate, centre, feed or radius is NaN or infinite
    START_MISMATCH = 50003  # the block starts elsewhere than the previous motion ended
    FEED_INVALID = 50004  # F <= 0 in a G1/G2/G3 block
    PLANE_INVALID = 50005  # the plane's axis indices are out of range or equal
    DWELL_INVALID = 50006  # negative or infinite dwell time
    ARC_CENTER = 50010  # arc start (or end) coincides with its centre: radius 0
    ARC_END_RADIUS = 50011  # arc end point is not on the circle through the start
    ARC_HELIX = 50012  # unused since issue 39 (helical arcs run); the id stays reserved
    SW_LIMIT_MIN = 50100  # the motion leaves an axis' software limit downwards
    SW_LIMIT_MAX = 50101  # the motion leaves an axis' software limit upwards
    AXIS_NOT_REFERENCED = 50110  # the block moves an axis that needs homing first
    # (P-AXIS-00277 prog_move_requires_homing); project id: ISG's pages name none
    COMP_RADIUS_NEGATIVE = 50200  # tool radius for compensation is negative
    COMP_ARC_RADIUS = 50201  # arc radius <= tool radius on the inside of the arc
    COMP_NO_INTERSECTION = 50202  # offset elements at an inside corner do not intersect
    COMP_CONTOUR_VIOLATION = 50203  # an element is too short for the tool: offset reverses it
    COMP_DESELECT_ON_ARC = 50204  # G40 programmed in an arc block (deselect in a line)
    COMP_NO_PLANE_MOTION = 50205  # compensated block without motion in the plane
    COMP_PLANE_CHANGE = 50206  # plane changed while compensation is active
    COMP_BOTTLENECK = 50207  # LA_ON, BBTRC: compensated elements of two blocks cross
    COMP_HELIX = 50208  # G41/G42 on a helical arc (the offset helix is not built)
    BUFFER_FULL = 50300  # push() without a free slot in the look-ahead buffer
    BUFFER_LIMITS_SPEED = 50301  # warning: the end of the full buffer holds the speed down


class PathError(Exception):
    """A block refused by path preparation.

    ``id`` is a ``PathErrorId``, ``block`` the block concerned (None when not known,
    e.g. a geometry helper called directly), ``message`` the sentence without the id.
    """

    def __init__(self, id: PathErrorId, message: str, block: Block | None = None) -> None:
        self.id = PathErrorId(id)
        self.message = message
        self.block = block
        super().__init__(str(self))

    def for_block(self, block: Block) -> PathError:
        """The same error attributed to ``block`` (kept if one is already set)."""
        if self.block is not None:
            return self
        return PathError(self.id, self.message, block)

    def __str__(self) -> str:
        where = ""
        if self.block is not None:
            src = self.block.source
            number = f"N{self.block.number}, " if self.block.number is not None else ""
            where = f" ({number}{src.file}:{src.line})"
        return f"path error {int(self.id)} {self.id.name}: {self.message}{where}"

    def __reduce__(  # picklable despite the custom __init__
        self,
    ) -> tuple[type[PathError], tuple[PathErrorId, str, Block | None]]:
        return (PathError, (self.id, self.message, self.block))
