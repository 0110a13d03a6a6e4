"""The output area on the wire: ADS read, write and read-write at ``OUTPUT_AREA_GROUP``.

Every role lists and downloads (monitor included); operator and admin delete (the
default role of a Write, ``protocol.roles``). Nothing here waits for the writer: the
listing shows the files as they will be once the queue is written; a download of a file
with writes still queued is answered later (``answer``), once the writer has written
them, so that a client that saw an effect (a channel in ERROR) and then downloads the
log sees the line that effect wrote, while every other request is served meanwhile.
Faults map to the program store's ADS codes (``program_service.FAULT_CODES``).
"""

from __future__ import annotations

from collections.abc import Callable

from cnc_objects.protocol.constants import OutputAreaOffset as Op
from cnc_objects.protocol.errors import AdsReturnCode
from cnc_objects.protocol.file_listing import encode_listing

from .program_service import FAULT_CODES, Result, request_name
from .storage.output_area import WHAT
from .storage.output_writer import OutputWriter
from .storage.program_store import StoreError, StoreFault

_E = AdsReturnCode
Answer = Callable[[Result], None]  # a result delivered later, from any thread


def _unknown(offset: int, what: str) -> Result:
    ops = ", ".join(f"{o.value} {o.name}" for o in Op)
    return _E.DEVICE_INVALIDOFFSET, f"output area offset {offset} does not {what}; offsets: {ops}"


class OutputService:
    """ADS operations on the output area behind an ``OutputWriter``."""

    def __init__(self, writer: OutputWriter) -> None:
        self.writer = writer

    def read(self, offset: int, length: int) -> Result:
        """ADS Read: the file list."""
        if offset != Op.LIST:
            return _unknown(offset, "answer a read")
        listing = encode_listing(
            (p.name, p.size_bytes, p.mtime_s) for p in self.writer.listing())
        if len(listing) > length:
            return _E.DEVICE_INVALIDSIZE, f"the list has {len(listing)} bytes; read asked {length}"
        return 0, listing

    def write(self, offset: int, data: bytes) -> Result:
        """ADS Write: delete a file."""
        if offset != Op.DELETE:
            return _unknown(offset, "take a write")
        try:
            name = request_name(data)
            if not self.writer.delete(name):
                raise StoreError(StoreFault.NOT_FOUND, f"no {WHAT} {name!r}")
        except StoreError as exc:
            return FAULT_CODES[exc.fault], str(exc)
        return 0, None

    def read_write(
        self, offset: int, data: bytes, read_length: int, answer: Answer
    ) -> Result | None:
        """ADS ReadWrite: download. None when the answer comes later through ``answer``
        (writes to the file were still queued)."""
        if offset != Op.DOWNLOAD:
            return _unknown(offset, "answer a read-write")
        try:
            name = request_name(data)
            self.writer.area.path(name)  # a bad name is refused now
        except StoreError as exc:
            return FAULT_CODES[exc.fault], str(exc)
        if self.writer.when_written(name, lambda: answer(self._download(name, read_length))):
            return None
        return self._download(name, read_length)

    def _download(self, name: str, read_length: int) -> Result:
        try:
            content = self.writer.area.read(name)
        except StoreError as exc:
            return FAULT_CODES[exc.fault], str(exc)
        if len(content) > read_length:
            return (_E.DEVICE_INVALIDSIZE,
                    f"the file has {len(content)} bytes; read length was {read_length}")
        return 0, content
