"""TwinCAT's file functions on the program store: FOPEN, FREAD, FWRITE, FCLOSE and FDELETE
of the system service (AMS port 10000), as Tc2_System's FB_FileOpen and AdsLib's
``AdsFile`` send them (``SystemServiceGroup``; Beckhoff InfoSys, Tc2_System, FB_FileOpen:
https://infosys.beckhoff.com/content/1033/tcplclib_tc2_system/30977547.html).

A PLC or an ADS tool that writes a CAM program with FB_FileWrite, or reads one back with
FB_FileRead, does it here as on a TwinCAT target. The only path served is PATH_GENERIC
(``ePath`` 1, or 0), and it is the program store: a file name is a store name (no
directories). What a handle is:

- opened for writing (``FOPEN_MODEWRITE``, with or without BINARY/TEXT): an upload in
  chunks (``program_uploads``): the bytes go to a temporary file, FCLOSE makes it the
  program atomically (a reader sees the old program or the new one whole); until then
  nothing is listed. The store's limits hold (``program_max_bytes``,
  ``store_max_total_bytes``): beyond them the write is refused and the handle is closed
  with nothing stored;
- opened for reading (``FOPEN_MODEREAD``): reads from the start, each FREAD up to its
  read length (fewer at the end; 0 bytes: the end);
- gone when its connection ends: a write in progress is abandoned, nothing is left.

Append and read-write (``a``, ``+``) are refused 0x706: the store replaces programs
whole. Writing (FOPEN for writing, FWRITE, FDELETE) needs the admin role as every change
of the store does; reading needs monitor. Text mode is binary here (no CR LF translation:
a CNC reads either). A connection holds at most ``HANDLES_PER_CONNECTION`` files.
"""

from __future__ import annotations

import logging
import struct
from collections.abc import Hashable
from dataclasses import dataclass
from typing import BinaryIO

from cnc_objects.protocol.constants import (
    FILE_PATH_GENERIC,
    FILE_PATH_SHIFT,
    PROGRAM_MAX_BYTES,
    FileOpenMode,
    SystemServiceGroup,
)
from cnc_objects.protocol.errors import AdsReturnCode
from cnc_objects.protocol.roles import Role, roles_that_may

from ..program_service import FAULT_CODES, Result, request_name
from ..storage.program_store import StoreError, StoreFault, check_name
from ..storage.program_uploads import ProgramUploads

log = logging.getLogger(__name__)

_E = AdsReturnCode
_G = SystemServiceGroup
_HANDLE = struct.Struct("<I")
#: Files one connection may hold open (a PLC's FB_File* blocks use a handful).
HANDLES_PER_CONNECTION = 32
_HANDLE_MAX = 0xFFFF  # hFile is a UINT in Tc2_System
_MODES_SERVED = FileOpenMode.READ | FileOpenMode.WRITE | FileOpenMode.BINARY | FileOpenMode.TEXT
#: the FOPEN flags beyond the mode that TwinCAT defines (ENSURE_DIR, ENABLE_DIR,
#: OVERWRITE, OVERWRITE_RENAME): they do nothing in a store without directories
_FLAGS_IGNORED = 0x3C0


@dataclass(slots=True)
class _OpenFile:
    """One handle: its connection, its program and how it was opened."""

    holder: Hashable
    name: str
    reader: BinaryIO | None  # opened for reading; None: writing (an upload)
    written_bytes: int = 0


