"""Velocity planning over the look-ahead buffer.

The model (exactly this; ``plan_profile`` computes it in closed form):

Element limits (``limits.element_limits``), with programmed feed F (G0: F = inf) and
the axes' limits V_i (velocity), A_i (acceleration):

* line, unit direction u: speed v_max = min(F, min_i V_i/|u_i|), acceleration
  a = min_i A_i/|u_i|, both over the axes with u_i != 0;
* arc in the plane of axes (p, q), radius R: a = min(A_p, A_q)/sqrt(2) (for the
  tangential and for the normal acceleration), v_max = min(F, V_p, V_q, sqrt(R * a)).

Feed override k scales the feed part only: cap = min(v_max(F) * k, axis limit), so an
override above 100 % never exceeds an axis limit. Plans are made for the current
override and re-made when it changes.

Junction of element j with element j+1, tangents u_in (end of j) and u_out (start of
j+1): v_junction = min(min_i dV_i/|u_out,i - u_in,i| over axes whose component
changes, cap_j, cap_j+1), where dV_i is the axis' permitted velocity jump. The speed is
0 at the start of the program, at the end of the last buffered element (the look-ahead
assumes a stop after it), at the end of a block that needs a stop (M0/M1/M2/M30,
dwell) and, with single block, at the end of every block.

Profile: every element is a trapezoid in time: accelerate with the element's a from
its entry speed, cruise at its cap, decelerate with a to its exit speed (or a
triangle when the element is too short to reach the cap).

Passes:

* backward, from the last element to the first: exit_j = min(v_junction_j, entry_j+1)
  (0 for the last), entry_j = min(cap_j, sqrt(exit_j^2 + 2 a_j L_j)): the highest
  speeds from which every later constraint can still be met by braking;
* forward, from the first element: in_j = out_j-1 (0 at the start), out_j =
  min(exit_j, sqrt(in_j^2 + 2 a_j L_j)): what accelerating can actually reach.

Streaming (``LookAhead``): arriving elements are appended; before the next cycle the
backward pass runs from the last element towards the head, through every element not
planned yet, and stops at the first planned element whose exit speed does not change
(everything before it is unchanged). For a long program of short elements it touches
only the elements within the stopping distance of the buffer's end. A new override
or a single-block switch re-plans the whole buffer. The forward pass is not stored
while streaming: the interpolator realises it cycle by cycle (it accelerates with a
from the actual speed, which is the forward pass), and ``forward`` computes it on
demand. ``plan_profile`` runs both passes over a whole program at once (unbounded
buffer): the reference for the benchmark.

Machining time of an element: with peak^2 = a L + (in^2 + out^2)/2, a triangle takes
(2 peak - in - out)/a if peak <= cap, else the trapezoid takes
(2 cap - in - out)/a + (L - (2 cap^2 - in^2 - out^2)/(2 a))/cap.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Iterator, Sequence
from dataclasses import dataclass

from ..nc.blocks import Block
from .limits import AxisDynamics, corner_limit_mm_s
from .segments import PathPreparation, Segment


class LookAhead:
    """The look-ahead buffer of segments (a linked list) and its backward pass.

    ``append`` only links the new segment and computes its junction with the previous
    one; the backward pass runs in ``update`` (the interpolator calls it at the start of
    a cycle when something was appended), so several blocks pushed in one cycle cost
    one pass. Segments never planned yet are always passed through; the pass stops at
    the first planned segment whose exit speed stays the same.
    """

    def __init__(self, vel_jump_mm_s: Sequence[float]) -> None:
        self.vel_jump_mm_s = tuple(vel_jump_mm_s)
        self.head: Segment | None = None
        self.tail: Segment | None = None
        self.override = 1.0
        self.rapid_override = 1.0  # the factor G0 segments take instead (P-CHAN-00181)
        self.dirty = False  # segments appended since the last backward pass

    def __iter__(self) -> Iterator[Segment]:
        seg = self.head
        while seg is not None:
            yield seg
            seg = seg.next

    def _cap(self, seg: Segment) -> float:
        cap = seg.speed_mm_s * (self.rapid_override if seg.rapid else self.override)
        return cap if cap < seg.axis_speed_mm_s else seg.axis_speed_mm_s

    def _junction(self, seg: Segment) -> None:
        if seg.stop or seg.single_stop:
            seg.junction_mm_s = 0.0
        elif seg.next is not None:
            seg.junction_mm_s = min(seg.corner_mm_s, seg.cap_mm_s)
        elif seg.la_exit_mm_s > 0.0:
            # the buffer's end inside a planned LA_ON section: the section's plan
            # guarantees a stop is reachable from this speed (scaled like the caps by
            # an override below 100 %; above it the caps only grow)
            scale = self.override if self.override < 1.0 else 1.0
            seg.junction_mm_s = min(seg.la_exit_mm_s * scale, seg.cap_mm_s)
        else:
            seg.junction_mm_s = 0.0

    def append(self, seg: Segment) -> None:
        """Append ``seg`` behind the last segment (planned at the next ``update``)."""
        seg.cap_mm_s = self._cap(seg)
        seg.junction_mm_s = seg.exit_mm_s = 0.0
        entry = math.sqrt(seg.two_acc_len)
        seg.entry_mm_s = entry if entry < seg.cap_mm_s else seg.cap_mm_s
        seg.planned = False
        tail = self.tail
        self.tail = seg
        self.dirty = True
        if seg.la_exit_mm_s > 0.0:
            self._junction(seg)  # the buffer's end inside an LA_ON section
        if tail is None:
            self.head = seg
            return
        tail.next = seg
        seg.prev = tail
        corner = corner_limit_mm_s(tail.tangent_end, seg.tangent_start, self.vel_jump_mm_s)
        if seg.vfbt and tail.vfbt and corner != math.inf:  # a transition inside LA_ON
            corner *= seg.vfbt
        tail.corner_mm_s = corner
        self._junction(tail)

    def update(self) -> None:
        """Run the pending backward pass (after ``append``)."""
        if self.dirty:
            self.dirty = False
            if self.tail is not None:
                self.backward(self.tail)

    def pop_head(self) -> Segment | None:
        """Drop the first segment (the interpolator passed it); returns the new first."""
        seg = self.head
        if seg is None:
            return None
        nxt = seg.next
        seg.next = None
        self.head = nxt
        if nxt is None:
            self.tail = None
        else:
            nxt.prev = None
        return nxt

    def clear(self) -> None:
        """Drop every segment."""
        self.head = self.tail = None
        self.dirty = False

    def mark_stop(self, seg: Segment, *, single: bool = False) -> None:
        """Speed 0 at the end of ``seg`` (a block needing a stop, or single block)."""
        if single:
            seg.single_stop = True
        else:
            seg.stop = True
        self._junction(seg)
        self.update()
        seg.planned = False
        self.backward(seg)

    def release(self, seg: Segment) -> None:
        """``seg.stop`` was cleared: its junction and the plan up to it again."""
        self._junction(seg)
        self.replan()

    def set_override(self, override: float) -> None:
        """New feed override: new caps everywhere, full backward pass."""
        self.override = override
        for seg in self:
            seg.cap_mm_s = self._cap(seg)
            self._junction(seg)
        self.replan()

    def set_rapid_override(self, override: float) -> None:
        """New rapid override (the factor of G0 segments): new caps, full backward pass."""
        self.rapid_override = override
        for seg in self:
            seg.cap_mm_s = self._cap(seg)
            self._junction(seg)
        self.replan()

    def set_single_block(self, first: Segment | None) -> None:
        """Single-block stops at every block end from ``first`` on (None: none at all)."""
        flag = False
        for seg in self:
            flag = flag or seg is first
            seg.single_stop = flag and bool(seg.events)
            self._junction(seg)
        self.replan()

    def replan(self) -> None:
        """Full backward pass over the whole buffer."""
        for seg in self:
            seg.planned = False
        self.dirty = False
        if self.tail is not None:
            self.backward(self.tail)

    def backward(self, last: Segment) -> None:
        """Backward pass from ``last`` towards the head.

        exit = min(junction, entry of the next), entry = min(cap, sqrt(exit^2 + 2 a L)).
        Stops at the first planned segment whose exit speed stays the same.
        """
        sqrt = math.sqrt
        # the last segment's junction is its exit limit (0, or an LA_ON section's plan)
        nxt_entry = last.next.entry_mm_s if last.next is not None else math.inf
        seg: Segment | None = last
        while seg is not None:
            exit_ = seg.junction_mm_s
            if nxt_entry < exit_:
                exit_ = nxt_entry
            if exit_ == seg.exit_mm_s and seg.planned:
                return
            seg.planned = True
            seg.exit_mm_s = exit_
            entry = sqrt(exit_ * exit_ + seg.two_acc_len)
            if entry > seg.cap_mm_s:
                entry = seg.cap_mm_s
            seg.entry_mm_s = nxt_entry = entry
            seg = seg.prev

    def forward(self, entry_mm_s: float) -> list[tuple[Segment, float, float]]:
        """Forward pass from the head entered at ``entry_mm_s``: (segment, in, out) each."""
        self.update()
        out = []
        v = entry_mm_s
        for seg in self:
            v_out = min(seg.exit_mm_s, math.sqrt(v * v + seg.two_acc_len))
            out.append((seg, v, v_out))
            v = v_out
        return out


def trapezoid(length_mm: float, acc_mm_s2: float, cap_mm_s: float, v_in: float,
              v_out: float) -> tuple[float, float]:
    """(peak speed, time) of the fastest profile over one element, closed form.

    Accelerate with ``acc_mm_s2`` from ``v_in``, cruise at ``cap_mm_s``, decelerate to
    ``v_out``; a triangle when the cap is not reached. ``v_in``/``v_out`` must be
    mutually reachable over ``length_mm`` (the passes guarantee it).
    """
    a = acc_mm_s2
    peak2 = a * length_mm + 0.5 * (v_in * v_in + v_out * v_out)
    if peak2 <= cap_mm_s * cap_mm_s:
        peak = math.sqrt(peak2)
        return peak, (2.0 * peak - v_in - v_out) / a
    cruise_mm = length_mm - (2.0 * cap_mm_s * cap_mm_s - v_in * v_in - v_out * v_out) / (2.0 * a)
    return cap_mm_s, (2.0 * cap_mm_s - v_in - v_out) / a + max(cruise_mm, 0.0) / cap_mm_s


@dataclass(frozen=True, slots=True)
class PlannedElement:
    """One element of a whole-program plan."""

    block: Block
    length_mm: float
    entry_mm_s: float
    peak_mm_s: float
    exit_mm_s: float
    time_s: float


def plan_profile(blocks: Iterable[Block], dynamics: Sequence[AxisDynamics],
                 start_mm: Sequence[float] | None = None) -> list[PlannedElement]:
    """Plan a whole program at once (unbounded look-ahead, override 100 %).

    Runs the same preparation as the executor (compensation included), then one
    backward and one forward pass over all elements.
    """
    blocks = list(blocks)
    if start_mm is None:
        first = next((b.motion for b in blocks if b.motion is not None), None)
        start_mm = first.start_mm if first is not None else (0.0,) * len(dynamics)
    prep = PathPreparation(dynamics, start_mm)
    items: list[Segment | Block] = []
    for block in blocks:
        items.extend(prep.prepare(block))
    items.extend(prep.flush())
    segs: list[Segment] = []
    for item in items:
        if isinstance(item, Segment):
            segs.append(item)
        elif item.needs_stop and segs:
            segs[-1].stop = True
    jumps = [d.vel_jump_mm_s for d in dynamics]
    n = len(segs)
    exits = [0.0] * n
    entries = [0.0] * n
    for j in range(n - 1, -1, -1):  # backward
        seg = segs[j]
        if j == n - 1 or seg.stop:
            exit_ = 0.0
        else:
            corner = corner_limit_mm_s(seg.tangent_end, segs[j + 1].tangent_start, jumps)
            exit_ = min(corner, seg.speed_mm_s, segs[j + 1].speed_mm_s, entries[j + 1])
        exits[j] = exit_
        entries[j] = min(seg.speed_mm_s, math.sqrt(exit_ * exit_ + seg.two_acc_len))
    plan = []
    v = 0.0
    for j, seg in enumerate(segs):  # forward
        v_out = min(exits[j], math.sqrt(v * v + seg.two_acc_len))
        peak, time_s = trapezoid(seg.length_mm, seg.acc_mm_s2, seg.speed_mm_s, v, v_out)
        plan.append(PlannedElement(seg.block, seg.length_mm, v, peak, v_out, time_s))
        v = v_out
    return plan


def plan_time_optimal(blocks: Iterable[Block], dynamics: Sequence[AxisDynamics],
                      start_mm: Sequence[float] | None = None) -> float:
    """Machining time (s) of the whole-program plan: sum of the closed-form element
    times plus every dwell. Waiting at M0/M1 is not counted."""
    blocks = list(blocks)
    plan = plan_profile(blocks, dynamics, start_mm)
    return math.fsum(p.time_s for p in plan) + math.fsum(b.dwell_s for b in blocks)
