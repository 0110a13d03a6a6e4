"""The program store: the NC programs, in one directory.

Programs reach the controller over the wire (upload, list, download, delete; upload and
delete are admin's); the kernel reads them from here when a program is selected and when
a program calls a file subprogram, and never writes here: the files it writes go to the
output area (``output_area``). Writes are atomic (a temporary file in the same directory, then
``os.replace``): a reader sees the old content or the new, never half a file.

Names are plain file names: no path separators, no ``..``, no leading dot, at most
``PROGRAM_NAME_MAX_CHARS`` characters of letters, digits and ``_ - .``. A bad name or an
oversized upload raises ``StoreError`` and changes nothing.
"""

from __future__ import annotations

import os
import re
import tempfile
import threading
from dataclasses import dataclass
from enum import IntEnum
from pathlib import Path

from cnc_objects.protocol.constants import (
    PROGRAM_MAX_BYTES,
    PROGRAM_NAME_MAX_CHARS,
    STORE_MAX_TOTAL_BYTES,
)

_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.\-]*")
_TEMP_PREFIX = ".upload-"


class StoreFault(IntEnum):
    """Why the store refused an operation."""

    BAD_NAME = 1  # the name is not a plain file name
    NOT_FOUND = 2  # no program of that name
    TOO_LARGE = 3  # the content exceeds the size bound
    FULL = 4  # the store holds its maximum number of files
    IO = 5  # the file system refused
    OUT_OF_ORDER = 6  # a chunked upload's chunk or total does not follow what arrived
    NO_UPLOAD = 7  # a chunk or commit without an upload open on the connection


class StoreError(Exception):
    """A refused store operation, with a sentence for the user."""

    def __init__(self, fault: StoreFault, message: str) -> None:
        super().__init__(message)
        self.fault = fault


@dataclass(frozen=True, slots=True)
class ProgramInfo:
    """One stored file."""

    name: str
    size_bytes: int
    mtime_s: float


def check_name(name: str, what: str = "program") -> str:
    """``name`` when it is a valid name of a ``what`` (program, output file); StoreError
    otherwise."""
    if not name:
        raise StoreError(StoreFault.BAD_NAME, f"a {what} name must not be empty")
    if len(name) > PROGRAM_NAME_MAX_CHARS:
        raise StoreError(
            StoreFault.BAD_NAME,
            f"{what} name {name[:20]!r}... has {len(name)} characters; "
            f"at most {PROGRAM_NAME_MAX_CHARS}",
        )
    if "/" in name or "\\" in name or ".." in name or not _NAME.fullmatch(name):
        raise StoreError(
            StoreFault.BAD_NAME,
            f"{what} name {name!r} is not a plain file name (letters, digits, _ - . ; "
            "no path separators, no '..', no leading dot)",
        )
    return name


def list_files(root: Path) -> list[ProgramInfo]:
    """The files of directory ``root``, sorted by name; names starting with a dot (the
    temporary files of writes in progress) are not listed."""
    found = []
    for entry in os.scandir(root):
        if entry.name.startswith(".") or not entry.is_file():
            continue
        st = entry.stat()
        found.append(ProgramInfo(entry.name, st.st_size, st.st_mtime))
    return sorted(found, key=lambda p: p.name)


