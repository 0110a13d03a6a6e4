"""Contour look-ahead (ISG FCT-C40): future contour elements for the PLC.

``ContourLog`` watches the path of one program run as it is prepared, i.e. as blocks
enter the look-ahead buffer, before they are executed. It keeps

* the **log** of the marked area (``#CONTOUR LOOKAHEAD LOG ON`` .. ``LOG OFF``): the LOG
  entries (types 3, 4, 5) and every element of the compensated path in between, at most
  ``contour_lookahead_log_max`` (P-CHAN-00658) entries. Only the first marked area is
  kept until ``LOG CLEAR``; mode 1 requests read it by index;
* the **recent elements** of the whole path for mode 2 requests by path distance:
  every element that can still be in the look-ahead buffer and at least the last
  ``contour_lookahead_log_max`` before them, each with the distance epoch it counts in
  (``#DISTANCE PROG START CLEAR`` starts a new one);
* the **prepared path distance**: the start position of the next element, i.e. the sum
  of the lengths of all earlier elements on the compensated path since program start or
  ``#DISTANCE PROG START CLEAR``. Its value after the last prepared element is the
  maximum look-ahead distance (``state.max_dist_prog_start``): it depends on the
  look-ahead buffer and the block supply only, not on feedhold, override, M functions
  or dwell.

An element is a piece of the compensated path: a block's line or arc, and also the
pieces tool radius compensation adds (the approach line of the selection block, the
connecting arc of radius r around an outside corner, which belongs to the following
block). A block therefore gives one element or more, all with its N and block count.

Real-time loops (``#RT WHILE``): the decoder unrolls them and marks the passes of a loop
entered while the marked area is open (``ContourKind.RT_PASS``/``RT_END``). The marks
never enter the path; ``mark``/``expect`` apply them in path order, after what radius
compensation still holds of the pass before. ISG logs such
a body three times, once per transition: start of loop, loop to loop, end of loop. Here
the first pass (its first element has the angle to the block before the loop), the
second pass (angle to the end of the body) and the last pass (its end meets what follows
the loop) are logged; passes 3 .. n-1 repeat the second and are left out. A loop with
fewer passes has fewer transitions, and is logged with as many copies as it has passes.
LOG ON inside the loop opens the area in the first pass; the later passes' LOG ON are
ignored (only the first area is kept), so the body is logged once, with the angle to the
block before the loop.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Iterable, Sequence

from cnc_objects.protocol.units import UM01_PER_MM
from cnc_objects.protocol.values import ContourBlockType

from .nc.blocks import Block, ContourCommand, ContourKind, LogArea, MotionKind, next_log_area
from .path.geometry import Arc, Element
from .path.segments import Segment
from .state import ContourElement

RESPONSE_BLOCKS = 32  # entries of gpCh[i].contour_lookahead.response.block[0..31]
LOG_FULL_WARNING = 22074  # warning id: the marked area has more entries than the log keeps

LINEAR, CIRCULAR = ContourBlockType.LINEAR, ContourBlockType.CIRCULAR  # motion elements
_SAME_CENTRE_MM = 1e-6  # an offset arc keeps the centre of its programmed arc
# mode 2 window edges: start positions are exact sums of the lengths in 0.1 um, as a
# PLC adds them; this only absorbs a client's own rounding
_WINDOW_TOLERANCE_INCR = 1e-6


class RequestError(ValueError):
    """A request the CNC cannot answer (the semaphore write is refused)."""


def _unit(v: Sequence[float]) -> Sequence[float]:
    norm = math.sqrt(sum(x * x for x in v))
    if norm == 0.0 or abs(norm - 1.0) <= 1e-12:
        return v  # a unit vector already: left exactly as it is
    return [x / norm for x in v]


def tangent_angle_rad(a: Sequence[float], b: Sequence[float]) -> float:
    """Angle between unit vectors ``a`` and ``b`` in [0, pi], exact near 0 and pi.

    A line that moves tracking axes besides the main axes has a tangent longer than 1
    (its motion per mm of path, ``geometry.Line``): such tangents are made unit first."""
    a, b = _unit(a), _unit(b)
    diff = math.sqrt(sum((x - y) * (x - y) for x, y in zip(a, b, strict=True)))
    total = math.sqrt(sum((x + y) * (x + y) for x, y in zip(a, b, strict=True)))
    return 2.0 * math.atan2(diff, total)


def _programmed_radius_mm(element: Element, block: Block) -> float:
    """Radius of the programmed arc this element is the (offset) image of; 0 for a line
    and for the pieces compensation adds (connecting arcs, approach lines)."""
    motion = block.motion
    if not isinstance(element, Arc) or motion is None or motion.center_mm is None:
        return 0.0
    if motion.kind not in (MotionKind.ARC_CW, MotionKind.ARC_CCW):
        return 0.0
    cp, cq = motion.center_mm
    if math.hypot(element.center[0] - cp, element.center[1] - cq) > _SAME_CENTRE_MM:
        return 0.0  # a connecting arc around a corner of the programmed contour
    p, q = motion.plane
    return math.hypot(motion.start_mm[p] - cp, motion.start_mm[q] - cq)


class _Prepared:
    """An element of the prepared path as mode 2 keeps it: what its ``ContourElement``
    is made of, made only when a request reads it (``entry``). Most elements are never
    asked for, and building each one cost a block of a CAM program about a tenth of
    its preparation (issue 37, short blocks)."""

    __slots__ = ("element", "number", "ordinal", "start_position", "previous")

    def __init__(self, element: Element, number: int, ordinal: int, start_position: float,
                 previous: tuple[float, ...] | None) -> None:
        self.element = element
        self.number = number
        self.ordinal = ordinal
        self.start_position = start_position  # 0.1 um
        self.previous = previous  # the end tangent of the element before (None: none)

    def entry(self, block: Block) -> ContourElement:
        """The element as the PLC reads it (``block``: the block it belongs to)."""
        element, previous = self.element, self.previous
        variation = 0.0 if previous is None else tangent_angle_rad(previous,
                                                                   element.tangent_start)
        length = element.length_mm * UM01_PER_MM
        if isinstance(element, Arc):
            return ContourElement(
                CIRCULAR, self.number, self.ordinal, self.start_position, length,
                _programmed_radius_mm(element, block) * UM01_PER_MM,
                element.radius_mm * UM01_PER_MM, element.sweep_rad, 0.0, variation,
            )
        return ContourElement(
            LINEAR, self.number, self.ordinal, self.start_position, length, 0.0, 0.0, 0.0,
            0.0, variation,
        )


class ContourLog:
    """The contour look-ahead of one program run (GEO task).

    ``buffer_blocks`` is the look-ahead size: mode 2 keeps every element that may still
    be in the buffer (a block gives at most three: approach line, connecting arc and its
    own element) plus the last ``log_max`` before them.
    """

    def __init__(self, log_max: int, buffer_blocks: int) -> None:
        self.log_max = log_max
        self.log: list[ContourElement] = []
        # mode 2: (distance epoch, element); nothing when P-CHAN-00658 is 0
        # (an element is made into its ``ContourElement`` only when a request reads it)
        self.recent: deque[tuple[int, _Prepared, Block]] = deque(
            maxlen=log_max + 3 * buffer_blocks if log_max else 0)
        self.area = LogArea.NONE
        self.distance_01um = 0.0  # start of the next element (0.1 um, summed as the PLC does)
        self.epoch = 0  # #DISTANCE PROG START CLEAR prepared so far
        self.executed_epoch = 0  # ... and executed: the distances dist_prog_start counts in
        self.complete = False  # the end of data was prepared: everything is read in
        self.full_warned = False  # the log-full warning was given for this area
        self.dropped_at: Block | None = None  # the block of the first entry that did not fit
        self._tangent: tuple[float, ...] | None = None  # end tangent of the last element
        self._block: Block | None = None
        self._ordinal = 0  # number of the block being prepared in the run (block_count_r)
        self._loop = 0  # serial of the real-time loop whose passes are being sorted
        self._pending: list[tuple[ContourElement, Block]] | None = None  # pass >= 3
        self._marks: list[ContourCommand] = []  # loop markers not yet bound to a block
        self._bound: deque[tuple[Block | None, list[ContourCommand]]] = deque()

    # ------------------------------------------------------------ state

    @property
    def max_dist_prog_start_01um(self) -> float:
        """Maximum look-ahead distance: the end of the path prepared so far (0.1 um)."""
        return self.distance_01um

    @property
    def active(self) -> bool:
        """``f_log_is_active``: the area is open and not all of its elements are read in."""
        return self.area == LogArea.OPEN and not self.complete

    # ------------------------------------------------------------ prepared path

    def mark(self, command: ContourCommand) -> None:
        """A real-time loop marker from the decoder; it takes effect in path order just
        before the next block handed to the path (``expect``)."""
        self._marks.append(command)

    def expect(self, block: Block | None) -> None:
        """``block`` is handed to the path next (None: the end of the data so far). The
        markers that came before it apply when the path preparation releases its first
        piece: radius compensation may still hold the block before the markers."""
        if self._marks:
            self._bound.append((block, self._marks))
            self._marks = []

    def take(self, items: Iterable[Segment | Block]) -> bool:
        """Watch segments and bare blocks as they enter the look-ahead buffer, in path
        order; True when this made the log overflow for the first time in its area."""
        overflowed = False
        bound = self._bound
        for item in items:
            block = item.block if isinstance(item, Segment) else item
            while bound and bound[0][0] is block:
                overflowed |= self._markers(bound.popleft()[1])
            self._count(block)
            if isinstance(item, Segment):
                overflowed |= self._element(item)
            elif item.contour is not None:
                overflowed |= self._command(item, item.contour.kind, item.contour.param)
        while bound and bound[0][0] is None:  # markers at the end of the data so far
            overflowed |= self._markers(bound.popleft()[1])
        return overflowed

    def count_block(self) -> None:
        """A block that did not enter the look-ahead buffer (axis exchange, LOG CLEAR)
        still has its number in the run."""
        self._block = None
        self._ordinal += 1

    def end_of_data(self) -> bool:
        """All blocks are prepared; True when the last pass of a loop overflowed."""
        self.complete = True
        return self._flush_pending()

    def stop(self) -> None:
        """The run ended early (error, RESET): nothing more will be read in."""
        self.complete = True

    def distance_cleared(self) -> None:
        """The path passed a ``#DISTANCE PROG START CLEAR``."""
        self.executed_epoch += 1

    def clear(self) -> None:
        """LOG CLEAR, reached at standstill: empty the log; the next LOG ON opens a new
        area. The recent elements (mode 2) and the path distance stay."""
        self.log = []
        self.area = LogArea.NONE
        self.full_warned = False
        self._pending = None
        self._loop = 0

    def _count(self, block: Block) -> None:
        if block is not self._block:
            self._block = block
            self._ordinal += 1

    def _number(self, block: Block) -> int:
        return block.number if block.number is not None else -1

    def _element(self, segment: Segment) -> bool:
        element = segment.element
        block = segment.block
        start = self.distance_01um
        self.distance_01um = start + element.length_mm * UM01_PER_MM
        previous, self._tangent = self._tangent, element.tangent_end
        prepared = _Prepared(element, self._number(block), self._ordinal, start, previous)
        if self.log_max:
            self.recent.append((self.epoch, prepared, block))
        if self.area == LogArea.OPEN:
            return self._log(prepared.entry(block), block)
        return False

    def _command(self, block: Block, kind: ContourKind, param: float | None) -> bool:
        if kind == ContourKind.DISTANCE_CLEAR:
            self.distance_01um = 0.0
            self.epoch += 1
            return False
        if kind == ContourKind.LOG_CLEAR:  # normally applied at standstill by the channel
            self.clear()
            return False
        before = self.area
        self.area = next_log_area(before, kind)
        entry = ContourElement(
            int(kind), self._number(block), self._ordinal, self.distance_01um,
            0.0 if param is None else param, 0.0, 0.0, 0.0, 0.0, 0.0,
        )
        if kind == ContourKind.LOG_ON:
            return self._log(entry, block) if before == LogArea.NONE else False
        if before != LogArea.OPEN:
            return False  # PARAM or OFF outside the area
        if kind == ContourKind.LOG_OFF:
            overflowed = self._flush_pending()
            return self._log(entry, block) or overflowed
        return self._log(entry, block)

    def _markers(self, commands: list[ContourCommand]) -> bool:
        overflowed = False
        for command in commands:
            if command.kind == ContourKind.RT_END:
                overflowed |= self._flush_pending()
            elif self.area == LogArea.OPEN:
                overflowed |= self._rt_pass(command)
        return overflowed

    def _rt_pass(self, command: ContourCommand) -> bool:
        overflowed = False
        if command.rt_pass == 1 or command.loop != self._loop:
            # a new loop: what is pending was the last pass of the one before
            overflowed = self._flush_pending()
            self._loop = command.loop
        if command.rt_pass >= 3:
            self._pending = []  # the pass before it repeated the loop-to-loop transition
        return overflowed

    def _flush_pending(self) -> bool:
        pending, self._pending = self._pending, None
        overflowed = False
        for entry, block in pending or ():
            overflowed |= self._log(entry, block)
        return overflowed

    def _log(self, entry: ContourElement, block: Block) -> bool:
        if self._pending is not None:
            self._pending.append((entry, block))
            return False
        if len(self.log) < self.log_max:
            self.log.append(entry)
            return False
        if self.full_warned:
            return False
        self.full_warned = True
        self.dropped_at = block
        return True

    # ------------------------------------------------------------ requests

    def answer(self, start_position: float, length: float) -> tuple[ContourElement, ...]:
        """The reply to a request: mode 1 (``length`` 0) the log from index
        ``start_position`` on; mode 2 the recent elements whose start lies in
        [start_position, start_position + length] (0.1 um), counted in the distances
        ``dist_prog_start`` shows now. At most RESPONSE_BLOCKS. The request was checked
        when the semaphore was set (``check_request``)."""
        if length == 0.0:
            index = int(start_position)
            return tuple(self.log[index:index + RESPONSE_BLOCKS])
        low = start_position - _WINDOW_TOLERANCE_INCR
        high = start_position + length + _WINDOW_TOLERANCE_INCR
        epoch = self.executed_epoch
        found = [(e, block) for k, e, block in self.recent
                 if k == epoch and low <= e.start_position <= high]
        return tuple(e.entry(block) for e, block in found[:RESPONSE_BLOCKS])


def check_request(start_position: float, length: float) -> None:
    """Raise RequestError for a request no CNC could answer."""
    if not (math.isfinite(start_position) and math.isfinite(length)):
        raise RequestError("request.start_position and request.length must be finite numbers")
    if length == 0.0:
        if start_position < 0 or start_position != int(start_position):
            raise RequestError(
                f"mode 1 (length 0) needs an element index >= 0 in start_position, "
                f"not {start_position:g}"
            )
    elif length < 0.0:
        raise RequestError(
            f"mode 2 needs a positive length (0.1 um), not {length:g}; length 0 is mode 1"
        )
