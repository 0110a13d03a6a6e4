"""AMS/TCP framing and the AMS header, as Beckhoff's ADS specification lays them out.

Every ADS message on TCP is one AMS/TCP frame; all integers are little-endian::

    AMS/TCP header (6 bytes)
       0  reserved      u16   0 for an AMS command (else a router command, below)
       2  length        u32   bytes that follow: the AMS header and the data
    AMS header (32 bytes)
       6  target net id 6 x u8   AMS Net ID of the receiver (a.b.c.d.e.f)
      12  target port   u16      AMS port of the receiver (851 PLC, 551 GEO, ...)
      14  source net id 6 x u8   AMS Net ID of the sender
      20  source port   u16      AMS port of the sender
      22  command id    u16      ADS command (1 ReadDeviceInfo ... 9 ReadWrite)
      24  state flags   u16      0x0004 request, 0x0005 response (AmsStateFlag)
      26  data length   u32      bytes of ADS data after the header
      30  error code    u32      AMS error (0x6 port not found, ...); 0 otherwise
      34  invoke id     u32      chosen by the requester, echoed in the response
    data (data length bytes): the command's payload (see ``ads_commands``)

A first u16 other than 0 is a command to the local AMS router (``AmsTcpCommand``: port
connect, port close, get local Net ID): no AMS header follows, only the command's data
(``length`` bytes); such a frame is a ``RouterFrame`` (``protocol.ams_router``).

``AmsStreamParser`` cuts frames out of a byte stream however TCP segments it (a frame
split over several segments, several frames in one segment). It never raises on bad
input: each frame it cannot use becomes a ``SkippedFrame`` that says why, so that the
server can answer (when the header could be read) and keep the connection; only a frame
longer than the configured maximum ends the stream, because what follows it cannot be
trusted to be read in time.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from enum import IntEnum

from .constants import AMS_MAX_FRAME_BYTES, AmsStateFlag

AMS_TCP_HEADER = struct.Struct("<HI")
AMS_HEADER = struct.Struct("<6sH6sHHHIII")
#: The AMS/TCP header and the AMS header in one struct: one ``pack`` per frame sent.
FRAME_HEADER = struct.Struct("<HI6sH6sHHHIII")
AMS_TCP_HEADER_BYTES = AMS_TCP_HEADER.size  # 6
AMS_HEADER_BYTES = AMS_HEADER.size  # 32

REQUEST_FLAGS = AmsStateFlag.ADS_COMMAND  # 0x0004
RESPONSE_FLAGS = AmsStateFlag.ADS_COMMAND | AmsStateFlag.RESPONSE  # 0x0005


# --------------------------------------------------------------------------- net ids


def parse_net_id(text: str) -> bytes:
    """The 6 bytes of an AMS Net ID written ``a.b.c.d.e.f`` (each 0..255).

    Raises ``ValueError`` naming what is wrong."""
    parts = text.strip().split(".")
    if len(parts) != 6 or not all(p.isdigit() for p in parts):
        raise ValueError(f"{text!r} is not an AMS Net ID: six numbers a.b.c.d.e.f")
    values = [int(p) for p in parts]
    if any(v > 255 for v in values):
        raise ValueError(f"{text!r} is not an AMS Net ID: each number is 0..255")
    return bytes(values)


def format_net_id(raw: bytes) -> str:
    """``a.b.c.d.e.f`` for the 6 bytes of an AMS Net ID."""
    return ".".join(str(b) for b in raw)


# --------------------------------------------------------------------------- header


@dataclass(frozen=True, slots=True)
class AmsHeader:
    """The 32-byte AMS header (layout in the module docstring). Net IDs are 6 bytes."""

    target_net_id: bytes
    target_port: int
    source_net_id: bytes
    source_port: int
    command_id: int
    state_flags: int
    data_length: int
    error_code: int
    invoke_id: int

    @classmethod
    def decode(cls, raw: bytes, offset: int = 0) -> AmsHeader:
        """The header in ``raw`` at ``offset`` (32 bytes must be there)."""
        return cls(*AMS_HEADER.unpack_from(raw, offset))

    def encode(self) -> bytes:
        """The 32 header bytes."""
        return AMS_HEADER.pack(
            self.target_net_id, self.target_port, self.source_net_id, self.source_port,
            self.command_id, self.state_flags, self.data_length, self.error_code,
            self.invoke_id,
        )

    @property
    def is_response(self) -> bool:
        """The response bit is set: a reply, not a request."""
        return bool(self.state_flags & AmsStateFlag.RESPONSE)


@dataclass(frozen=True, slots=True)
class AmsFrame:
    """One AMS/TCP frame: its header and its ADS data."""

    header: AmsHeader
    data: bytes


@dataclass(frozen=True, slots=True)
class RouterFrame:
    """One AMS/TCP frame for the router itself: its command (the AMS/TCP header's first
    u16, not 0; ``AmsTcpCommand``) and the data after the 6-byte header (no AMS header)."""

    command: int
    data: bytes


def encode_frame(
    target_net_id: bytes, target_port: int, source_net_id: bytes, source_port: int,
    command_id: int, state_flags: int, invoke_id: int, data: bytes = b"", error_code: int = 0,
) -> bytes:
    """A whole AMS/TCP frame: both headers (lengths filled in) and ``data``."""
    return FRAME_HEADER.pack(
        0, AMS_HEADER_BYTES + len(data), target_net_id, target_port, source_net_id,
        source_port, command_id, state_flags, len(data), error_code, invoke_id,
    ) + data


def encode_reply_frame(request: AmsHeader, data: bytes = b"", error_code: int = 0) -> bytes:
    """The frame that answers ``request``: addresses swapped, same command and invoke id."""
    return encode_frame(
        request.source_net_id, request.source_port, request.target_net_id,
        request.target_port, request.command_id, RESPONSE_FLAGS, request.invoke_id, data,
        error_code,
    )


# --------------------------------------------------------------------------- stream


class FrameProblem(IntEnum):
    """Why a frame of the stream could not be used."""

    TRUNCATED_HEADER = 1  # the AMS/TCP length leaves no room for the 32-byte AMS header
    LENGTH_MISMATCH = 2  # the AMS header's data length disagrees with the AMS/TCP length
    TOO_LONG = 4  # longer than the maximum: the stream ends here


@dataclass(frozen=True, slots=True)
class SkippedFrame:
    """A frame that was skipped, with the reason; ``header`` when it could be read (so
    the sender can be answered), ``length`` the AMS/TCP length it announced."""

    problem: FrameProblem
    length: int
    header: AmsHeader | None = None

    def __str__(self) -> str:
        return {
            FrameProblem.TRUNCATED_HEADER:
                f"AMS/TCP length {self.length} is shorter than the 32-byte AMS header",
            FrameProblem.LENGTH_MISMATCH:
                f"AMS/TCP length {self.length} does not match the AMS data length "
                f"{self.header.data_length if self.header else '?'} + 32",
            FrameProblem.TOO_LONG: f"AMS/TCP length {self.length} exceeds the maximum",
        }[self.problem]


#: What ``AmsStreamParser.feed`` yields for each frame of the stream.
StreamItem = AmsFrame | RouterFrame | SkippedFrame


class AmsStreamParser:
    """Cuts AMS/TCP frames out of a byte stream: ``feed`` bytes, get complete frames.

    ``max_frame_bytes`` bounds the AMS/TCP length of one frame; the first frame over it
    yields ``SkippedFrame(TOO_LONG)`` and the parser takes no more input (``closed``).
    """

    def __init__(self, max_frame_bytes: int = AMS_MAX_FRAME_BYTES) -> None:
        self.max_frame_bytes = max_frame_bytes
        self.closed = False
        self._pending = bytearray()
        self._need = AMS_TCP_HEADER_BYTES  # bytes in _pending before a frame can end

    @property
    def buffered(self) -> int:
        """Bytes received that do not make a whole frame yet."""
        return len(self._pending)

    def feed(self, data: bytes) -> list[StreamItem]:
        """Take ``data`` (any amount); return the frames it completes, in order."""
        out: list[StreamItem] = []
        if self.closed:
            return out
        if self._pending:
            self._pending += data
            if len(self._pending) < self._need:
                return out
            data = bytes(self._pending)
            self._pending.clear()
        pos, end = 0, len(data)
        unpack_tcp = AMS_TCP_HEADER.unpack_from
        while end - pos >= AMS_TCP_HEADER_BYTES:
            reserved, length = unpack_tcp(data, pos)
            if length > self.max_frame_bytes:
                self.closed = True
                out.append(SkippedFrame(FrameProblem.TOO_LONG, length))
                return out
            stop = pos + AMS_TCP_HEADER_BYTES + length
            if stop > end:
                self._need = AMS_TCP_HEADER_BYTES + length
                break
            out.append(_frame(data, pos + AMS_TCP_HEADER_BYTES, length, reserved))
            pos = stop
        else:
            self._need = AMS_TCP_HEADER_BYTES
        if pos < end:
            self._pending += data[pos:]
        return out


def _frame(data: bytes, start: int, length: int, reserved: int) -> StreamItem:
    """The frame of ``length`` bytes at ``start`` (after its AMS/TCP header)."""
    if reserved != 0:  # a command to the router: its data only, no AMS header
        return RouterFrame(reserved, data[start:start + length])
    if length < AMS_HEADER_BYTES:
        return SkippedFrame(FrameProblem.TRUNCATED_HEADER, length)
    header = AmsHeader(*AMS_HEADER.unpack_from(data, start))
    if header.data_length != length - AMS_HEADER_BYTES:
        return SkippedFrame(FrameProblem.LENGTH_MISMATCH, length, header)
    return AmsFrame(header, data[start + AMS_HEADER_BYTES:start + length])
