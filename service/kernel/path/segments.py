"""Path preparation: decoded blocks in, planning segments out.

``PathPreparation.prepare(block)`` validates the block, builds its programmed element,
runs tool radius compensation, checks the software limits of every element it
releases and turns each element into a ``Segment``: the unit of velocity planning and
interpolation, carrying every per-element constant the cycle needs (length,
acceleration, speed limits, tangents). Blocks without motion come out as bare
``Block``s (they end where the path is when they are reached).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence

from ..nc.blocks import Block, Compensation, MotionKind
from .compensation import Piece, RadiusCompensator
from .errors import PathError, PathErrorId
from .geometry import Arc, Element, Line
from .limits import AxisDynamics, check_software_limits, element_limits

START_TOLERANCE_MM = 1e-3  # a block may start this far from the previous end (rounding)


class Segment:
    """One element of the path with its planning constants and planned speeds.

    Segments form a doubly linked list in the look-ahead buffer (``prev``/``next``).
    ``events`` are the blocks whose end lies at the end of this segment, in order.
    """

    __slots__ = (
        "element", "block", "point_at", "length_mm", "acc_mm_s2", "inv_2acc", "two_acc_len",
        "speed_mm_s", "axis_speed_mm_s", "programmed_mm_s", "tangent_start", "tangent_end",
        "block_rest_mm", "events", "stop", "single_stop", "cap_mm_s", "corner_mm_s",
        "junction_mm_s", "entry_mm_s", "exit_mm_s", "planned", "prev", "next",
        "la_exit_mm_s", "vfbt", "rapid",
    )

    def __init__(self, element: Element, block: Block, dynamics: Sequence[AxisDynamics],
                 ends_block: bool) -> None:
        motion = block.motion
        assert motion is not None
        rapid = motion.kind == MotionKind.RAPID
        feed = math.inf if rapid else motion.feed_mm_s
        limits = element_limits(element, feed, dynamics)
        mark = block.look_ahead
        if mark is not None and mark.max_mm_s < limits.axis_speed_mm_s:
            # a planned LA_ON block: the block rate the buffer can pass limits it too
            limits = limits._replace(axis_speed_mm_s=mark.max_mm_s,
                                     speed_mm_s=min(limits.speed_mm_s, mark.max_mm_s))
        self.element = element
        self.block = block
        self.rapid = rapid  # G0: the rapid override scales it (planner.LookAhead._cap)
        self.point_at = element.point_at
        self.length_mm = element.length_mm
        self.acc_mm_s2 = limits.acc_mm_s2
        self.inv_2acc = 0.5 / limits.acc_mm_s2
        self.two_acc_len = 2.0 * limits.acc_mm_s2 * element.length_mm
        self.speed_mm_s = limits.speed_mm_s  # min(F, axis limit)
        self.axis_speed_mm_s = limits.axis_speed_mm_s
        self.programmed_mm_s = limits.axis_speed_mm_s if rapid else feed
        self.tangent_start = element.tangent_start
        self.tangent_end = element.tangent_end
        self.block_rest_mm = 0.0  # length of the block's later segments
        self.events: list[Block] = [block] if ends_block else []
        self.stop = block.needs_stop and ends_block  # speed 0 at the end (M0.., dwell)
        self.single_stop = False  # speed 0 at the end for single block
        self.cap_mm_s = self.speed_mm_s  # speed limit with the feed override applied
        self.corner_mm_s = math.inf  # velocity-jump limit of the junction to ``next``
        self.junction_mm_s = 0.0  # min(corner, cap); 0 with a stop or without ``next``
        self.entry_mm_s = 0.0  # backward pass: highest speed at the start
        self.exit_mm_s = 0.0  # backward pass: highest speed at the end
        self.planned = False  # the backward pass has set entry/exit
        self.prev: Segment | None = None
        self.next: Segment | None = None
        # LA_ON: planned speed from which the rest of the section can be met (at the
        # buffer's end instead of a stop; 0: none), VFBT of transitions into it (0: none)
        self.la_exit_mm_s = mark.exit_mm_s if mark is not None and ends_block else 0.0
        self.vfbt = mark.vfbt if mark is not None else 0.0

    def __repr__(self) -> str:
        return (f"Segment({self.element!r}, L={self.length_mm:.6g}, cap={self.cap_mm_s:.6g}, "
                f"exit={self.exit_mm_s:.6g})")


def _finite(values: Iterable[float]) -> bool:
    return all(map(math.isfinite, values))


class PathPreparation:
    """Validation, programmed geometry, radius compensation and software limits.

    ``prepare`` is transactional: when it raises PathError nothing of the block is
    taken and the preparation state is as before the call.
    """

    def __init__(self, dynamics: Sequence[AxisDynamics], start_mm: Sequence[float],
                 sw_limits_mm: Sequence[tuple[float, float]] | None = None) -> None:
        self.dynamics = tuple(dynamics)
        self.axes = len(self.dynamics)
        self.sw_limits_mm = None if sw_limits_mm is None else tuple(
            (float(lo), float(hi)) for lo, hi in sw_limits_mm)
        self.compensator = RadiusCompensator()
        self.last_end_mm = tuple(float(x) for x in start_mm)

    @property
    def holding(self) -> int:
        """Blocks held back by radius compensation."""
        return self.compensator.holding

    def reset(self, position_mm: Sequence[float]) -> None:
        """Forget everything held back; the next block starts at ``position_mm``."""
        self.compensator.restore(None)
        self.last_end_mm = tuple(position_mm)

    def prepare(self, block: Block) -> list[Segment | Block]:
        """Segments (and bare blocks) released by ``block``, in path order."""
        saved = (self.compensator.state, self.last_end_mm)
        try:
            programmed = self._programmed(block)
            pieces = self.compensator.push(block, programmed)
            out = self._segments(pieces)
        except PathError as err:
            self.compensator.restore(saved[0])
            self.last_end_mm = saved[1]
            raise err.for_block(block) from None
        return out

    def flush(self) -> list[Segment | Block]:
        """Release what compensation holds back (end of data)."""
        saved = self.compensator.state
        try:
            return self._segments(self.compensator.flush())
        except PathError:
            self.compensator.restore(saved)
            raise

    def _programmed(self, block: Block) -> Element | None:
        if not (block.dwell_s >= 0.0 and math.isfinite(block.dwell_s)):
            raise PathError(PathErrorId.DWELL_INVALID, f"dwell time {block.dwell_s} s is invalid")
        motion = block.motion
        if motion is None:
            return None
        n = self.axes
        start, end, kind = motion.start_mm, motion.end_mm, motion.kind
        if len(start) != n or len(end) != n:
            raise PathError(PathErrorId.AXIS_COUNT,
                            f"motion has {len(end)} axes, the channel has {n}")
        if not (_finite(start) and _finite(end)):
            raise PathError(PathErrorId.NOT_FINITE, "motion coordinates must be finite")
        if math.dist(start, self.last_end_mm) > START_TOLERANCE_MM:
            raise PathError(PathErrorId.START_MISMATCH,
                            f"block starts at {start}, the previous motion ended at "
                            f"{self.last_end_mm}")
        if kind != MotionKind.RAPID and not motion.feed_mm_s > 0.0:
            raise PathError(PathErrorId.FEED_INVALID, f"feed {motion.feed_mm_s} mm/s must be > 0")
        linear = kind == MotionKind.LINEAR or kind == MotionKind.RAPID
        if not linear or motion.compensation != Compensation.OFF:
            p, q = motion.plane
            if not (0 <= p < n and 0 <= q < n and p != q):
                raise PathError(PathErrorId.PLANE_INVALID, f"plane {motion.plane} is invalid")
        element: Element
        if linear:
            element = Line(tuple(map(float, start)), tuple(map(float, end)))
        else:
            if motion.center_mm is None or not _finite(motion.center_mm):
                raise PathError(PathErrorId.NOT_FINITE, "arc needs a finite centre")
            element = Arc.from_points(motion.start_mm, motion.end_mm, motion.center_mm,
                                      (p, q), motion.kind == MotionKind.ARC_CCW)
            if (element.rise and motion.compensation != Compensation.OFF
                    and motion.tool_radius_mm != 0.0):
                # the offset helix (and its corners) are not built: refused, not run
                # uncompensated (issue 39, docs/kernel.md "Helical interpolation")
                raise PathError(PathErrorId.COMP_HELIX,
                                "tool radius compensation (G41/G42) on a helical arc is not "
                                "supported: deselect it (G40) for the helix")
        self.last_end_mm = end
        return element if element.length_mm > 0.0 else None

    def _segments(self, pieces: list[Piece]) -> list[Segment | Block]:
        out: list[Segment | Block] = []
        for piece in pieces:
            if piece.element is None:
                out.append(piece.block)
                continue
            try:
                check_software_limits(piece.element, self.sw_limits_mm)
            except PathError as err:
                raise err.for_block(piece.block) from None
            out.append(Segment(piece.element, piece.block, self.dynamics, piece.ends_block))
        # remaining length of the block after each segment (held part: its current length)
        rest = 0.0
        held = self.compensator.state
        last_block = None
        for item in reversed(out):
            if not isinstance(item, Segment):
                continue
            if item.block is not last_block:
                last_block = item.block
                rest = 0.0
                if not item.events and held is not None and held.block is item.block:
                    rest = held.element.length_mm
            item.block_rest_mm = rest
            rest += item.length_mm
        return out
