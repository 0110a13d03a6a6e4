"""The private link between cnc-service and its OPC UA process (``host``, ``child``):
what travels and how it is framed, without I/O.

A frame is a 4-byte little-endian length, then a pickled tuple whose first member is a
``Link`` kind. Pickle, not msgpack: the values are the objects' getters' own Python
values (ints, floats, strings, tuples), which must arrive as they are; both ends are the
same program, and the link is a socket pair only they hold (docs/opcua.md "One process
of its own").

::

    +----------------+---------------------------------------+
    | length: u32 LE | pickle((Link, field, ...)), length B  |
    +----------------+---------------------------------------+
"""

from __future__ import annotations

import copyreg
import io
import pickle
import struct
from dataclasses import dataclass
from enum import IntEnum
from typing import Any

from cnc_objects.protocol.constants import TransmissionMode
from cnc_objects.protocol.datatypes import DataType, parse_type

_LENGTH = struct.Struct("<I")
#: A frame longer than this is a broken peer, not a message (the start message, the
#: objects' metadata, is the longest: some 2 MB for a large machine).
FRAME_MAX_BYTES = 256 << 20


class Link(IntEnum):
    """What a frame carries (first member of its tuple)."""

    # child -> parent on the calls socket (the child waits for the answer)
    READ = 1  # (READ, [object index, ...]) -> (READ, [value or None, ...])
    SUBSCRIBE = 2  # (SUBSCRIBE, key, envelope, index, cycle_ns) -> (SUBSCRIBE, code, handle|msg)
    # child -> parent on the events socket (no answer, or one later)
    UNSUBSCRIBE = 3  # (UNSUBSCRIBE, envelope, handle)
    WRITE = 4  # (WRITE, call, [(index, data), ...], holder) -> (WRITTEN, call, results)
    READY = 5  # (READY, facts dict): serving
    FAILED = 6  # (FAILED, kind, message): cannot serve; the child ends
    # parent -> child on the events socket
    START = 7  # (START, facts dict): what the child serves
    NOTIFY = 8  # (NOTIFY, key, envelope, port, samples)
    WRITTEN = 9  # (WRITTEN, call, [(code, message), ...])


@dataclass(frozen=True, slots=True)
class ReadFailed:
    """A READ answer's value where the object's getter failed."""

    message: str


def _data_type(dtype: DataType) -> tuple[Any, tuple[str]]:
    """A data type travels as its name (it holds a ``struct.Struct``, which pickle
    cannot carry) and is the same cached type again at the other end."""
    return parse_type, (dtype.name,)


_DISPATCH = copyreg.dispatch_table.copy()
_DISPATCH[DataType] = _data_type


def frame(message: tuple[Any, ...]) -> bytes:
    """``message`` as one frame."""
    out = io.BytesIO()
    out.write(b"\0\0\0\0")
    pickler = pickle.Pickler(out, protocol=pickle.HIGHEST_PROTOCOL)
    pickler.dispatch_table = _DISPATCH
    pickler.dump(message)
    data = out.getbuffer()
    _LENGTH.pack_into(data, 0, len(data) - _LENGTH.size)
    del data
    return out.getvalue()


class FrameBuffer:
    """Bytes in, whole messages out (a frame may arrive in pieces or several at once)."""

    def __init__(self) -> None:
        self._data = bytearray()

    def feed(self, data: bytes) -> list[tuple[Any, ...]]:
        """The messages ``data`` completes, in order; ``ValueError`` on a frame too long."""
        buffer = self._data
        buffer += data
        messages: list[tuple[Any, ...]] = []
        start = 0
        while len(buffer) - start >= _LENGTH.size:
            (length,) = _LENGTH.unpack_from(buffer, start)
            if length > FRAME_MAX_BYTES:
                raise ValueError(f"a link frame of {length} bytes")
            end = start + _LENGTH.size + length
            if len(buffer) < end:
                break
            messages.append(pickle.loads(buffer[start + _LENGTH.size:end]))
            start = end
        del buffer[:start]
        return messages


@dataclass(frozen=True, slots=True)
class HubWatch:
    """The fields of an AddDeviceNotification the notification hub reads: what a feed
    (child) subscribes and the host hands the service's hub."""

    port: int
    group: int
    offset: int
    length: int
    transmission_mode: int = TransmissionMode.SERVER_ON_CHANGE
