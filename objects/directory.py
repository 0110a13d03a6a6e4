"""The COM object directory (index group ``0x13010<ch>``), as ISG serves it.

Offset 0 holds the number of objects (UNS32); offset n (1..N) the 84-byte descriptor of
object n. A read whose length is an exact multiple of 84 returns that many consecutive
descriptors from n. Descriptor layout (little-endian)::

     0  UNS32      id (n)
     4  UNS32      size in bytes
     8  UNS16      write access (1 = writable)
    10  UNS16      padding
    12  UNS32      index group (logical)
    16  UNS32      index offset
    20  STRING(32) name ("mc_command_execution_mode_w")
    52  STRING(32) type, IEC spelling ("DINT", "LREAL", "STRING")

Directory 0 lists the platform objects; directory c lists the COM objects of channel c,
and directory 1 also the platform objects ("platform data can be addressed under channel
0 or 1").
"""

from __future__ import annotations

import struct

from cnc_objects.protocol.datatypes import STRING
from cnc_objects.protocol.errors import AdsReturnCode

from .model import CncObject

DESCRIPTOR_SIZE = 84
_HEAD = struct.Struct("<IIHHII")
_NAME = STRING(32)


def encode_descriptor(ordinal: int, obj: CncObject) -> bytes:
    """The 84-byte descriptor of ``obj`` at position ``ordinal`` (from 1)."""
    head = _HEAD.pack(
        ordinal, obj.length, 1 if obj.access.writable else 0, 0, obj.group, obj.offset
    )
    return head + _NAME.encode(obj.element[:31]) + _NAME.encode(obj.dtype.iec)


class ObjectDirectory:
    """The descriptors of one directory group, readable as ADS reads."""

    def __init__(self, objects: list[CncObject]) -> None:
        self._descriptors = [encode_descriptor(k, o) for k, o in enumerate(objects, start=1)]

    def __len__(self) -> int:
        return len(self._descriptors)

    def read(self, offset: int, length: int) -> tuple[int, bytes | str]:
        """ADS read at ``offset``: (0, data) or (code, message)."""
        count = len(self._descriptors)
        if offset == 0:
            if length != 4:
                return AdsReturnCode.DEVICE_INVALIDSIZE, "object count is UNS32: read 4 bytes"
            return 0, struct.pack("<I", count)
        if not 1 <= offset <= count:
            return AdsReturnCode.DEVICE_INVALIDOFFSET, f"directory has objects 1..{count}"
        wanted, rest = divmod(length, DESCRIPTOR_SIZE)
        if rest or wanted == 0 or offset - 1 + wanted > count:
            return (
                AdsReturnCode.DEVICE_INVALIDSIZE,
                f"read a multiple of {DESCRIPTOR_SIZE} bytes, at most up to object {count}",
            )
        return 0, b"".join(self._descriptors[offset - 1 : offset - 1 + wanted])
