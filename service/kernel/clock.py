"""Clocks of the cycle task: real time, or virtual time.

``RealtimeClock`` sleeps to each cycle deadline and counts overruns and jitter.
``VirtualClock`` does not tie kernel time to the wall: while the kernel has work it runs
cycles back to back (or paced at ``speed`` times real time); while it is idle it waits
for the next command, at most one cycle time, so an idle service costs no CPU and a
command is applied at once. Kernel time is always cycles x cycle time. With
``event_speed`` (``--clock virtual``; ``--clock virtual-step`` is without) the kernel
also runs the cycles between two events in bulk (``Kernel``, docs/kernel.md).
"""

from __future__ import annotations

import ctypes
import logging
import sys
import time
from typing import Protocol

from .realtime_priority import DEFAULT_RT_PRIORITY, RealtimeGrant, claim
from .state import CycleStats

log = logging.getLogger(__name__)


class Clock(Protocol):
    """Decides when the next cycle starts; ``lateness`` of the cycle starts against their
    deadlines, where there are deadlines (None: virtual time has none)."""

    @property
    def lateness(self) -> LatenessHistogram | None:
        """The lateness of the cycle starts, or None where there are no deadlines."""

    def start(self) -> None:
        """Called once before the first cycle."""

    def wait(self, busy: bool, stats: CycleStats, wake: WakeSource) -> None:
        """Block until the next cycle should start; update ``stats``."""


class WakeSource(Protocol):
    """What a clock may wait on instead of sleeping: the command queue."""

    def wait_for_command(self, timeout_s: float) -> None:
        """Return when a command is queued or ``timeout_s`` has passed."""


#: Width of one bucket of the lateness histogram, and how far it reaches (later: the last).
LATENESS_BUCKET_US = 10
LATENESS_RANGE_US = 100_000


class LatenessHistogram:
    """How late cycles started against their deadlines: counts per ``LATENESS_BUCKET_US``
    (one list index per cycle: cheap enough for every cycle), percentiles on demand."""

    def __init__(self) -> None:
        self.counts = [0] * (LATENESS_RANGE_US // LATENESS_BUCKET_US + 1)
        self.total = 0

    def add(self, late_us: int) -> None:
        """One cycle that started ``late_us`` after its deadline."""
        self.counts[min(max(late_us, 0) // LATENESS_BUCKET_US, len(self.counts) - 1)] += 1
        self.total += 1

    def percentile_us(self, fraction: float) -> int:
        """The lateness ``fraction`` (0.5, 0.99) of the cycles kept to: the upper edge of
        the bucket it falls in (so at most ``LATENESS_BUCKET_US`` above the exact one);
        0 before the first cycle."""
        wanted = fraction * self.total
        seen = 0
        for index, count in enumerate(self.counts):
            seen += count
            if count and seen >= wanted:
                return (index + 1) * LATENESS_BUCKET_US
        return 0

    def reset(self) -> None:
        """Forget every cycle so far."""
        self.counts = [0] * len(self.counts)
        self.total = 0


_PR_SET_TIMERSLACK = 29  # linux/prctl.h


def precise_sleep() -> None:
    """Let the calling thread's sleeps end on time: Linux lets a sleep run up to the
    thread's timer slack (50 us by default) late to batch wake-ups; 1 ns takes that away
    (the cycle's median lateness fell from 90 to 40 us, make bench part jitter). Elsewhere,
    or where prctl is refused, sleeps stay as they are."""
    if not sys.platform.startswith("linux"):
        return
    try:
        ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_TIMERSLACK, 1, 0, 0, 0)
    except (OSError, AttributeError):
        pass


class RealtimeClock:
    """Sleep to each deadline; a cycle that ends after the next deadline is an overrun.
    Every cycle's lateness goes into ``lateness``.

    ``rt_priority`` (1..99): the cycle thread asks for SCHED_FIFO at this priority and
    locks the process's memory (``realtime_priority``); 0 leaves it a normal thread.
    ``grant`` says what it got; the first start logs it.
    """

    def __init__(self, cycle_s: float, rt_priority: int = DEFAULT_RT_PRIORITY) -> None:
        self.cycle_s = cycle_s
        self._deadline = 0.0
        self.lateness = LatenessHistogram()
        self.grant = RealtimeGrant(rt_priority)
        self._logged = False

    def start(self) -> None:
        precise_sleep()
        claim(self.grant)  # on the cycle thread: the policy is the calling thread's
        if not self._logged:  # once: a STOP and RUN starts the thread again, same grant
            self._logged = True
            if self.grant.refusals:
                log.warning("%s", self.grant.describe())
            else:
                log.info("%s", self.grant.describe())
        self._deadline = time.perf_counter() + self.cycle_s

    def wait(self, busy: bool, stats: CycleStats, wake: WakeSource) -> None:
        now = time.perf_counter()
        if now > self._deadline:
            # The cycle's work ran past the next deadline: count it and skip the missed
            # deadlines instead of running a burst of late cycles.
            stats.overruns += 1
            missed = int((now - self._deadline) / self.cycle_s) + 1
            self._deadline += missed * self.cycle_s
        remaining = self._deadline - time.perf_counter()
        if remaining > 0:
            time.sleep(remaining)
        late_us = int((time.perf_counter() - self._deadline) * 1e6)
        if late_us > stats.jitter_max_us:
            stats.jitter_max_us = late_us
        self.lateness.add(late_us)
        self._deadline += self.cycle_s


#: A busy virtual clock yields the CPU to other threads once per this many cycles.
YIELD_EVERY_CYCLES = 64


class VirtualClock:
    """Kernel time detached from the wall clock.

    ``speed`` None: as fast as the CPU allows while busy. ``speed`` X: X times real time.
    ``event_speed``: the kernel may run the cycles between two events in one step
    (unpaced only: a paced clock steps, every cycle has its wall time).
    """

    def __init__(self, cycle_s: float, speed: float | None = None,
                 event_speed: bool = True) -> None:
        self.cycle_s = cycle_s
        self.speed = speed
        self.event_speed = event_speed and speed is None
        self.lateness: LatenessHistogram | None = None  # no deadlines in virtual time
        self._deadline = 0.0
        self._busy_cycles = 0

    def start(self) -> None:
        self._deadline = time.perf_counter()

    def wait(self, busy: bool, stats: CycleStats, wake: WakeSource) -> None:
        if self.speed is not None:
            self._deadline += self.cycle_s / self.speed
            remaining = self._deadline - time.perf_counter()
            if remaining > 0:
                wake.wait_for_command(remaining) if not busy else time.sleep(remaining)
            else:
                self._deadline = time.perf_counter()
        elif busy:
            # Let the service's thread take the GIL now and then. Not every cycle: a
            # sleep(0) costs tens of microseconds on a VM, several cycles' worth of work,
            # and the interpreter's switch interval hands the GIL over anyway.
            self._busy_cycles += 1
            if self._busy_cycles % YIELD_EVERY_CYCLES == 0:
                time.sleep(0)
        else:
            wake.wait_for_command(self.cycle_s)
