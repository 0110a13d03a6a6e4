"""The kernel's worker registry: counts its threads, cancels and joins them, and runs
them below the cycle's real-time priority (``realtime_priority.run_as_worker``)."""

from __future__ import annotations

import os
import threading

import pytest

from cnc_objects.service.kernel.realtime_priority import (
    RealtimeGrant,
    SchedPolicy,
    worker_priority,
)
from cnc_objects.service.kernel.workers import Workers

JOIN_S = 5.0


def test_close_cancels_and_joins_every_worker() -> None:
    workers = Workers()
    stops = [threading.Event() for _ in range(3)]
    for k, stop in enumerate(stops):
        workers.start(f"w{k}", lambda stop=stop: stop.wait(JOIN_S * 2), stop.set)
    assert workers.alive() == 3
    assert workers.close(JOIN_S) == 0
    assert workers.alive() == 0
    assert not [t for t in threading.enumerate() if t.name in ("w0", "w1", "w2")]


def test_a_worker_that_ended_leaves_the_count() -> None:
    workers = Workers()
    thread = workers.start("short", lambda: None, lambda: None)
    thread.join(JOIN_S)
    assert not thread.is_alive() and workers.alive() == 0


def test_worker_priority_is_two_below_a_fifo_cycle() -> None:
    assert worker_priority(RealtimeGrant(60, SchedPolicy.FIFO, 60)) == 58
    assert worker_priority(RealtimeGrant(2, SchedPolicy.FIFO, 2)) == 0
    assert worker_priority(RealtimeGrant(60)) == 0  # refused: the cycle is SCHED_OTHER
    assert worker_priority(None) == 0  # virtual clock


def _policy_of_a_worker_started_from_fifo(cycle: int, priority: int) -> tuple[int, int]:
    """(policy, priority) of a worker started by a thread at SCHED_FIFO ``cycle``."""
    workers = Workers()
    workers.priority = priority
    seen: list[tuple[int, int]] = []
    failed: list[OSError] = []

    def cycle_thread() -> None:
        try:
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(cycle))
        except OSError as exc:
            failed.append(exc)
            return
        workers.start("probe", lambda: seen.append(
            (os.sched_getscheduler(0), os.sched_getparam(0).sched_priority)), lambda: None)

    creator = threading.Thread(target=cycle_thread)
    creator.start()
    creator.join(JOIN_S)
    workers.close(JOIN_S)
    if failed:
        pytest.skip(f"SCHED_FIFO refused: {failed[0].strerror}")
    return seen[0]


@pytest.mark.skipif(not hasattr(os, "sched_setscheduler"), reason="Linux only")
def test_a_worker_does_not_inherit_the_cycle_priority() -> None:
    assert _policy_of_a_worker_started_from_fifo(60, 58) == (os.SCHED_FIFO, 58)
    assert _policy_of_a_worker_started_from_fifo(60, 0) == (os.SCHED_OTHER, 0)