class FileService:
    """The file functions of the system service over a store's ``ProgramUploads``."""

    def __init__(self, uploads: ProgramUploads) -> None:
        self.uploads = uploads
        self.store = uploads.store
        self._files: dict[int, _OpenFile] = {}
        self._next_handle = 1

    @staticmethod
    def serves(group: int) -> bool:
        """True when ``group`` is one of the file functions (at the system service), served
        or answered 0x701."""
        return group in _GROUPS

    def read_write(self, holder: Hashable, group: int, offset: int, data: bytes,
                   read_length: int, role: Role = Role.ADMIN) -> Result:
        """Serve one file function for connection ``holder`` of ``role``."""
        try:
            match group:
                case _G.FOPEN:
                    return self._open(holder, offset, data, role)
                case _G.FREAD:
                    return self._read(holder, offset, read_length)
                case _G.FWRITE:
                    return self._write(holder, offset, data, role)
                case _G.FCLOSE:
                    return self._close(holder, offset)
                case _G.FDELETE:
                    return self._delete(offset, data, role)
        except StoreError as exc:
            return FAULT_CODES[exc.fault], str(exc)
        served = ", ".join(f"{g.value} {g.name}" for g in _G)
        return _E.DEVICE_SRVNOTSUPP, f"file function {group} is not served; served: {served}"

    # ------------------------------------------------------------ functions

    def _open(self, holder: Hashable, flags: int, data: bytes, role: Role) -> Result:
        mode = FileOpenMode(flags & 0xFFFF & ~_FLAGS_IGNORED)
        path = flags >> FILE_PATH_SHIFT
        if path not in (0, FILE_PATH_GENERIC):
            return _E.DEVICE_NOTFOUND, (f"path {path} is not served: only PATH_GENERIC (1), "
                                        "the program store")
        reading = bool(mode & FileOpenMode.READ)
        if mode & ~_MODES_SERVED or reading == bool(mode & FileOpenMode.WRITE):
            return _E.DEVICE_INVALIDDATA, (
                f"open mode 0x{int(mode):x} is not served: open for reading (FOPEN_MODEREAD) or "
                "for writing (FOPEN_MODEWRITE), with BINARY or TEXT; the store replaces "
                "programs whole (no append, no '+')")
        if not reading and not role.may(Role.ADMIN):
            return _E.DEVICE_INVALIDACCESS, (f"role {role.label} may not write the program "
                                             f"store; {roles_that_may(Role.ADMIN)} may")
        name = check_name(request_name(data))
        if sum(1 for f in self._files.values() if f.holder == holder) >= HANDLES_PER_CONNECTION:
            return _E.DEVICE_NOMEMORY, (f"this connection holds {HANDLES_PER_CONNECTION} files "
                                        "open; close one first")
        handle = self._free_handle()
        if reading:
            try:
                reader = (self.store.root / name).open("rb")
            except FileNotFoundError:
                raise StoreError(StoreFault.NOT_FOUND, f"no program {name!r} in the store") from None
            except OSError as exc:
                raise StoreError(StoreFault.IO, f"cannot read {name!r}: {exc.strerror}") from None
            self._files[handle] = _OpenFile(holder, name, reader)
        else:
            self.uploads.open(_upload_key(holder, handle), name)
            self._files[handle] = _OpenFile(holder, name, None)
        log.debug("file %r opened for %s, handle %d", name, "reading" if reading else "writing",
                  handle)
        return 0, _HANDLE.pack(handle)

    def _read(self, holder: Hashable, handle: int, read_length: int) -> Result:
        file = self._file(holder, handle)
        if isinstance(file, tuple):
            return file
        if file.reader is None:
            return _E.DEVICE_INVALIDDATA, f"handle {handle} ({file.name!r}) is open for writing"
        if read_length > PROGRAM_MAX_BYTES:
            return _E.DEVICE_INVALIDSIZE, (f"a read takes at most {PROGRAM_MAX_BYTES} bytes (one "
                                           f"frame); {read_length} asked")
        try:
            return 0, file.reader.read(read_length)
        except OSError as exc:
            return _E.DEVICE_ERROR, f"cannot read {file.name!r}: {exc.strerror}"

    def _write(self, holder: Hashable, handle: int, data: bytes, role: Role) -> Result:
        file = self._file(holder, handle)
        if isinstance(file, tuple):
            return file
        if file.reader is not None:
            return _E.DEVICE_INVALIDDATA, f"handle {handle} ({file.name!r}) is open for reading"
        if not role.may(Role.ADMIN):  # the route's role may differ from the opener's
            return _E.DEVICE_INVALIDACCESS, (f"role {role.label} may not write the program "
                                             f"store; {roles_that_may(Role.ADMIN)} may")
        try:
            self.uploads.write(_upload_key(holder, handle), file.written_bytes, data)
        except StoreError:
            del self._files[handle]  # the upload is abandoned: the handle is gone with it
            raise
        file.written_bytes += len(data)
        return 0, b""

    def _close(self, holder: Hashable, handle: int) -> Result:
        file = self._file(holder, handle)
        if isinstance(file, tuple):
            return file
        del self._files[handle]
        if file.reader is not None:
            file.reader.close()
            return 0, b""
        self.uploads.commit(_upload_key(holder, handle), file.written_bytes)
        return 0, b""

    def _delete(self, flags: int, data: bytes, role: Role) -> Result:
        if not role.may(Role.ADMIN):
            return _E.DEVICE_INVALIDACCESS, (f"role {role.label} may not delete from the "
                                             f"program store; {roles_that_may(Role.ADMIN)} may")
        if flags >> FILE_PATH_SHIFT not in (0, FILE_PATH_GENERIC):
            return _E.DEVICE_NOTFOUND, "only PATH_GENERIC (1), the program store, is served"
        self.store.delete(request_name(data))
        return 0, b""

    # ------------------------------------------------------------ handles

    def _file(self, holder: Hashable, handle: int) -> _OpenFile | tuple[int, str]:
        file = self._files.get(handle)
        if file is None or file.holder != holder:  # another connection's handle is unknown
            return _E.DEVICE_INVALIDOFFSET, (f"no file open with handle {handle} on this "
                                             "connection (FOPEN gives one)")
        return file

    def _free_handle(self) -> int:
        handle = self._next_handle
        while handle in self._files:  # at most the open ones are skipped
            handle = handle % _HANDLE_MAX + 1
        self._next_handle = handle % _HANDLE_MAX + 1
        return handle

    def connection_ended(self, holder: Hashable) -> None:
        """``holder``'s connection is gone: its files are closed, its writes abandoned."""
        for handle in [h for h, f in self._files.items() if f.holder == holder]:
            file = self._files.pop(handle)
            if file.reader is not None:
                file.reader.close()
            else:
                self.uploads.abandon(_upload_key(holder, handle), "the connection ended")


#: the system service's file functions, served or not (100 OPENCREATE .. 139 RMDIR): one
#: not served gets 0x701 with the list of those that are, not "invalid index group"
_GROUPS = frozenset(range(100, 140))


def _upload_key(holder: Hashable, handle: int) -> tuple[str, Hashable, int]:
    """The key of a handle's upload: apart from the connection's own chunked upload."""
    return ("file", holder, handle)
