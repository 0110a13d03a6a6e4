"""The files the kernel writes, written by a thread of their own into the output area.

The cycle thread and the decoder threads only queue bytes: a call takes a lock, checks
the limits against what the files will hold once the queue is written, and returns. The
writer thread takes everything queued at once, joins the lines queued for one file into
one ``O_APPEND`` write, and writes; nothing is rewritten per line.

What may be queued is bounded:

- an NC program's write (``save``: ``#MSG SAVE``, a cycle's result file) over a limit
  (``output_max_files``, ``output_max_file_bytes``, ``output_max_total_bytes`` of the
  area, ``output_queue_max_bytes`` of what waits to be written) raises
  ``OutputLimitReached`` naming the key: the program stops with an NC error at that
  statement, the service runs on;
- the kernel's own files (``kernel_file``: the error logs, syntax check logs, PROD_TIME
  traces; a fixed set per channel) are never refused by the file count or the total: an
  error log keeps its newest lines within ``output_max_file_bytes`` (when it would pass
  the limit it is cut once to half of it, so the cut happens once per half a limit of
  lines), a report (check log, trace) replaces a report of the same file still waiting.
  When the queue is full a kernel line is dropped and a throttled warning says so.

No request of a client waits for the queue: a listing shows the files as they will be
once written (``listing``); a download or a delete of a file that has writes waiting is
answered when the writer has written those writes (``when_written``), without holding
the event loop or any other request.
"""

from __future__ import annotations

import heapq
import itertools
import logging
import threading
import time
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from enum import IntEnum

from cnc_objects.protocol.constants import PROGRAM_MAX_BYTES

from ..kernel.nc.technology import OutputLimitReached
from ..log_throttle import ThrottledWarning
from .output_area import WHAT, OutputArea
from .program_store import ProgramInfo, StoreError, check_name

log = logging.getLogger(__name__)

ITEM_COST_BYTES = 128  # what one queued write costs besides its data (the item, its list slot)
BATCH_MAX_BYTES = 1 << 20  # the writer takes at most this much at once (then writes it)
MAKER_COST_BYTES = PROGRAM_MAX_BYTES  # a report made in the writer thread: at most this

Content = bytes | Callable[[], bytes]


class WriteKind(IntEnum):
    """What a queued write does to its file."""

    APPEND = 1  # an NC program's text at the end (#MSG SAVE)
    REPLACE = 2  # the whole content (#MSG SAVE EXCLUSIVE, a result file, a report)
    LOG = 3  # a kernel log line at the end; the oldest lines go at output_max_file_bytes
    DELETE = 4  # a client removes the file


@dataclass(slots=True)
class _Write:
    seq: int  # position in the queue's order (from 1)
    name: str
    kind: WriteKind
    data: Content
    cost_bytes: int


@dataclass(frozen=True, slots=True)
class OutputLimits:
    """The ``output_*`` keys of ``[limits]`` (service/limits.py)."""

    max_files: int = 1000
    max_file_bytes: int = PROGRAM_MAX_BYTES
    max_total_bytes: int = 64 << 20
    queue_max_bytes: int = 4 << 20


