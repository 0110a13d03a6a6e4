"""The kernel's worker threads: the SDA decoders and the syntax checks of the channels.

The kernel owns its threads as the real kernel owns its tasks. A worker is started
through ``Workers.start`` with the function that cancels it (RESET): the registry knows
every worker alive, puts each under the workers' scheduling (``realtime_priority``:
below the cycle thread and below the service's threads, never at the cycle's priority,
which a thread started from the cycle thread would otherwise inherit) and, when the
kernel closes, cancels and joins them all within the time left.

A RESET cancels a run's worker without waiting for it (the cycle never blocks): the
decoder looks at its run every few hundred steps (``nc.work_guard``), so the thread ends
within milliseconds and leaves the registry by itself. ``alive()`` counts the workers
that have not ended: after RESET, the old run's worker is gone from it.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable

from .realtime_priority import run_as_worker

log = logging.getLogger(__name__)


class Workers:
    """The worker threads of one kernel (thread-safe: started from the cycle thread,
    counted from any thread, joined from the service's)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._alive: dict[threading.Thread, Callable[[], None]] = {}  # thread -> its cancel
        #: SCHED_FIFO priority of the workers, 0: SCHED_OTHER; the kernel sets it from
        #: the cycle thread's grant (``realtime_priority.worker_priority``)
        self.priority = 0

    def start(self, name: str, target: Callable[[], None],
              cancel: Callable[[], None]) -> threading.Thread:
        """Run ``target`` in a new worker thread called ``name``; ``cancel`` ends it
        (RESET, the kernel's close)."""
        priority = self.priority
        thread: threading.Thread

        def run() -> None:
            try:
                run_as_worker(priority)
                target()
            finally:
                with self._lock:
                    self._alive.pop(thread, None)

        thread = threading.Thread(target=run, name=name, daemon=True)
        with self._lock:
            self._alive[thread] = cancel
        thread.start()
        return thread

    def alive(self) -> int:
        """The number of workers that have not ended."""
        with self._lock:
            return len(self._alive)

    def close(self, timeout_s: float) -> int:
        """Cancel every worker and wait up to ``timeout_s`` in all for them to end; the
        number still alive then (logged)."""
        with self._lock:
            workers = list(self._alive.items())
        for _, cancel in workers:
            cancel()
        deadline = time.monotonic() + timeout_s
        for thread, _ in workers:
            thread.join(max(deadline - time.monotonic(), 0.0))
        left = self.alive()
        if left:
            log.error("%d kernel worker thread(s) did not end within %.1f s", left, timeout_s)
        return left
