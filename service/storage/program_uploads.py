"""Chunked uploads into the program store: programs larger than one frame (CAM programs
of hundreds of MB).

One upload per connection at a time: open (a name), chunks in order (each says where it
starts, so a lost or repeated chunk is seen), then commit (the total size) or abandon.
The bytes go to a temporary file in the store's directory (a dot name: never listed, never
selectable); the commit renames it over the program atomically, so a reader sees the old
program or the new one whole. Anything wrong (a chunk out of order, beyond
``max_bytes``, the store's total ``max_total_bytes`` reached, a wrong total) abandons the
upload: the temporary file is removed and the error says why. A connection that ends
abandons its upload too (``connection_ended``): nothing is left behind.
"""

from __future__ import annotations

import logging
import os
import tempfile
from collections.abc import Callable, Hashable
from dataclasses import dataclass, field
from pathlib import Path
from typing import BinaryIO

from .program_line_index import LineCounter
from .program_store import _TEMP_PREFIX, ProgramStore, StoreError, StoreFault, check_name

log = logging.getLogger(__name__)


@dataclass(slots=True)
class _Upload:
    """One connection's upload in progress."""

    name: str
    temp: Path
    file: BinaryIO
    written_bytes: int = 0
    lines: LineCounter = field(default_factory=LineCounter)  # the view's index, as it comes


class ProgramUploads:
    """The chunked uploads in progress, one per connection (``holder``)."""

    def __init__(self, store: ProgramStore,
                 committed: Callable[[str, LineCounter], None] | None = None) -> None:
        self.store = store
        self._committed = committed  # told each program committed, with its lines counted
        self._uploads: dict[Hashable, _Upload] = {}

    def in_progress_bytes(self) -> int:
        """Bytes the temporary files of all uploads in progress hold."""
        return sum(u.written_bytes for u in self._uploads.values())

    def open(self, holder: Hashable, name: str, size_bytes: int | None = None) -> None:
        """Start an upload of ``name`` for ``holder`` (an earlier one of it is abandoned).
        ``size_bytes``, when the client says it: a program the limits will not take is
        refused here, before a byte is sent."""
        check_name(name)
        self.abandon(holder, "a new upload was opened")
        if size_bytes is not None:
            self._check_announced(name, size_bytes)
        try:
            fd, temp = tempfile.mkstemp(prefix=_TEMP_PREFIX, dir=self.store.root)
        except OSError as exc:
            raise StoreError(StoreFault.IO, f"cannot start {name!r}: {exc.strerror}") from None
        self._uploads[holder] = _Upload(name, Path(temp), os.fdopen(fd, "wb"))

    def _check_announced(self, name: str, size_bytes: int) -> None:
        """Refuse an upload of ``size_bytes`` that ``max_bytes`` or the store's room forbid."""
        if size_bytes > self.store.max_bytes:
            raise StoreError(StoreFault.TOO_LARGE, (
                f"program {name!r} has {size_bytes} bytes; the store takes at most "
                f"{self.store.max_bytes} in one program ([limits] program_max_bytes)"))
        room = self.store.max_total_bytes - self.store.used_bytes() - self.in_progress_bytes()
        if size_bytes > room:
            raise StoreError(StoreFault.FULL, (
                f"program {name!r} has {size_bytes} bytes; the store has room for {max(room, 0)} "
                f"more (of {self.store.max_total_bytes}, [limits] store_max_total_bytes); "
                "delete some programs first"))

    def _current(self, holder: Hashable, what: str) -> _Upload:
        upload = self._uploads.get(holder)
        if upload is None:
            raise StoreError(StoreFault.NO_UPLOAD, f"{what}: this connection has no upload "
                             "open (open one first; an error abandons it)")
        return upload

    def write(self, holder: Hashable, position: int, data: bytes) -> None:
        """Append the chunk ``data`` that starts at byte ``position`` of the program."""
        upload = self._current(holder, "a chunk")
        fault: StoreError | None = None
        end = position + len(data)
        if position != upload.written_bytes:
            fault = StoreError(StoreFault.OUT_OF_ORDER, (
                f"upload of {upload.name!r}: a chunk at byte {position}, expected byte "
                f"{upload.written_bytes}; the upload is abandoned"))
        elif end > self.store.max_bytes:
            fault = StoreError(StoreFault.TOO_LARGE, (
                f"upload of {upload.name!r} reaches {end} bytes; the store takes at most "
                f"{self.store.max_bytes} in one program; the upload is abandoned"))
        elif (self.store.used_bytes() + self.in_progress_bytes() + len(data)
              > self.store.max_total_bytes):
            fault = StoreError(StoreFault.FULL, (
                f"upload of {upload.name!r}: the store would hold more than "
                f"{self.store.max_total_bytes} bytes; delete some programs first; "
                "the upload is abandoned"))
        if fault is None:
            try:
                upload.file.write(data)
                upload.written_bytes = end
                upload.lines.feed(data)
                return
            except OSError as exc:
                fault = StoreError(StoreFault.IO, f"cannot write {upload.name!r}: {exc.strerror}")
        self.abandon(holder, str(fault))
        raise fault

    def commit(self, holder: Hashable, size_bytes: int) -> str:
        """Finish the upload: when ``size_bytes`` were received, the program replaces its
        older version atomically; its name is returned."""
        upload = self._current(holder, "a commit")
        if size_bytes != upload.written_bytes:
            fault = StoreError(StoreFault.OUT_OF_ORDER, (
                f"upload of {upload.name!r}: the commit says {size_bytes} bytes, "
                f"{upload.written_bytes} arrived; the upload is abandoned"))
            self.abandon(holder, str(fault))
            raise fault
        del self._uploads[holder]
        try:
            upload.file.close()
            self.store.replace_with(upload.name, upload.temp)
        except OSError as exc:
            upload.temp.unlink(missing_ok=True)
            raise StoreError(StoreFault.IO, f"cannot store {upload.name!r}: {exc.strerror}") from None
        except StoreError:
            upload.temp.unlink(missing_ok=True)
            raise
        log.info("program %r uploaded in chunks (%d bytes)", upload.name, size_bytes)
        if self._committed is not None:
            self._committed(upload.name, upload.lines)
        return upload.name

    def abandon(self, holder: Hashable, why: str) -> bool:
        """Drop ``holder``'s upload and its temporary file; False when it had none."""
        upload = self._uploads.pop(holder, None)
        if upload is None:
            return False
        try:
            upload.file.close()
        finally:
            upload.temp.unlink(missing_ok=True)
        log.info("upload of %r abandoned after %d bytes: %s", upload.name,
                 upload.written_bytes, why)
        return True

    def connection_ended(self, holder: Hashable) -> None:
        """``holder``'s connection is gone: its upload is abandoned."""
        self.abandon(holder, "the connection ended")