class OutputWriter:
    """Queues writes to an ``OutputArea`` (any thread, never blocks on disk) and writes
    them in one background thread, in the order queued."""

    def __init__(self, area: OutputArea, limits: OutputLimits = OutputLimits()) -> None:
        self.area = area
        self.limits = limits
        self._lock = threading.Lock()
        self._wake = threading.Condition(self._lock)
        self._queue: deque[_Write] = deque()
        self._queued_bytes = 0
        self._reports: dict[str, _Write] = {}  # kernel reports still in the queue, by name
        # sizes as they will be once the queue is written (the limits act on these)
        self._sizes = {p.name: p.size_bytes for p in area.list()}
        self._total_bytes = sum(self._sizes.values())
        self._seq = 0  # writes queued so far
        self._written = 0  # writes done so far (they are done in order)
        self._last_seq: dict[str, int] = {}  # the last write queued per file
        self._waiters: list[tuple[int, int, Callable[[], None]]] = []  # (seq, tie, callback)
        self._tie = itertools.count()
        self._closing = False
        self._disk_sizes: dict[str, int] = {}  # writer thread: sizes it knows on disk
        self.dropped = ThrottledWarning(log, "output area: a kernel file line was dropped")
        self._failed = ThrottledWarning(log, "output area: a write failed")
        self._thread = threading.Thread(target=self._run, name="cnc-output-writer", daemon=True)
        self._thread.start()

    # ------------------------------------------------------------ kernel side

    def save(self, name: str, data: bytes, replace: bool = False) -> None:
        """Queue an NC program's write: ``data`` at the end of ``name`` (``replace``: as
        its whole content). ``OutputLimitReached`` names the limit it would pass,
        ``ValueError`` says why else it is refused (a bad name, the service stops)."""
        try:
            check_name(name, WHAT)
        except StoreError as exc:
            raise ValueError(str(exc)) from None
        lim = self.limits
        cost = len(data) + ITEM_COST_BYTES
        with self._lock:
            if self._closing:
                raise ValueError("the service is stopping")
            old = self._sizes.get(name)
            size = len(data) if replace else (old or 0) + len(data)
            total = self._total_bytes - (old or 0) + size
            if old is None and len(self._sizes) >= lim.max_files:
                raise OutputLimitReached(
                    "output_max_files", f"the output area holds {len(self._sizes)} files, "
                    f"[limits] output_max_files = {lim.max_files}")
            if size > lim.max_file_bytes:
                raise OutputLimitReached(
                    "output_max_file_bytes", f"{name} would have {size} bytes, "
                    f"[limits] output_max_file_bytes = {lim.max_file_bytes}")
            if total > lim.max_total_bytes:
                raise OutputLimitReached(
                    "output_max_total_bytes", f"the output area would hold {total} bytes, "
                    f"[limits] output_max_total_bytes = {lim.max_total_bytes}")
            if self._queued_bytes + cost > lim.queue_max_bytes:
                raise OutputLimitReached(
                    "output_queue_max_bytes", f"{self._queued_bytes} bytes wait to be "
                    f"written, [limits] output_queue_max_bytes = {lim.queue_max_bytes}")
            self._resize(name, size)
            self._put(name, WriteKind.REPLACE if replace else WriteKind.APPEND, data, cost)

    def kernel_file(self, name: str, data: Content, replace: bool = False) -> None:
        """The kernel's own file: a log line at the end of ``name``, or (``replace``) a
        report as its whole content (``data`` may be a function that makes the bytes in
        the writer thread). Never raises, never blocks; see the module docstring."""
        with self._lock:
            if self._closing:
                self.dropped.note(f"{name}: the service is stopping")
                return
            if replace:
                self._report(name, data)
                return
            assert isinstance(data, bytes)
            cost = len(data) + ITEM_COST_BYTES
            if self._queued_bytes + cost > self.limits.queue_max_bytes:
                self.dropped.note(f"{name}: [limits] output_queue_max_bytes reached")
                return
            size = self._sizes.get(name, 0) + len(data)
            if size > self.limits.max_file_bytes:  # the writer cuts it to half
                size = min(size, self.limits.max_file_bytes // 2 + len(data))
            self._resize(name, size)
            self._put(name, WriteKind.LOG, data, cost)

    def _report(self, name: str, data: Content) -> None:
        cost = (len(data) if isinstance(data, bytes) else MAKER_COST_BYTES) + ITEM_COST_BYTES
        waiting = self._reports.get(name)
        if waiting is not None:  # not taken yet: the new report supersedes it
            self._queued_bytes += cost - waiting.cost_bytes
            waiting.data, waiting.cost_bytes = data, cost
        elif self._queued_bytes + cost > self.limits.queue_max_bytes:
            self.dropped.note(f"{name}: [limits] output_queue_max_bytes reached")
            return
        else:
            self._reports[name] = self._put(name, WriteKind.REPLACE, data, cost)
        if isinstance(data, bytes):
            self._resize(name, len(data))
        else:
            self._resize(name, self._sizes.get(name, 0))  # known once it is made

    def _resize(self, name: str, size: int) -> None:
        self._total_bytes += size - self._sizes.get(name, 0)
        self._sizes[name] = size

    def _put(self, name: str, kind: WriteKind, data: Content, cost: int) -> _Write:
        self._seq += 1
        item = _Write(self._seq, name, kind, data, cost)
        self._queue.append(item)
        self._queued_bytes += cost
        self._last_seq[name] = self._seq
        self._wake.notify()
        return item

    # ------------------------------------------------------------ client side

    def listing(self) -> list[ProgramInfo]:
        """Every file as it will be once the queue is written, sorted by name (the time
        is the file's on disk, the present time for one not written yet)."""
        with self._lock:
            sizes = dict(self._sizes)
        mtimes = {p.name: p.mtime_s for p in self.area.list()}
        now_s = time.time()
        return [ProgramInfo(name, size, mtimes.get(name, now_s))
                for name, size in sorted(sizes.items())]

    def delete(self, name: str) -> bool:
        """Queue the removal of ``name``; False when there is no such file."""
        check_name(name, WHAT)
        with self._lock:
            if name not in self._sizes:
                return False
            self._total_bytes -= self._sizes.pop(name)
            self._reports.pop(name, None)
            self._put(name, WriteKind.DELETE, b"", ITEM_COST_BYTES)  # frees room: never refused
            return True

    def when_written(self, name: str, callback: Callable[[], None]) -> bool:
        """True when writes to ``name`` wait: ``callback`` is then called (in the writer
        thread) once they are written. False: nothing waits, read it now."""
        with self._lock:
            target = self._last_seq.get(name, 0)
            if target <= self._written:
                return False
            heapq.heappush(self._waiters, (target, next(self._tie), callback))
            return True

    def refuse_new(self) -> None:
        """Refuse every write from now on (the service stops): an NC program that writes
        stops with an NC error at once, so a write loop cannot keep its decoder, or a
        cycle waiting for that decoder, busy while the service shuts down."""
        with self._lock:
            self._closing = True
            self._wake.notify()

    def close(self, timeout_s: float = 3.0) -> None:
        """Refuse new writes, write what is queued, stop the thread (at most
        ``timeout_s``); waiting downloads are answered with what is on disk."""
        self.refuse_new()
        self._thread.join(timeout_s)
        if self._thread.is_alive():
            log.error("output writer did not finish within %.1f s", timeout_s)
        with self._lock:
            waiters, self._waiters = self._waiters, []
        for _, _, callback in waiters:
            callback()

    # ------------------------------------------------------------ writer thread

    def _run(self) -> None:
        while True:
            with self._lock:
                while not self._queue and not self._closing:
                    self._wake.wait()
                if not self._queue:
                    return
                batch = self._take()
            self._write(batch)
            self._done(batch)

    def _take(self) -> list[_Write]:
        batch: list[_Write] = []
        taken = 0
        while self._queue and (not batch or taken < BATCH_MAX_BYTES):
            item = self._queue.popleft()
            batch.append(item)
            taken += item.cost_bytes
            self._queued_bytes -= item.cost_bytes
            if self._reports.get(item.name) is item:
                del self._reports[item.name]
        return batch

    def _write(self, batch: list[_Write]) -> None:
        """Write ``batch`` in order; lines for one file in a row go in one write."""
        start = 0
        while start < len(batch):
            first = batch[start]
            end = start + 1
            if first.kind in (WriteKind.APPEND, WriteKind.LOG):
                while (end < len(batch) and batch[end].name == first.name
                       and batch[end].kind == first.kind):
                    end += 1
            try:
                self._apply(first, b"".join(w.data for w in batch[start:end])  # type: ignore[misc]
                            if end - start > 1 else first.data)
            except (OSError, StoreError) as exc:
                self._disk_sizes.pop(first.name, None)
                self._failed.note(f"{first.name}: {exc}")
            except Exception:  # a report's maker failed: the writer thread goes on
                self._disk_sizes.pop(first.name, None)
                log.exception("cannot make the content of %s", first.name)
            start = end

    def _apply(self, item: _Write, data: Content) -> None:
        area, name = self.area, item.name
        match item.kind:
            case WriteKind.APPEND:
                size = area.append(name, data)  # type: ignore[arg-type]
            case WriteKind.REPLACE:
                size = area.replace(name, data() if callable(data) else data)
            case WriteKind.LOG:
                size = self._append_log(name, data)  # type: ignore[arg-type]
            case WriteKind.DELETE:
                area.delete(name)
                size = 0
        self._disk_sizes[name] = size

    def _append_log(self, name: str, data: bytes) -> int:
        """Append to a log; at the size limit its newest lines are kept, cut to half the
        limit once (not a rewrite per line)."""
        half = self.limits.max_file_bytes // 2
        size = self._disk_sizes.get(name)
        if size is None:
            size = self.area.size(name)
        if size + len(data) > self.limits.max_file_bytes:
            if len(data) > half:
                tail = data[len(data) - half:]
                return self.area.replace(name, tail[tail.find(b"\n") + 1:])
            self.area.keep_newest(name, half - len(data))
        return self.area.append(name, data)

    def _done(self, batch: list[_Write]) -> None:
        ready: list[Callable[[], None]] = []
        with self._lock:
            self._written = batch[-1].seq
            for item in batch:  # a file without later writes: its size as written
                if (self._last_seq.get(item.name) == item.seq and item.kind != WriteKind.DELETE
                        and item.name in self._sizes and item.name in self._disk_sizes):
                    self._resize(item.name, self._disk_sizes[item.name])
            while self._waiters and self._waiters[0][0] <= self._written:
                ready.append(heapq.heappop(self._waiters)[2])
            for item in batch:
                if self._last_seq.get(item.name) == item.seq:
                    del self._last_seq[item.name]
        for callback in ready:
            try:
                callback()
            except Exception:
                log.exception("a callback of the output writer failed")
