"""The program store on the wire: ADS read, write and read-write at ``PROGRAM_STORE_GROUP``.

Turns the store's operations into ADS replies: (0, payload) or (code, message). Nothing
here waits for anything but the store's own directory: the kernel writes no file here. Store
faults map to ADS codes a pyads user knows: a bad name 0x706, a missing program 0x70C,
an oversized upload or a short read buffer 0x705, a full store 0x70A.
"""

from __future__ import annotations

import logging
import struct
from collections.abc import Callable, Hashable
from concurrent.futures import ThreadPoolExecutor

from cnc_objects.protocol.constants import ProgramStoreOffset as Op
from cnc_objects.protocol.datatypes import STRING_ENCODING
from cnc_objects.protocol.errors import AdsReturnCode
from cnc_objects.protocol.file_listing import encode_listing
from cnc_objects.protocol.program_lines import (
    REPLY_HEADER_BYTES,
    decode_lines_request,
    encode_lines_reply,
)

from .storage.program_line_index import ProgramLines
from .storage.program_store import ProgramStore, StoreError, StoreFault, check_name
from .storage.program_uploads import ProgramUploads

log = logging.getLogger(__name__)

_E = AdsReturnCode
Result = tuple[int, bytes | str | None]
Answer = Callable[[Result], None]  # a result delivered later, from another thread

FAULT_CODES: dict[StoreFault, AdsReturnCode] = {
    StoreFault.BAD_NAME: _E.DEVICE_INVALIDDATA,
    StoreFault.NOT_FOUND: _E.DEVICE_NOTFOUND,
    StoreFault.TOO_LARGE: _E.DEVICE_INVALIDSIZE,
    StoreFault.FULL: _E.DEVICE_NOMEMORY,
    StoreFault.IO: _E.DEVICE_ERROR,
    StoreFault.OUT_OF_ORDER: _E.DEVICE_INVALIDDATA,
    StoreFault.NO_UPLOAD: _E.DEVICE_INVALIDSTATE,
}

_U64 = struct.Struct("<Q")


def request_name(data: bytes) -> str:
    """The file name a request carries: CP1252 text up to the first NUL."""
    try:
        return data.split(b"\x00", 1)[0].decode(STRING_ENCODING)
    except UnicodeDecodeError:
        raise StoreError(StoreFault.BAD_NAME, "a program name must be CP1252 text") from None


def _unknown(offset: int, what: str) -> Result:
    ops = ", ".join(f"{o.value} {o.name}" for o in Op)
    return _E.DEVICE_INVALIDOFFSET, f"program store offset {offset} does not {what}; offsets: {ops}"


class ProgramStoreService:
    """ADS operations on a ``ProgramStore``."""

    def __init__(self, store: ProgramStore) -> None:
        self.store = store
        self.lines = ProgramLines(store)
        self.uploads = ProgramUploads(store, self.lines.adopt)
        # a program not yet indexed is read once, whole, off the event loop (0.2 s for 200 MB)
        self._indexer = ThreadPoolExecutor(1, thread_name_prefix="program-lines")

    def close(self) -> None:
        """Stop the indexing thread (an index under way is finished, not answered)."""
        self._indexer.shutdown(wait=False, cancel_futures=True)

    def read(self, offset: int, length: int) -> Result:
        """ADS Read: the program list."""
        if offset != Op.LIST:
            return _unknown(offset, "answer a read")
        listing = encode_listing((p.name, p.size_bytes, p.mtime_s) for p in self.store.list())
        if len(listing) > length:
            return _E.DEVICE_INVALIDSIZE, f"the list has {len(listing)} bytes; read asked {length}"
        return 0, listing

    def write(self, offset: int, data: bytes, holder: Hashable = None) -> Result:
        """ADS Write: upload (whole, or in chunks for connection ``holder``) or delete."""
        try:
            match offset:
                case Op.UPLOAD:
                    name, sep, content = data.partition(b"\x00")
                    if not sep:
                        return _E.DEVICE_INVALIDDATA, "an upload is the name, a NUL, then the content"
                    self.store.write(request_name(name), content)
                    log.info("program %r uploaded (%d bytes)", request_name(name), len(content))
                case Op.DELETE:
                    self.store.delete(request_name(data))
                case Op.UPLOAD_OPEN:
                    name, _, announced = data.partition(b"\x00")
                    if announced and len(announced) != _U64.size:
                        return _E.DEVICE_INVALIDSIZE, "an open is the name, NUL, [size u64]"
                    self.uploads.open(holder, request_name(name),
                                      _U64.unpack(announced)[0] if announced else None)
                case Op.UPLOAD_CHUNK:
                    if len(data) < _U64.size:
                        return _E.DEVICE_INVALIDSIZE, "a chunk is its position (u64), then bytes"
                    self.uploads.write(holder, _U64.unpack_from(data)[0], data[_U64.size:])
                case Op.UPLOAD_COMMIT:
                    if len(data) != _U64.size:
                        return _E.DEVICE_INVALIDSIZE, "a commit is the total size (u64)"
                    self.uploads.commit(holder, _U64.unpack(data)[0])
                case Op.UPLOAD_ABANDON:
                    self.uploads.abandon(holder, "the client abandoned it")
                case _:
                    return _unknown(offset, "take a write")
        except StoreError as exc:
            return FAULT_CODES[exc.fault], str(exc)
        return 0, None

    def read_write(self, offset: int, data: bytes, read_length: int,
                   answer: Answer | None = None) -> Result | None:
        """ADS ReadWrite: download, or a window of a program's lines. None when the answer
        comes later through ``answer`` (a program whose lines are not yet indexed)."""
        if offset == Op.READ_LINES:
            return self._read_lines(data, read_length, answer)
        if offset != Op.DOWNLOAD:
            return _unknown(offset, "answer a read-write")
        try:
            name = request_name(data)
            size_bytes = self.store.size_bytes(name)  # a CAM program is not read to refuse it
            if size_bytes > read_length:
                return (
                    _E.DEVICE_INVALIDSIZE,
                    f"the program has {size_bytes} bytes; read length was {read_length} (a "
                    "program larger than one frame is read with FOPEN/FREAD at port 10000)",
                )
            content = self.store.read(name)
        except StoreError as exc:
            return FAULT_CODES[exc.fault], str(exc)
        if len(content) > read_length:  # grew since: replaced in between
            return (
                _E.DEVICE_INVALIDSIZE,
                f"the program has {len(content)} bytes; read length was {read_length}",
            )
        return 0, content

    def _read_lines(self, data: bytes, read_length: int, answer: Answer | None) -> Result | None:
        """READ_LINES: whole lines from the first asked, as many as the read length holds;
        later through ``answer`` when the program must be indexed first."""
        try:
            request = decode_lines_request(data)
            check_name(request.name)
        except ValueError as exc:
            return _E.DEVICE_INVALIDDATA, str(exc)
        except StoreError as exc:
            return FAULT_CODES[exc.fault], str(exc)
        if read_length <= REPLY_HEADER_BYTES:
            return _E.DEVICE_INVALIDSIZE, (f"a lines reply needs more than {REPLY_HEADER_BYTES} "
                                           f"bytes; read length was {read_length}")
        room = read_length - REPLY_HEADER_BYTES

        def window() -> Result:
            try:
                return 0, encode_lines_reply(self.lines.read(request, room))
            except StoreError as exc:
                return FAULT_CODES[exc.fault], str(exc)

        if answer is None or self.lines.indexed(request.name):
            return window()
        self._indexer.submit(lambda: answer(window()))
        return None
