"""The output area: the directory of the files the kernel writes, apart from the store.

NC programs write files (``#MSG SAVE``, the result files of calculation cycles) and the
kernel writes its logs (``errors-ch<c>.log``), syntax check logs (``dec0<c>.sc``) and
PROD_TIME traces (``prodtime0<c>.csv``). They live here, never in the program store:
whatever an NC program names, it cannot create, replace or delete a program, whoever
started it. Clients list, download and delete these files through their own index group
(``OUTPUT_AREA_GROUP``); only the writer thread (``output_writer``) writes them.

Names follow the store's rule (plain file names, ``program_store.check_name``).
Appends append (``O_APPEND``: one write call, no rewrite of what is there); a whole-file
replace and the trimming of a log are atomic (a temporary file, then ``os.replace``), so
a reader sees the old content or the new, never half a file.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from .program_store import ProgramInfo, StoreError, StoreFault, check_name, list_files

_TEMP_PREFIX = ".write-"
WHAT = "output file"  # how messages name a file of this area


class OutputArea:
    """The files in one directory; written by one thread, read by any."""

    def __init__(self, root: Path) -> None:
        self.root = Path(root)
        self.root.mkdir(parents=True, exist_ok=True)
        for entry in os.scandir(self.root):  # a temporary file a kill left behind
            if entry.name.startswith(_TEMP_PREFIX) and entry.is_file():
                Path(entry.path).unlink(missing_ok=True)

    def path(self, name: str) -> Path:
        """The file of ``name``; StoreError when ``name`` is not a plain file name."""
        return self.root / check_name(name, WHAT)

    def list(self) -> list[ProgramInfo]:
        """Every file, sorted by name (temporary files are not listed)."""
        return list_files(self.root)

    def read(self, name: str) -> bytes:
        """The content of ``name`` as written so far."""
        try:
            return self.path(name).read_bytes()
        except FileNotFoundError:
            raise StoreError(StoreFault.NOT_FOUND, f"no {WHAT} {name!r}") from None
        except OSError as exc:
            raise StoreError(StoreFault.IO, f"cannot read {name!r}: {exc.strerror}") from None

    # ------------------------------------------------------------ writer thread only

    def append(self, name: str, data: bytes) -> int:
        """Add ``data`` at the end of ``name`` (created when absent); its size after."""
        fd = os.open(self.path(name), os.O_WRONLY | os.O_APPEND | os.O_CREAT, 0o644)
        try:
            view = memoryview(data)
            while view:
                view = view[os.write(fd, view):]
            return os.fstat(fd).st_size
        finally:
            os.close(fd)

    def replace(self, name: str, data: bytes) -> int:
        """Make ``data`` the whole content of ``name``, atomically; its size."""
        path = self.path(name)
        fd, temp = tempfile.mkstemp(prefix=_TEMP_PREFIX, dir=self.root)
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(data)
            os.replace(temp, path)
        except BaseException:
            Path(temp).unlink(missing_ok=True)
            raise
        return len(data)

    def keep_newest(self, name: str, keep_bytes: int) -> int:
        """Cut ``name`` to its newest whole lines within ``keep_bytes`` (a log that
        reached its size limit), atomically; its size after."""
        try:
            data = self.path(name).read_bytes()
        except FileNotFoundError:
            return 0
        if len(data) <= keep_bytes:
            return len(data)
        tail = data[len(data) - keep_bytes:]
        return self.replace(name, tail[tail.find(b"\n") + 1:])

    def delete(self, name: str) -> None:
        """Remove ``name`` (nothing when absent)."""
        self.path(name).unlink(missing_ok=True)

    def size(self, name: str) -> int:
        """Bytes of ``name`` on disk (0 when absent)."""
        try:
            return self.path(name).stat().st_size
        except FileNotFoundError:
            return 0
