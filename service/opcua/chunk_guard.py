"""A thin guard in front of asyncua's connection handler: every chunk's header is checked
as soon as its first 8 bytes arrive, before asyncua buffers its body, and a message that
asyncua cannot decode closes its connection with an OPC UA ERR message and one log line
(docs/opcua.md "Bad input").

asyncua 2.1 buffers a chunk until the size its header declares has arrived (4 GiB if it
says so), hands a chunk of any message type to its processor, and logs a decoding error
with a traceback and leaves the connection open. Here (OPC 10000-6, 7.1.2 and 7.1.5):

- a header whose message type is not HEL, OPN, MSG or CLO (a client sends nothing else),
  or whose chunk type is not F, C or A: Bad_TcpMessageTypeInvalid;
- a chunk smaller than its own header: Bad_DecodingError;
- a chunk larger than the server's receive buffer (65 535 bytes, what the server's
  Acknowledge told): Bad_TcpMessageTooLarge;
- a message whose body does not decode (a Hello of nonsense, a chunk on no channel):
  Bad_DecodingError (or the status asyncua raised).

Each: ERR with the status and a reason, then the connection is closed; nothing else
changes. The guard is installed by ``install`` (asyncua's server module builds its
``BinaryServer`` by name at ``Server.start``: ours makes this protocol).
"""

from __future__ import annotations

import asyncio
import logging
import struct
from dataclasses import dataclass
from typing import Any

from asyncua import ua
from asyncua.common.utils import Buffer, ServiceError
from asyncua.server import server as asyncua_server
from asyncua.server.binary_server_asyncio import BinaryServer, OPCUAProtocol
from asyncua.ua.ua_binary import uatcp_to_binary

log = logging.getLogger(__name__)

_S = ua.StatusCodes
#: The message types a client sends (Part 6, 7.1.2.2 and 6.7.2.2).
CLIENT_MESSAGE_TYPES = frozenset({b"HEL", b"OPN", b"MSG", b"CLO"})
CHUNK_TYPES = frozenset({b"F", b"C", b"A"})
_HEADER = struct.Struct("<3scI")  # message type, chunk type, message size
_SECURE_HEADER_BYTES = 12  # OPN, MSG and CLO carry the secure channel id


def head_status(head: bytes, max_chunk_bytes: int) -> tuple[int, str] | None:
    """The status that refuses a chunk with the 8-byte ``head``, and why; None when it
    may be read on."""
    message_type, chunk_type, size = _HEADER.unpack(head)
    if message_type not in CLIENT_MESSAGE_TYPES or chunk_type not in CHUNK_TYPES:
        return _S.BadTcpMessageTypeInvalid, f"message type {head[:4]!r} is not one a client sends"
    least = 8 if message_type == b"HEL" else _SECURE_HEADER_BYTES
    if size < least:
        return _S.BadDecodingError, f"a {message_type.decode()} chunk of {size} bytes is " \
            "shorter than its header"
    if size > max_chunk_bytes:
        return _S.BadTcpMessageTooLarge, f"a chunk of {size} bytes is larger than the " \
            f"receive buffer ({max_chunk_bytes} bytes)"
    return None


@dataclass(frozen=True, slots=True)
class _Refusal:
    """A refused chunk, queued behind the chunks before it (their answers go first)."""

    status: int
    reason: str


class GuardedProtocol(OPCUAProtocol):  # type: ignore[misc]  # asyncua: Any to mypy
    """asyncua's connection handler with its chunks checked (module docstring)."""

    _refused = False

    def data_received(self, data: bytes) -> None:
        if self._refused or self.transport is None or self.transport.is_closing():
            return
        pending = self._buffer + data if self._buffer else data
        at = 0
        while len(pending) - at >= 8:  # each chunk asyncua has not taken yet, by its head
            refused = head_status(pending[at:at + 8], self.limits.max_recv_buffer)
            if refused is not None:
                cut = at - len(self._buffer)
                if cut > 0:  # the whole chunks before it are served first
                    super().data_received(data[:cut])
                self._refuse_after_queued(_Refusal(*refused))
                return
            at += _HEADER.unpack_from(pending, at)[2]
        super().data_received(data)

    def _refuse_after_queued(self, refusal: _Refusal) -> None:
        """Read no more; answer ``refusal`` once the chunks queued before it are served."""
        self._refused = True
        if self.transport is None or self.transport.is_closing():
            return
        self.transport.pause_reading()
        try:
            self.messages.put_nowait((refusal, None))
        except asyncio.QueueFull:
            self.refuse(refusal.status, refusal.reason)

    async def _process_one_msg(self, header: Any, buf: Buffer) -> bool:
        if isinstance(header, _Refusal):
            self.refuse(header.status, header.reason)
            return False
        try:
            served: bool = await super()._process_one_msg(header, buf)
            return served
        except (ua.UaStatusCodeError, ServiceError) as exc:
            self.refuse(exc.code, ua.StatusCode(exc.code).doc or type(exc).__name__)
        except Exception as exc:  # asyncua could not decode what the client sent
            self.refuse(_S.BadDecodingError, f"{type(exc).__name__}: {exc}")
        return False

    def refuse(self, status: int, reason: str) -> None:
        """Answer ERR ``status`` with ``reason`` and close the connection."""
        log.warning("OPC UA connection from %s closed: %s (%s)", self.peer_name, reason,
                    ua.StatusCode(status).name)
        if self.transport is None or self.transport.is_closing():
            return
        error = ua.ErrorMessage(ua.StatusCode(status), reason[:200])
        self.transport.write(uatcp_to_binary(ua.MessageType.Error, error))
        self.transport.close()


class GuardedBinaryServer(BinaryServer):  # type: ignore[misc]
    """asyncua's listening server, making ``GuardedProtocol`` connections."""

    def _make_protocol(self) -> GuardedProtocol:
        return GuardedProtocol(iserver=self.iserver, policies=self._policies,
                               clients=self.clients, closing_tasks=self.closing_tasks,
                               limits=self.limits)


def install() -> None:
    """Make asyncua's ``Server.start`` listen with ``GuardedBinaryServer`` (idempotent;
    the service runs one OPC UA server)."""
    asyncua_server.BinaryServer = GuardedBinaryServer
