"""Files the kernel writes (logs, result files), written into the program store by a
thread of their own: the cycle thread only queues the bytes and never touches a disk.

``flush`` waits until everything queued so far is on disk; the program-store service
calls it before answering a list or a download, so a client that saw an effect (a
channel in ERROR) and then downloads the log sees the line that effect wrote.
"""

from __future__ import annotations

import logging
import queue
import threading
from collections.abc import Callable

from .program_store import ProgramStore, StoreError

log = logging.getLogger(__name__)


class StoreWriter:
    """Appends to (or replaces) files of the store in a background thread, in the order
    queued."""

    def __init__(self, store: ProgramStore) -> None:
        self._store = store
        self._queue: queue.Queue[tuple[str, bytes, bool] | None] = queue.Queue()
        self._thread = threading.Thread(target=self._run, name="cnc-store-writer", daemon=True)
        self._thread.start()

    def append(self, name: str, data: bytes | Callable[[], bytes], replace: bool = False) -> None:
        """Queue ``data`` for the end of ``name`` (``replace``: as its whole content);
        any thread, never blocks. ``data`` may be a function that makes the bytes: it is
        called in the writer thread, so that a large file (a PROD_TIME trace) is
        formatted off the cycle thread."""
        self._queue.put((name, data, replace))

    def flush(self) -> None:
        """Return once everything queued before the call is written."""
        self._queue.join()

    def close(self) -> None:
        """Write what is queued, then stop the thread."""
        self._queue.put(None)
        self._thread.join(5.0)

    def _run(self) -> None:
        while True:
            item = self._queue.get()
            try:
                if item is None:
                    return
                name, data, replace = item
                try:
                    if callable(data):
                        data = data()
                    if replace:
                        self._store.write(name, data)
                    else:
                        self._store.append(name, data)
                except StoreError as exc:
                    log.error("cannot write %s: %s", name, exc)
                except Exception:  # a maker that failed must not end the writer thread
                    log.exception("cannot make the content of %s", name)
            finally:
                self._queue.task_done()
