"""Windows of a stored program's lines, read without reading the program (READ_LINES).

A view of a CAM program of hundreds of MB asks for a few hundred lines around the current
block. Each program has a line index: the number of lines before each block of
``BLOCK_BYTES`` (a 200 MB program has 200 entries), counted as a chunked upload arrives
(``LineCounter``), else in one pass over the file the first time the program is asked.
A window then costs two reads: the block where its first line starts (to skip to it),
and the window's bytes. An index belongs to one version of the file (size, modification
time, inode: an upload replaces the file, so a new version gets a new index);
``INDEXES_KEPT`` are kept.
"""

from __future__ import annotations

import bisect
import threading
from collections import OrderedDict
from dataclasses import dataclass
from pathlib import Path

from cnc_objects.protocol.program_lines import LinesReply, LinesRequest

from .program_store import ProgramStore, StoreError, StoreFault, check_name

BLOCK_BYTES = 1 << 20  # one index entry per MiB: 200 for a 200 MB program
INDEXES_KEPT = 16  # programs whose index is kept (one 200 MB program's: ~2 kB)


@dataclass(frozen=True, slots=True)
class LineIndex:
    """Where the lines of one version of a file are: ``lines_before[k]`` newlines come
    before byte ``k * BLOCK_BYTES``."""

    version: tuple[int, int, int]  # size, mtime_ns, inode
    total_lines: int
    lines_before: tuple[int, ...]


def _version(path: Path) -> tuple[int, int, int]:
    st = path.stat()
    return st.st_size, st.st_mtime_ns, st.st_ino


class LineCounter:
    """Counts the lines of a file fed in pieces of any size, in order (a chunked upload
    indexes its program as it arrives: the first window needs no pass over the file)."""

    def __init__(self) -> None:
        self.size_bytes = 0
        self.newlines = 0
        self.lines_before: list[int] = []
        self._last = b"\n"

    def feed(self, data: bytes | memoryview) -> None:
        """The next ``data`` of the file."""
        view = memoryview(data)
        while view:
            if self.size_bytes % BLOCK_BYTES == 0:
                self.lines_before.append(self.newlines)
            room = BLOCK_BYTES - self.size_bytes % BLOCK_BYTES
            piece = view[:room]
            self.newlines += bytes(piece).count(b"\n")
            self.size_bytes += len(piece)
            self._last = bytes(piece[-1:])
            view = view[room:]

    def index(self, version: tuple[int, int, int]) -> LineIndex:
        """The index of the file fed, as version ``version`` of it."""
        total = self.newlines + (self._last != b"\n")  # a last line without its newline
        return LineIndex(version, total, tuple(self.lines_before))


def build_index(path: Path) -> LineIndex:
    """Count the lines of ``path`` block by block (memory: one block)."""
    version = _version(path)
    counter = LineCounter()
    with path.open("rb") as f:
        while block := f.read(BLOCK_BYTES):
            counter.feed(block)
    return counter.index(version)


def _skip_lines(data: bytes, count: int) -> int:
    """The position in ``data`` after its ``count``-th newline (``count`` are there)."""
    position = 0
    for _ in range(count):
        position = data.index(b"\n", position) + 1
    return position


def _whole_lines(data: bytes, count: int, at_end: bool) -> tuple[bytes, int]:
    """The first ``count`` whole lines of ``data`` (a window's bytes from a line start)
    and how many they are; the last line of the file needs no newline (``at_end``: the
    data reaches the end of the file); a first line longer than ``data`` is cut."""
    position, found = 0, 0
    while found < count:
        end = data.find(b"\n", position)
        if end < 0:
            break
        position, found = end + 1, found + 1
    if found < count and position < len(data) and (at_end or found == 0):
        return data, found + 1  # the file's last line, or one line longer than the room
    return data[:position], found


class ProgramLines:
    """Line windows of the programs of ``store``."""

    def __init__(self, store: ProgramStore) -> None:
        self.store = store
        self._indexes: OrderedDict[str, LineIndex] = OrderedDict()
        self._lock = threading.Lock()  # the loop reads, the indexing thread adds

    def indexed(self, name: str) -> bool:
        """True when the index of ``name`` as stored now is kept (a window is two reads);
        False means a pass over the file first (or a request that fails at once)."""
        with self._lock:
            kept = self._indexes.get(name)
        try:
            return kept is not None and kept.version == _version(self.store.root / name)
        except OSError:
            return True  # no such file: answered (refused) at once

    def adopt(self, name: str, counter: LineCounter) -> None:
        """Keep the lines ``counter`` counted as the index of ``name`` as stored now (its
        upload just committed); nothing when the file is not what was counted."""
        try:
            version = _version(self.store.root / check_name(name))
        except (OSError, StoreError):
            return
        if version[0] == counter.size_bytes:
            self._keep(name, counter.index(version))

    def _keep(self, name: str, index: LineIndex) -> None:
        with self._lock:
            self._indexes[name] = index
            self._indexes.move_to_end(name)
            while len(self._indexes) > INDEXES_KEPT:
                self._indexes.popitem(last=False)

    def index(self, name: str) -> LineIndex:
        """The line index of the stored program ``name`` as it is now."""
        path = self.store.root / check_name(name)
        try:
            version = _version(path)
            with self._lock:
                kept = self._indexes.get(name)
            if kept is None or kept.version != version:
                kept = build_index(path)
            self._keep(name, kept)
            return kept
        except FileNotFoundError:
            raise StoreError(StoreFault.NOT_FOUND, f"no program {name!r} in the store") from None
        except OSError as exc:
            raise StoreError(StoreFault.IO, f"cannot read {name!r}: {exc.strerror}") from None

    def read(self, request: LinesRequest, room_bytes: int) -> LinesReply:
        """Lines ``request.first_line``.. of the program, whole lines in ``room_bytes``."""
        check_name(request.name)
        index = self.index(request.name)
        skip = request.first_line - 1
        if skip >= index.total_lines or room_bytes <= 0:
            return LinesReply(index.total_lines, 0, b"")
        # the block that holds the newline ending line first_line - 1 (its last before it)
        block = max(0, bisect.bisect_left(index.lines_before, skip) - 1)
        size = index.version[0]
        try:
            with (self.store.root / request.name).open("rb") as f:
                f.seek(block * BLOCK_BYTES)
                start = block * BLOCK_BYTES + _skip_lines(
                    f.read(BLOCK_BYTES), skip - index.lines_before[block])
                f.seek(start)
                data = f.read(room_bytes)
        except (OSError, ValueError) as exc:  # replaced meanwhile: the next request indexes it
            with self._lock:
                self._indexes.pop(request.name, None)
            raise StoreError(StoreFault.IO, f"cannot read {request.name!r}: {exc}") from None
        text, count = _whole_lines(data, request.line_count, start + len(data) >= size)
        return LinesReply(index.total_lines, count, text)
