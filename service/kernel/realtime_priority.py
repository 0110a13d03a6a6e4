"""Real-time priority for the realtime clock's cycle thread: SCHED_FIFO and locked memory.

Where the process may (root, or CAP_SYS_NICE / an RLIMIT_RTPRIO that allows the
priority; CAP_IPC_LOCK or an RLIMIT_MEMLOCK above the process's size), the cycle thread
runs under SCHED_FIFO, ahead of every normal thread of the machine, and the process's
memory is locked (``mlockall(MCL_CURRENT | MCL_FUTURE)``) so that no page fault to swap
or to a dropped file page stalls a cycle. Where not, the thread stays SCHED_OTHER and the
service goes on: ``RealtimeGrant`` says what was asked, what was granted and why not.
``serve_below`` puts the service's other threads one priority below the cycle thread:
the cycle needs the GIL as well as the CPU. The kernel's workers (decoder, syntax
check) run below both (``worker_priority``, ``run_as_worker``): only the cycle thread
has the cycle's priority, and a worker that computes without pause never starves the
service's threads (the event loop, ZeroMQ's, the shutdown).

Only Linux has these calls here; elsewhere the grant says so.
"""

from __future__ import annotations

import ctypes
import logging
import os
import sys
from dataclasses import dataclass, field
from enum import IntEnum

log = logging.getLogger(__name__)

#: The SCHED_FIFO priority of the cycle thread unless configured (1..99). Above the
#: threaded interrupt handlers' 50, so that network interrupts do not delay a cycle,
#: below the kernel's own watchdog and migration threads (99).
DEFAULT_RT_PRIORITY = 60
RT_PRIORITY_MAX = 99
#: The kernel's workers run this far below the cycle thread: one below the service's
#: threads (which run one below the cycle), so that they preempt a busy worker.
WORKERS_BELOW_CYCLE = 2

_MCL_CURRENT = 1  # sys/mman.h (Linux)
_MCL_FUTURE = 2


class SchedPolicy(IntEnum):
    """Scheduling policies of a thread, Linux's numbers (``cnc_cycle_sched_policy_r``)."""

    OTHER = 0  # the normal time-sharing scheduler: no real-time priority
    FIFO = 1  # real-time: runs until it blocks, ahead of every OTHER thread


@dataclass
class RealtimeGrant:
    """What the cycle thread asked for and what it got (filled in by ``claim``)."""

    asked_priority: int  # 0: real-time priority not asked for (--rt-priority 0)
    policy: SchedPolicy = SchedPolicy.OTHER
    priority: int = 0  # the SCHED_FIFO priority granted; 0 under SCHED_OTHER
    memory_locked: bool = False
    refusals: list[str] = field(default_factory=list)  # why what was asked was not granted

    def describe(self) -> str:
        """One sentence for the log: the policy, the memory, and what was refused."""
        if self.asked_priority == 0:
            return "cycle thread under SCHED_OTHER: real-time priority is off (--rt-priority 0)"
        got = (f"SCHED_FIFO priority {self.priority}" if self.policy is SchedPolicy.FIFO
               else "SCHED_OTHER")
        memory = "memory locked" if self.memory_locked else "memory not locked"
        text = f"cycle thread under {got}, {memory}"
        if self.refusals:
            text += f" ({'; '.join(self.refusals)}); the service goes on without"
        return text


def _libc() -> ctypes.CDLL:
    return ctypes.CDLL(None, use_errno=True)


def claim(grant: RealtimeGrant, lock_memory: bool = True) -> None:
    """Ask for SCHED_FIFO at ``grant.asked_priority`` for the CALLING thread, and lock the
    process's memory (unless ``lock_memory`` is False); record in ``grant`` what was
    granted. Never raises."""
    grant.policy, grant.priority, grant.memory_locked = SchedPolicy.OTHER, 0, False
    grant.refusals.clear()
    if grant.asked_priority == 0:
        return
    if not sys.platform.startswith("linux"):
        grant.refusals.append(f"SCHED_FIFO and mlockall are not available on {sys.platform}")
        return
    try:
        # pid 0 is the calling thread (Linux schedules threads, not processes)
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(grant.asked_priority))
        grant.policy, grant.priority = SchedPolicy.FIFO, grant.asked_priority
    except OSError as exc:
        grant.refusals.append(
            f"SCHED_FIFO refused: {exc.strerror} (needs root or CAP_SYS_NICE, or RLIMIT_RTPRIO "
            f">= {grant.asked_priority})")
    if not lock_memory:
        return
    try:
        failed = _libc().mlockall(_MCL_CURRENT | _MCL_FUTURE)
        errno = ctypes.get_errno()
    except (OSError, AttributeError) as exc:
        failed, errno = -1, 0
        grant.refusals.append(f"mlockall unavailable: {exc}")
    if failed == 0:
        grant.memory_locked = True
    elif errno:
        grant.refusals.append(
            f"mlockall refused: {os.strerror(errno)} (needs CAP_IPC_LOCK or an RLIMIT_MEMLOCK "
            "above the process's size)")


def serve_below(cycle_priority: int) -> RealtimeGrant:
    """Put the CALLING thread (the service's event loop) under SCHED_FIFO one priority
    below the cycle thread's, before it starts the other threads (they inherit it).

    Why: the cycle thread needs the GIL as well as the CPU. A thread of the service that
    holds the GIL and is preempted by another process of the machine keeps the cycle
    waiting for as long as the OS runs that process (milliseconds on a busy machine);
    under SCHED_FIFO no normal process preempts it. Never raises; 0: nothing asked."""
    grant = RealtimeGrant(max(cycle_priority - 1, 1) if cycle_priority else 0)
    claim(grant, lock_memory=False)
    return grant


def worker_priority(cycle: RealtimeGrant | None) -> int:
    """The SCHED_FIFO priority of the kernel's workers when the cycle thread got
    ``cycle``: ``WORKERS_BELOW_CYCLE`` below it; 0 (SCHED_OTHER) when the cycle thread
    has no real-time priority or the difference leaves none."""
    if cycle is None or cycle.policy is not SchedPolicy.FIFO:
        return 0
    return max(cycle.priority - WORKERS_BELOW_CYCLE, 0)


def run_as_worker(priority: int) -> bool:
    """Put the CALLING thread under SCHED_FIFO at ``priority``, or SCHED_OTHER for 0.

    A thread inherits its creator's policy: a worker started from the cycle thread would
    run at the cycle's priority, above every thread of the service. Lowering one's own
    priority is always permitted; False (logged) where the call is refused anyway, or
    where Linux's calls are missing. Never raises."""
    if not sys.platform.startswith("linux"):
        return False
    try:
        if priority > 0:
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
        elif os.sched_getscheduler(0) != os.SCHED_OTHER:
            os.sched_setscheduler(0, os.SCHED_OTHER, os.sched_param(0))
    except OSError as exc:
        log.warning("worker thread keeps its scheduling policy: %s", exc.strerror)
        return False
    return True
