"""A chunked upload fed piece by piece: for a gateway that receives a program in pieces
(cnc-web forwards a browser's slices as they come) and never holds it whole.

    upload = ChunkedUpload(client, "finish.nc", size_bytes)
    await upload.open()                 # refused here when the limits will not take it
    async for piece in pieces:
        await upload.write(piece)       # in frames of UPLOAD_CHUNK_BYTES
    await upload.commit()               # the program replaces its older version atomically

One upload per connection at a time (the service's rule): a second upload at once needs a
client of its own. Any refusal abandons the upload on the service; ``abandon`` drops it
on purpose, and a connection that ends abandons it too.
"""

from __future__ import annotations

import struct

from cnc_objects.protocol.constants import PROGRAM_STORE_GROUP, UPLOAD_CHUNK_BYTES, CncPort
from cnc_objects.protocol.constants import ProgramStoreOffset as Op
from cnc_objects.protocol.datatypes import STRING_ENCODING

from .client_core import ClientCore

_U64 = struct.Struct("<Q")


def name_bytes(name: str) -> bytes:
    """A program name as the store's requests carry it: CP1252, NUL."""
    return name.encode(STRING_ENCODING) + b"\x00"


class ChunkedUpload:
    """The upload of program ``name`` through ``client``; ``size_bytes`` (when known) is
    announced at the open, so that the service refuses a program over its limits at once."""

    def __init__(self, client: ClientCore, name: str, size_bytes: int | None = None) -> None:
        self.client = client
        self.name = name
        self.size_bytes = size_bytes
        self.sent_bytes = 0

    async def _write(self, offset: int, data: bytes) -> None:
        await self.client.write_raw(CncPort.COM, PROGRAM_STORE_GROUP, offset, data)

    async def open(self) -> None:
        """Start the upload on the service (an earlier one of this connection is abandoned)."""
        announced = b"" if self.size_bytes is None else _U64.pack(self.size_bytes)
        await self._write(Op.UPLOAD_OPEN, name_bytes(self.name) + announced)
        self.sent_bytes = 0

    async def write(self, data: bytes | bytearray | memoryview) -> None:
        """Send the next ``data`` of the program, in frames of ``UPLOAD_CHUNK_BYTES``."""
        view = memoryview(data)
        for start in range(0, len(view), UPLOAD_CHUNK_BYTES):
            chunk = view[start:start + UPLOAD_CHUNK_BYTES]
            await self._write(Op.UPLOAD_CHUNK, _U64.pack(self.sent_bytes) + chunk)
            self.sent_bytes += len(chunk)

    async def commit(self) -> int:
        """Finish: the program replaces its older version atomically; its size in bytes."""
        await self._write(Op.UPLOAD_COMMIT, _U64.pack(self.sent_bytes))
        return self.sent_bytes

    async def abandon(self) -> None:
        """Drop the upload: the service removes what arrived."""
        await self._write(Op.UPLOAD_ABANDON, b"")
