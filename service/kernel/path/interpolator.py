"""Interpolation: one fixed cycle at a time along the planned segments.

Each cycle the path moves for ``cycle_s`` of time on the fastest profile the plan
allows, integrated in closed form (``advance``): within a segment the speed follows
constant-acceleration pieces (accelerate with the segment's a, cruise at its cap with
the override applied, brake with a so that the planned exit speed is met exactly at
the segment end). When a segment end is reached before the cycle is over, the rest of
the cycle continues in the next segment, so any number of segment (and block) ends can
be passed in one cycle. Stops land exactly on the segment end: the braking piece ends
there at speed 0, the rest of the cycle is spent standing (or dwelling).

Speed is never raised by more than a * time and never lowered faster than a * time
(feed override reductions, feedhold); the planned exit speed of the current segment
already carries every later constraint in the buffer (backward pass).

At a segment end the blocks ending there are processed in order: a dwell stands for
``dwell_s`` (time of the same cycle counts), a programmed stop (M0/M1/M2/M30) waits for
``resume``, single block waits for ``resume``; other blocks are finished at once. A block
with ``#DISTANCE PROG START CLEAR`` restarts the path distance where it ends.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from enum import IntEnum

from ..nc.blocks import Block, ContourKind, StopKind
from .planner import LookAhead
from .profile import advance
from .segments import Segment


class Waiting(IntEnum):
    """What the path is waiting for at a block end."""

    NONE = 0  # running (or standing for lack of blocks, override 0, feedhold)
    DWELL = 1  # dwell time of a block running
    PROGRAMMED_STOP = 2  # M0/M1/M2/M30 reached: waiting for resume()
    SINGLE_BLOCK = 3  # single block: waiting for resume() at a block end
    TECHNOLOGY = 4  # M/S/T functions: waiting for release_technology()


@dataclass(slots=True)
class StepResult:
    """Outcome of one interpolation cycle."""

    position_mm: tuple[float, ...]  # command position of every channel axis after this cycle
    path_velocity_mm_s: float  # actual path speed at the end of the cycle
    programmed_velocity_mm_s: float  # F of the current element (axis limit for G0; 0 idle)
    finished: list[Block]  # blocks whose end was passed this cycle, in order
    current: Block | None  # block being executed (None when idle)
    remaining_in_block_mm: float  # path length left in the current block
    distance_mm: float  # path length covered since program start (compensated path)
    stopped_at: Block | None  # standing at a block with a programmed stop, waiting


class Interpolator:
    """Cycle-by-cycle motion along the look-ahead buffer, with dwell, stops and holds."""

    def __init__(self, planner: LookAhead, cycle_s: float, start_mm: tuple[float, ...]) -> None:
        self.planner = planner
        self.cycle_s = cycle_s
        self.seg: Segment | None = None  # segment being run (the planner's head)
        self.s_mm = 0.0  # position within it
        self.v_mm_s = 0.0  # path speed
        self.position_mm = start_mm
        self.events: deque[tuple[Block, bool]] = deque()  # block ends due here (block, single stop)
        self.waiting = Waiting.NONE
        self.wait_block: Block | None = None  # block dwelling or waited at
        self.dwell_left_s = 0.0
        self.dwell_single = False
        self.techno_single = False  # a single-block stop follows the technology wait
        # ids of TECHNOLOGY blocks acknowledged before the path reached them (MVS_SNS)
        self.released_stops: set[int] = set()
        self.hold = False
        self.override = 1.0
        self.unfinished = 0  # blocks handed over and not yet finished
        self.distance_base_mm = 0.0  # path length up to the start of ``seg``
        # the last ``cruise_budget``: (cycles, segment, s, v before, s, v after them)
        self._counted: tuple[int, Segment, float, float, float, float] | None = None

    # -- commands ---------------------------------------------------------------------

    def set_override(self, override: float) -> None:
        """Apply a new feed override factor (>= 0) and re-plan."""
        self.override = override
        self.planner.set_override(override if override >= 0.0 else 0.0)

    def resume(self) -> None:
        """Release feedhold and continue after a programmed or single-block stop."""
        self.hold = False
        if self.waiting in (Waiting.PROGRAMMED_STOP, Waiting.SINGLE_BLOCK):
            self.waiting = Waiting.NONE
            self.wait_block = None

    def release_technology(self) -> None:
        """The technology functions the path waits for are acknowledged: go on."""
        if self.waiting == Waiting.TECHNOLOGY:
            if self.techno_single:  # single block: the stop at the block end comes next
                self.waiting = Waiting.SINGLE_BLOCK
                return
            self.waiting = Waiting.NONE
            self.wait_block = None

    def set_single_block(self, on: bool) -> None:
        """Switch single block: stop at the first block end that can still be reached
        standing (braking with every segment's acceleration), and at every later one."""
        self.events = deque((b, on) for b, _ in self.events)
        self.dwell_single = on
        first = self._first_stoppable() if on else None
        if on and first is None and self.seg is not None:
            return  # no block end in the buffer yet: new segments get the flag
        self.planner.set_single_block(first)

    def _first_stoppable(self) -> Segment | None:
        self.planner.update()
        seg = self.seg
        if seg is None:
            return None
        v2 = self.v_mm_s * self.v_mm_s - 2.0 * seg.acc_mm_s2 * (seg.length_mm - self.s_mm)
        tolerance = 1e-9 * (self.v_mm_s * self.v_mm_s + 1.0)
        while seg is not None:
            if seg.events and v2 <= tolerance:
                return seg
            seg = seg.next
            if seg is not None:
                v2 -= seg.two_acc_len  # braking with the next segment's acceleration
        return None

    def stop_now(self) -> None:
        """Drop everything, stand still where the path is."""
        self.planner.clear()
        self.distance_base_mm += self.s_mm
        self.seg = None
        self.s_mm = self.v_mm_s = 0.0
        self.events.clear()
        self.released_stops.clear()
        self.waiting = Waiting.NONE
        self.wait_block = None
        self.dwell_left_s = 0.0
        self.hold = False
        self.unfinished = 0

    @property
    def idle(self) -> bool:
        """Nothing to run, nothing to wait for, standing."""
        return (self.seg is None and not self.events and self.waiting == Waiting.NONE
                and self.unfinished == 0)

    # -- the cycle --------------------------------------------------------------------

    def step(self, override: float) -> StepResult:
        """One cycle: move, pass block ends, report."""
        if override != self.override:
            self.set_override(override)
        if self.planner.dirty:
            self.planner.update()
        seg = self.seg
        if seg is None or self.waiting or self.events:
            return self._step(None)
        moved = self._in_segment(seg, self.s_mm, self.v_mm_s)
        if not moved[0] < seg.length_mm:  # the segment ends in this cycle
            return self._step(moved)
        self.s_mm, self.v_mm_s = moved[0], moved[1]
        return self._inside(seg)

    def _in_segment(self, seg: Segment, s: float, v: float) -> tuple[float, float, float]:
        """The in-segment cycle, the one function ``step`` and ``cruise`` both run: from
        ``s`` at speed ``v``, one cycle on ``seg`` (cruising at its cap while the
        braking point is ahead, else ``advance``'s closed form: accelerate, brake, stand
        in feedhold). Returns (s, v, time left): inside the segment while s < its length;
        else ``_step`` goes on from there with the time left, through the segment end."""
        t = self.cycle_s
        hold = self.hold
        if not hold and v == seg.cap_mm_s:  # cruising: the common case, kept short
            ex = seg.exit_mm_s
            s_next = s + v * t
            if s_next < seg.length_mm - (v * v - ex * ex) * seg.inv_2acc:
                return s_next, v, 0.0
        return advance(seg.length_mm, seg.acc_mm_s2, 0.0 if hold else seg.cap_mm_s,
                       seg.exit_mm_s, s, v, t)

    def _inside(self, seg: Segment) -> StepResult:
        """The report of a cycle that ended inside ``seg`` (no block end passed)."""
        s = self.s_mm
        pos = self.position_mm = seg.point_at(s)
        return StepResult(pos, self.v_mm_s, seg.programmed_mm_s, [], seg.block,
                          seg.length_mm - s + seg.block_rest_mm, self.distance_base_mm + s,
                          None)

    def cruise_budget(self, override: float, most: int,
                      accept: Callable[[float, float], bool] | None = None) -> int:
        """How many of the next cycles (at most ``most``) ``step(override)`` would end
        inside the current segment with no block end due: cruising, accelerating,
        braking or standing in feedhold. ``accept(s_mm, v_mm_s)``, when given, is asked
        after each cycle that ends below the segment's cap; the first cycle it refuses is
        not counted (the caller has work to do there). 0 when the next cycle is anything
        else."""
        seg = self.seg
        if (seg is None or override != self.override or self.planner.dirty
                or self.waiting or self.events):
            return 0
        return self._cruise(seg, most, accept, apply=False)

    def cruise(self, cycles: int) -> StepResult:
        """Run ``cycles`` cycles that ``cruise_budget`` allowed, in one call, and report
        the last: the same float operations in the same order as ``step`` cycle by
        cycle (the path length is summed cycle by cycle), so the result is bit for bit
        the same."""
        seg = self.seg
        assert seg is not None
        counted = self._counted
        if counted is not None and counted[0] == cycles and counted[1] is seg and (
                counted[2] == self.s_mm and counted[3] == self.v_mm_s):
            self.s_mm, self.v_mm_s = counted[4], counted[5]  # what the budget computed
        else:
            assert self._cruise(seg, cycles, None, apply=True) == cycles
        self._counted = None
        return self._inside(seg)

    def _cruise(self, seg: Segment, most: int, accept: Callable[[float, float], bool] | None,
                apply: bool) -> int:
        """Up to ``most`` in-segment cycles (``_in_segment``, as ``step`` runs them) from
        the current state; stops before the first that would reach the segment end or
        that ``accept`` refuses."""
        s, v = self.s_mm, self.v_mm_s
        length, cap_mm_s = seg.length_mm, seg.cap_mm_s
        n = 0
        while n < most:
            s_next, v_next, _left = self._in_segment(seg, s, v)
            if not s_next < length or (accept is not None and v_next < cap_mm_s
                                       and not accept(s_next, v_next)):
                break
            s, v = s_next, v_next
            n += 1
        if apply:
            self.s_mm, self.v_mm_s = s, v
        else:  # ``cruise`` of the same cycles from the same state takes this over
            self._counted = (n, seg, self.s_mm, self.v_mm_s, s, v)
        return n

    def _step(self, moved: tuple[float, float, float] | None) -> StepResult:
        """A cycle that passes block ends (or waits, or stands without a segment);
        ``moved``: its first piece in the current segment, already computed by
        ``_in_segment`` (None: none yet)."""
        finished: list[Block] = []
        t = self.cycle_s
        while True:
            if self.events or self.waiting:
                t = self._block_ends(t, finished)
                if self.waiting:
                    break
            seg = self.seg
            if seg is None or t <= 0.0:
                break
            if moved is not None:
                s, v, t = moved
                moved = None
            else:
                cap = 0.0 if self.hold else seg.cap_mm_s
                s, v, t = advance(seg.length_mm, seg.acc_mm_s2, cap, seg.exit_mm_s,
                                  self.s_mm, self.v_mm_s, t)
            self.s_mm, self.v_mm_s = s, v
            if s < seg.length_mm:
                break
            # segment end reached: its block ends become due, continue in the next one
            self.distance_base_mm += seg.length_mm
            self.position_mm = seg.element.end_mm
            if seg.events:
                single = seg.single_stop
                self.events.extend((b, single) for b in seg.events)
            self.seg = self.planner.pop_head()
            self.s_mm = 0.0
        seg = self.seg
        self.unfinished -= len(finished)
        stopped_at = None
        if self.waiting:
            current = self.wait_block
            if self.waiting == Waiting.PROGRAMMED_STOP:
                stopped_at = current
        else:
            current = seg.block if seg is not None else None
        if seg is None:
            self.v_mm_s = 0.0
            return StepResult(self.position_mm, 0.0, 0.0, finished, current, 0.0,
                              self.distance_base_mm, stopped_at)
        s = self.s_mm
        pos = self.position_mm = seg.point_at(s)
        return StepResult(pos, self.v_mm_s, seg.programmed_mm_s, finished, current,
                          seg.length_mm - s + seg.block_rest_mm if not self.waiting else 0.0,
                          self.distance_base_mm + s, stopped_at)

    def _block_ends(self, t: float, finished: list[Block]) -> float:
        """Process due block ends with ``t`` s of the cycle left; returns the time left
        (0 while dwelling or waiting)."""
        while True:
            waiting = self.waiting
            if waiting == Waiting.DWELL:
                if self.dwell_left_s > t:
                    self.dwell_left_s -= t
                    return 0.0
                t -= self.dwell_left_s
                self.dwell_left_s = 0.0
                self.waiting = Waiting.NONE
                block, self.wait_block = self.wait_block, None
                assert block is not None  # DWELL is entered with its block (below)
                if self._finish(block, self.dwell_single, finished):
                    return 0.0
                continue
            if waiting:
                return 0.0
            if not self.events:
                return t
            block, single = self.events.popleft()
            if block.dwell_s > 0.0:
                self.waiting = Waiting.DWELL
                self.wait_block = block
                self.dwell_left_s = block.dwell_s
                self.dwell_single = single
                continue
            if self._finish(block, single, finished):
                return 0.0

    def _finish(self, block: Block, single: bool, finished: list[Block]) -> bool:
        finished.append(block)
        contour = block.contour
        if contour is not None and contour.kind == ContourKind.DISTANCE_CLEAR:
            self.distance_base_mm = -self.s_mm  # the path distance restarts here
        if block.stop == StopKind.TECHNOLOGY and id(block) in self.released_stops:
            self.released_stops.discard(id(block))  # acknowledged in time: no stop
            if not single:
                return False
            self.waiting = Waiting.SINGLE_BLOCK
        elif block.stop == StopKind.TECHNOLOGY:
            self.waiting = Waiting.TECHNOLOGY
            self.techno_single = single
        elif block.stop != StopKind.NONE:
            self.waiting = Waiting.PROGRAMMED_STOP
        elif single:
            self.waiting = Waiting.SINGLE_BLOCK
        else:
            return False
        self.wait_block = block
        return True
