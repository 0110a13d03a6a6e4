"""Marker Blocks at the passes of a real-time loop inside the contour look-ahead's area.

ISG logs the body of a ``#RT WHILE`` loop three times (start of loop, loop to loop, end
of loop) when the loop starts inside an open marked area (``#CONTOUR LOOKAHEAD LOG
ON``). The decoder unrolls such loops, so it tells the kernel where the passes are:
RT_PASS before each pass, RT_END after the last one (``ContourCommand`` Blocks without
motion, at the ``#RT WHILE``). Only the outermost such loop is tracked; a loop entered
while the area is not open never gets markers, so a program without the contour
look-ahead gives the blocks it always gave. ``control.ControlFlow`` reports the loop
events; the markers do not count for its endless-loop guard (``contour.LOOP_MARKERS``).
"""

from __future__ import annotations

from dataclasses import dataclass

from .blocks import Block, ContourCommand, ContourKind, LogArea
from .call_stack import CallFrame, ControlEntry
from .contour_run import contour_block
from .running_decoder import RunningDecoder
from .statements import Control


@dataclass(slots=True)
class _Tracked:
    """The real-time loop that gets markers: where it runs and how far it is."""

    frame: CallFrame
    entry: ControlEntry  # its open control entry (a new one each pass)
    serial: int
    rt_pass: int


class RtLoopMarkers:
    """Marker Blocks at the passes of the real-time loop entered in an open marked area.

    ``ControlFlow`` reports every test of a ``#RT WHILE`` condition (``tested``), every
    ``#RT ENDWHILE`` (``closed``: the next test of that loop is a re-test) and the
    entries a ``$BREAK`` leaves (``broken``). A loop is tracked when it is entered (first
    test, not a re-test) with a true condition while ``contour_log_area`` is OPEN and no
    other loop is tracked: RT_PASS 1. Each true re-test gives RT_PASS n+1, a false one
    RT_END. A ``$BREAK`` out of the tracked loop gives RT_END. A ``$GOTO`` (or an M17)
    out of it gives no marker: the loop simply stops being tracked.
    """

    def __init__(self, decoder: RunningDecoder) -> None:
        self.decoder = decoder
        self.serial = 0  # serial number of the last tracked loop (per decoder)
        self.tracked: _Tracked | None = None
        self._closed: tuple[CallFrame, ControlEntry] | None = None  # the last #RT ENDWHILE

    def closed(self, frame: CallFrame, entry: ControlEntry) -> None:
        """``#RT ENDWHILE`` closed ``entry``: its loop tests its condition next."""
        self._closed = (frame, entry)

    def tested(self, frame: CallFrame, stmt: Control, index: int,
               entry: ControlEntry | None) -> Block | None:
        """The ``#RT WHILE`` ``stmt`` at line ``index`` was tested: ``entry`` is its new
        control entry (None: the condition was false). The marker, if any."""
        closed, self._closed = self._closed, None
        retest = closed is not None and closed[0] is frame and closed[1].index == index
        tracked = self.tracked
        if closed is not None and retest:
            if tracked is None or tracked.entry is not closed[1]:
                return None  # an untracked loop (or one nested in the tracked one)
            if entry is None:
                self.tracked = None
                return self._marker(stmt, ContourCommand(ContourKind.RT_END, loop=tracked.serial))
            tracked.entry = entry
            tracked.rt_pass += 1
            return self._pass(stmt, tracked)
        if (entry is None or self.decoder.modal.contour_log_area != LogArea.OPEN
                or self._alive()):
            return None
        self.serial += 1
        self.tracked = _Tracked(frame, entry, self.serial, 1)
        return self._pass(stmt, self.tracked)

    def broken(self, frame: CallFrame, left: list[ControlEntry]) -> Block | None:
        """A ``$BREAK`` left the control entries ``left`` of ``frame``: RT_END when the
        tracked loop is among them."""
        tracked = self.tracked
        if tracked is None or tracked.frame is not frame:
            return None
        if not any(e is tracked.entry for e in left):
            return None
        self.tracked = None
        return self._marker(tracked.entry.stmt,
                            ContourCommand(ContourKind.RT_END, loop=tracked.serial))

    def _alive(self) -> bool:
        """True while the tracked loop is open; forgets it once a $GOTO or a subprogram
        end has left it."""
        tracked = self.tracked
        if tracked is None:
            return False
        alive = (any(f is tracked.frame for f in self.decoder.frames)
                 and any(e is tracked.entry for e in tracked.frame.control))
        if not alive:
            self.tracked = None
        return alive

    def _pass(self, stmt: Control, tracked: _Tracked) -> Block:
        return self._marker(stmt, ContourCommand(ContourKind.RT_PASS, loop=tracked.serial,
                                                 rt_pass=tracked.rt_pass))

    def _marker(self, stmt: Control, command: ContourCommand) -> Block:
        return contour_block(stmt.line, stmt.pos, stmt.number, self.decoder.manual, command)
