"""The façade the GEO cycle calls: blocks in (``push``), one cycle out (``step``).

``PathExecutor`` wires path preparation (validation, tool radius compensation,
software limits), the look-ahead planner and the interpolator together and keeps the
block accounting of the look-ahead buffer:

* ``buffer_blocks`` is the look-ahead size in blocks (30 / 120 / 190 or any other);
  a block occupies a slot from ``push`` until it is reported in ``StepResult.finished``
  (held back by radius compensation included). Every block is reported exactly once.
* The look-ahead always assumes a stop after the last buffered element, so the path
  decelerates in time when blocks do not arrive fast enough; ``close`` only releases
  what radius compensation holds back (end of data).
* ``idle`` is true when no block is buffered and the path stands, waiting for nothing.
  After M2/M30 the path waits like after M0 (``stopped_at`` reports it) until
  ``resume()`` or ``stop_now()``.
* A ``PathError`` from ``push`` refuses that block only (its motion never starts);
  everything buffered before keeps running. A software limit or compensation error of
  a block held back by compensation can surface at the next ``push`` (or ``close``);
  the error then names the held block.
* Feedhold during a dwell lets the dwell time run; the motion after it waits.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

from ..nc.blocks import Block
from .errors import PathError, PathErrorId
from .interpolator import Interpolator, StepResult, Waiting
from .limits import AxisDynamics
from .planner import LookAhead, plan_time_optimal
from .segments import PathPreparation, Segment

_ON_BRAKING_CURVE = 0.98  # share of the braking reach that counts as "on the curve"

__all__ = ["AxisDynamics", "PathError", "PathErrorId", "PathExecutor", "StepResult",
           "Waiting", "plan_time_optimal"]


class PathExecutor:
    """Path preparation, look-ahead and interpolation of one channel."""

    def __init__(self, dynamics: Sequence[AxisDynamics], start_mm: Sequence[float], *,
                 cycle_s: float, buffer_blocks: int = 120,
                 sw_limits_mm: Sequence[tuple[float, float]] | None = None) -> None:
        dynamics = tuple(dynamics)
        start = tuple(float(x) for x in start_mm)
        if not dynamics or len(start) != len(dynamics):
            raise ValueError("start_mm needs one value per axis of dynamics")
        if not cycle_s > 0.0:
            raise ValueError(f"cycle_s must be > 0, not {cycle_s}")
        if buffer_blocks < 1:
            raise ValueError(f"buffer_blocks must be >= 1, not {buffer_blocks}")
        if sw_limits_mm is not None and len(sw_limits_mm) != len(dynamics):
            raise ValueError("sw_limits_mm needs one (min, max) per axis")
        self.dynamics = dynamics
        self.cycle_s = float(cycle_s)
        self.buffer_blocks = int(buffer_blocks)
        self._prep = PathPreparation(dynamics, start, sw_limits_mm)
        self._planner = LookAhead([d.vel_jump_mm_s for d in dynamics])
        self._ipo = Interpolator(self._planner, self.cycle_s, start)
        self._single_block = False
        self._closed = False
        # sees every segment and bare block as it enters the buffer (contour look-ahead)
        self.on_prepared: Callable[[list[Segment | Block]], None] | None = None

    # -- blocks in --------------------------------------------------------------------

    def free_slots(self) -> int:
        """How many more blocks ``push`` accepts now."""
        return max(self.buffer_blocks - self._ipo.unfinished, 0)

    def push(self, block: Block) -> None:
        """Append a block; PathError refuses it (nothing of it will move)."""
        if self._ipo.unfinished >= self.buffer_blocks:
            raise PathError(PathErrorId.BUFFER_FULL,
                            f"look-ahead buffer of {self.buffer_blocks} blocks is full", block)
        items = self._prep.prepare(block)
        self._ipo.unfinished += 1
        self._closed = False
        self._take(items)

    def close(self) -> None:
        """End of data: release what compensation holds back; the path stops at the end."""
        self._closed = True
        try:
            items = self._prep.flush()
        except PathError:
            dropped = self._prep.holding
            self._prep.compensator.restore(None)
            self._ipo.unfinished -= dropped
            raise
        self._take(items)

    def buffer_limits_speed(self) -> bool:
        """The end of the look-ahead buffer holds the path speed down: no stop is due
        at the last buffered segment, and the path runs below its speed limit on the
        braking curve towards a stop after that segment (the look-ahead must always be
        able to stop there). Meaningful after a cycle that started with every slot
        taken; a larger buffer or LA_ON helps."""
        return self._limits_speed(self._ipo.seg, self._ipo.s_mm, self._ipo.v_mm_s)

    def _limits_speed(self, seg: Segment | None, s_mm: float, v: float) -> bool:
        """``buffer_limits_speed`` with the path at ``s_mm`` in ``seg`` at speed ``v``."""
        ipo = self._ipo
        if (seg is None or v <= 0.0 or v >= seg.cap_mm_s * (1.0 - 1e-6) or ipo.hold
                or self._closed):
            return False
        tail = self._planner.tail
        # the interpolator's segment is the planner's head (pop_head), so there is a tail
        assert tail is not None
        if (tail.junction_mm_s > 0.0 or tail.stop or tail.single_stop
                or tail.block.look_ahead is not None):  # a section's end is planned
            return False
        reach2 = 2.0 * seg.acc_mm_s2 * (seg.length_mm - s_mm)  # v^2 the rest can take
        nxt = seg.next
        while nxt is not None:
            reach2 += nxt.two_acc_len
            nxt = nxt.next
        return v * v >= _ON_BRAKING_CURVE * reach2

    @property
    def closed(self) -> bool:
        """``close`` was called and no block pushed since."""
        return self._closed

    def _take(self, items: list[Segment | Block]) -> None:
        if self.on_prepared is not None:
            self.on_prepared(items)
        planner, ipo = self._planner, self._ipo
        for item in items:
            if isinstance(item, Segment):
                item.single_stop = self._single_block and bool(item.events)
                planner.append(item)
                if ipo.seg is None:
                    ipo.seg = planner.head
                continue
            tail = planner.tail
            if tail is None:  # nothing to move before it: due where the path stands
                ipo.events.append((item, self._single_block))
                continue
            tail.events.append(item)
            if item.needs_stop and id(item) not in self._ipo.released_stops:
                planner.mark_stop(tail)
            if self._single_block:
                planner.mark_stop(tail, single=True)

    # -- the cycle --------------------------------------------------------------------

    def step(self, override: float) -> StepResult:
        """Run one cycle with feed override factor ``override`` (1.0 = 100 %, 0 stands)."""
        return self._ipo.step(override)

    def set_rapid_override(self, override: float) -> None:
        """The factor G0 blocks run with (1.0 = 100 %), from this cycle on."""
        planner = self._planner
        if override != planner.rapid_override:
            planner.set_rapid_override(override if override >= 0.0 else 0.0)

    @property
    def in_rapid(self) -> bool:
        """The segment being run is a G0 one (the rapid override scales it)."""
        seg = self._ipo.seg
        return seg is not None and seg.rapid

    @property
    def rapid_override(self) -> float:
        """The factor G0 blocks run with."""
        return self._planner.rapid_override

    def cruise_budget(self, override: float, most: int, watch_buffer: bool) -> int:
        """How many of the next cycles (at most ``most``) only move inside the current
        segment (``Interpolator.cruise_budget``); ``watch_buffer``: the cycles end
        before the first after which ``buffer_limits_speed`` would be true."""
        seg = self._ipo.seg

        def quiet(s_mm: float, v_mm_s: float) -> bool:
            return not self._limits_speed(seg, s_mm, v_mm_s)

        return self._ipo.cruise_budget(override, most, quiet if watch_buffer else None)

    def cruise(self, cycles: int) -> StepResult:
        """Run ``cycles`` cruising cycles at once; the last cycle's result."""
        return self._ipo.cruise(cycles)

    def hold(self) -> None:
        """Feedhold: decelerate on the path within the limits and stand."""
        self._ipo.hold = True

    def release_hold(self) -> None:
        """End a feedhold only (a programmed or single-block stop keeps waiting)."""
        self._ipo.hold = False

    def resume(self) -> None:
        """Continue after feedhold, M0/M1/M2/M30 and single-block stops."""
        self._ipo.resume()

    def release_technology(self) -> None:
        """Continue after a stop for technology acknowledges (StopKind.TECHNOLOGY)."""
        self._ipo.release_technology()

    def release_stop(self, block: Block) -> None:
        """``block``'s TECHNOLOGY stop is no stop any more (MVS_SNS acknowledged in
        time): the look-ahead plans through its end, the path does not wait there."""
        ipo, planner = self._ipo, self._planner
        ipo.released_stops.add(id(block))
        for seg in planner:
            if any(b is block for b in seg.events):
                seg.stop = any(b.needs_stop and id(b) not in ipo.released_stops
                               for b in seg.events)
                planner.release(seg)
                return

    @property
    def single_block(self) -> bool:
        """Stop at the end of every block (from the first block end still reachable)."""
        return self._single_block

    @single_block.setter
    def single_block(self, on: bool) -> None:
        on = bool(on)
        if on != self._single_block:
            self._single_block = on
            self._ipo.set_single_block(on)

    def stop_now(self) -> None:
        """RESET: drop everything buffered and stand still at the current position."""
        self._ipo.stop_now()
        self._prep.reset(self._ipo.position_mm)
        self._closed = False

    def relocate(self, position_mm: Sequence[float],
                 sw_limits_mm: Sequence[tuple[float, float]] | None) -> None:
        """At standstill with nothing buffered: the same place in other coordinates
        (``#TRAFO ON/OFF``: the tool tip and the rotary axes, or the axes again), with
        the software limits that hold in them (None: none)."""
        if not self._ipo.idle:
            raise RuntimeError("relocate needs the path at standstill with nothing buffered")
        start = tuple(float(x) for x in position_mm)
        if len(start) != len(self.dynamics):
            raise ValueError("position_mm needs one value per axis")
        self._prep = PathPreparation(self.dynamics, start, sw_limits_mm)
        self._ipo.position_mm = start

    # -- state ------------------------------------------------------------------------

    @property
    def idle(self) -> bool:
        """Nothing buffered, standing still, waiting for nothing."""
        return self._ipo.idle

    @property
    def position_mm(self) -> tuple[float, ...]:
        """Command position of every channel axis."""
        return self._ipo.position_mm

    @property
    def path_velocity_mm_s(self) -> float:
        """Current path speed."""
        return self._ipo.v_mm_s

    @property
    def distance_mm(self) -> float:
        """Path length covered since program start (or the last block with
        ``#DISTANCE PROG START CLEAR``)."""
        return self._ipo.distance_base_mm + self._ipo.s_mm

    @property
    def holding(self) -> bool:
        """Feedhold is active."""
        return self._ipo.hold

    @property
    def waiting(self) -> Waiting:
        """What the path waits for at a block end (dwell, programmed stop, single block)."""
        return self._ipo.waiting

    @property
    def waiting_at(self) -> Block | None:
        """The block the path dwells or waits at (None while it waits for nothing)."""
        return self._ipo.wait_block

    @property
    def running(self) -> bool:
        """Waiting for nothing at a block end, with a segment or block end still to run
        (``waiting`` NONE and ``has_motion``, in one look: asked every cycle)."""
        ipo = self._ipo
        return not ipo.waiting and (ipo.seg is not None or bool(ipo.events))

    @property
    def has_motion(self) -> bool:
        """A segment or a block end is still to run: the path is not empty."""
        ipo = self._ipo
        return ipo.seg is not None or bool(ipo.events)

    @property
    def override(self) -> float:
        """Feed override factor of the last cycle."""
        return self._ipo.override