class ProgramStore:
    """NC programs in a directory; safe to use from several threads."""

    def __init__(
        self, root: Path, max_bytes: int = PROGRAM_MAX_BYTES, max_files: int = 1000,
        max_total_bytes: int = STORE_MAX_TOTAL_BYTES,
    ) -> None:
        self.root = Path(root)
        self.root.mkdir(parents=True, exist_ok=True)
        self.max_bytes = max_bytes
        self.max_files = max_files
        self.max_total_bytes = max_total_bytes
        self._lock = threading.Lock()  # serialises writers; readers need no lock

    def _path(self, name: str) -> Path:
        return self.root / check_name(name)

    def remove_unfinished_uploads(self) -> int:
        """Remove the temporary files of uploads a stopped service left (killed in the
        middle of a chunked upload: nothing else would ever remove them, and they count
        against no limit); how many. Called at start, before any client connects."""
        removed = 0
        for temp in self.root.glob(f"{_TEMP_PREFIX}*"):
            try:
                temp.unlink()
                removed += 1
            except OSError:  # gone meanwhile, or not ours to remove: left alone
                continue
        return removed

    def write(self, name: str, data: bytes) -> None:
        """Store ``data`` under ``name``, replacing any earlier content atomically."""
        path = self._path(name)
        if len(data) > self.max_bytes:
            raise StoreError(
                StoreFault.TOO_LARGE,
                f"program {name!r} has {len(data)} bytes; the store takes at most "
                f"{self.max_bytes}",
            )
        with self._lock:
            if not path.exists() and len(self.list()) >= self.max_files:
                raise StoreError(
                    StoreFault.FULL, f"the store holds {self.max_files} files; delete some first"
                )
            self._replace(name, data)

    def used_bytes(self) -> int:
        """Bytes the stored programs hold together."""
        return sum(p.size_bytes for p in self.list())

    def replace_with(self, name: str, temp: Path) -> None:
        """Make the finished temporary file ``temp`` (in ``root``) the program ``name``,
        replacing any earlier content atomically (a chunked upload's commit)."""
        path = self._path(name)
        with self._lock:
            if not path.exists() and len(self.list()) >= self.max_files:
                raise StoreError(
                    StoreFault.FULL, f"the store holds {self.max_files} files; delete some first"
                )
            os.replace(temp, path)

    def _replace(self, name: str, data: bytes) -> None:
        path = self._path(name)
        fd, temp = tempfile.mkstemp(prefix=_TEMP_PREFIX, dir=self.root)
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(data)
            os.replace(temp, path)
        except OSError as exc:
            Path(temp).unlink(missing_ok=True)
            raise StoreError(StoreFault.IO, f"cannot store {name!r}: {exc.strerror}") from None

    def read(self, name: str) -> bytes:
        """The content of ``name``."""
        path = self._path(name)
        try:
            return path.read_bytes()
        except FileNotFoundError:
            raise StoreError(StoreFault.NOT_FOUND, f"no program {name!r} in the store") from None
        except OSError as exc:
            raise StoreError(StoreFault.IO, f"cannot read {name!r}: {exc.strerror}") from None

    def size_bytes(self, name: str) -> int:
        """The size of ``name`` in bytes, without reading it."""
        path = self._path(name)
        try:
            return path.stat().st_size
        except FileNotFoundError:
            raise StoreError(StoreFault.NOT_FOUND, f"no program {name!r} in the store") from None
        except OSError as exc:
            raise StoreError(StoreFault.IO, f"cannot read {name!r}: {exc.strerror}") from None

    def path_of(self, name: str) -> Path:
        """The file of program ``name``, for the kernel to read as a stream (a program
        of 200 MB is never read whole); StoreError when there is none."""
        path = self._path(name)
        if not path.is_file():
            raise StoreError(StoreFault.NOT_FOUND, f"no program {name!r} in the store")
        return path

    def read_text(self, name: str) -> str:
        """The content of ``name`` as text: UTF-8, or CP1252 (ISG's encoding) when not."""
        data = self.read(name)
        try:
            return data.decode("utf-8")
        except UnicodeDecodeError:
            return data.decode("cp1252", errors="replace")

    def exists(self, name: str) -> bool:
        """True when ``name`` is a valid name and stored."""
        try:
            return self._path(name).is_file()
        except (StoreError, OSError):
            return False

    def delete(self, name: str) -> None:
        """Remove ``name``."""
        path = self._path(name)
        with self._lock:
            try:
                path.unlink()
            except FileNotFoundError:
                raise StoreError(StoreFault.NOT_FOUND, f"no program {name!r} in the store") from None
            except OSError as exc:
                raise StoreError(StoreFault.IO, f"cannot delete {name!r}: {exc.strerror}") from None

    def list(self) -> list[ProgramInfo]:
        """Every stored file, sorted by name (uploads in progress are not listed)."""
        return list_files(self.root)
