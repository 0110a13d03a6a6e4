"""Payloads of the ADS sum commands (index groups 0xF080, 0xF081, 0xF082).

A sum command is one ReadWrite whose index offset is the number of sub-requests N and
whose write data lists them, exactly as TwinCAT lays them out (little-endian UNS32)::

    0xF080 sum read        in:  N x (group, offset, length)
                           out: N x result, then each item's data (length bytes,
                                zero-filled where the item failed)
    0xF081 sum write       in:  N x (group, offset, length), then each item's data
                           out: N x result
    0xF082 sum read-write  in:  N x (group, offset, read_length, write_length), then data
                           out: N x (result, returned_length), then the returned data

Decoders raise ``ValueError`` when the payload does not match N; the server answers
that with ADS 0x705.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

_U32 = struct.Struct("<I")
_TRIPLE = struct.Struct("<III")
_QUAD = struct.Struct("<IIII")


@dataclass(frozen=True, slots=True)
class SumItem:
    """One sub-request: where, how many bytes to read, and the bytes to write."""

    group: int
    offset: int
    read_length: int = 0
    data: bytes = b""


def encode_sum_read(items: list[SumItem]) -> tuple[bytes, int]:
    """Write data and read length of a sum read of ``items``."""
    payload = b"".join(_TRIPLE.pack(i.group, i.offset, i.read_length) for i in items)
    return payload, 4 * len(items) + sum(i.read_length for i in items)


def encode_sum_read_addresses(addresses: list[tuple[int, int, int]]) -> tuple[bytes, int]:
    """``encode_sum_read`` of (group, offset, length) triples, without a ``SumItem`` each
    (the batching client's hot path)."""
    pack = _TRIPLE.pack
    payload = b"".join([pack(*address) for address in addresses])
    return payload, 4 * len(addresses) + sum([address[2] for address in addresses])


def decode_sum_read(count: int, data: bytes) -> list[SumItem]:
    """The sub-requests of a sum read."""
    if len(data) != 12 * count:
        raise ValueError(f"sum read of {count} items needs {12 * count} bytes, got {len(data)}")
    return [SumItem(*_TRIPLE.unpack_from(data, 12 * k)) for k in range(count)]


def encode_sum_read_reply(results: list[tuple[int, bytes]]) -> bytes:
    """N result codes, then each item's data (already padded to its requested length)."""
    return b"".join(_U32.pack(code) for code, _ in results) + b"".join(d for _, d in results)


def decode_sum_read_reply(lengths: list[int], data: bytes) -> list[tuple[int, bytes]]:
    """Split a sum-read reply into (result, data) per item of the requested lengths."""
    count = len(lengths)
    if len(data) < 4 * count + sum(lengths):
        raise ValueError("sum read reply is shorter than the items it answers")
    pos = 4 * count
    out = []
    for k, length in enumerate(lengths):
        out.append((_U32.unpack_from(data, 4 * k)[0], data[pos : pos + length]))
        pos += length
    return out


def encode_sum_write(items: list[SumItem]) -> tuple[bytes, int]:
    """Write data and read length of a sum write of ``items``."""
    head = b"".join(_TRIPLE.pack(i.group, i.offset, len(i.data)) for i in items)
    return head + b"".join(i.data for i in items), 4 * len(items)


def decode_sum_write(count: int, data: bytes) -> list[SumItem]:
    """The sub-requests of a sum write, each with its data."""
    head = 12 * count
    if len(data) < head:
        raise ValueError(f"sum write of {count} items needs at least {head} bytes")
    items, pos = [], head
    for k in range(count):
        group, offset, length = _TRIPLE.unpack_from(data, 12 * k)
        items.append(SumItem(group, offset, 0, data[pos : pos + length]))
        pos += length
    if pos != len(data):
        raise ValueError(f"sum write data is {len(data)} bytes, its items say {pos}")
    return items


def encode_codes(codes: list[int]) -> bytes:
    """N result codes (the reply of a sum write)."""
    return b"".join(_U32.pack(c) for c in codes)


def decode_codes(count: int, data: bytes) -> list[int]:
    """N result codes."""
    if len(data) < 4 * count:
        raise ValueError("reply is shorter than its result codes")
    return [_U32.unpack_from(data, 4 * k)[0] for k in range(count)]


def encode_sum_read_write(items: list[SumItem]) -> tuple[bytes, int]:
    """Write data and read length of a sum read-write of ``items``."""
    head = b"".join(_QUAD.pack(i.group, i.offset, i.read_length, len(i.data)) for i in items)
    return head + b"".join(i.data for i in items), 8 * len(items) + sum(
        i.read_length for i in items
    )


def decode_sum_read_write(count: int, data: bytes) -> list[SumItem]:
    """The sub-requests of a sum read-write."""
    head = 16 * count
    if len(data) < head:
        raise ValueError(f"sum read-write of {count} items needs at least {head} bytes")
    items, pos = [], head
    for k in range(count):
        group, offset, read_length, write_length = _QUAD.unpack_from(data, 16 * k)
        items.append(SumItem(group, offset, read_length, data[pos : pos + write_length]))
        pos += write_length
    if pos != len(data):
        raise ValueError(f"sum read-write data is {len(data)} bytes, its items say {pos}")
    return items


def encode_sum_read_write_reply(results: list[tuple[int, bytes]]) -> bytes:
    """N x (result, returned length), then the returned data."""
    head = b"".join(struct.pack("<II", code, len(d)) for code, d in results)
    return head + b"".join(d for _, d in results)


def decode_sum_read_write_reply(count: int, data: bytes) -> list[tuple[int, bytes]]:
    """Split a sum read-write reply into (result, data) per item."""
    if len(data) < 8 * count:
        raise ValueError("sum read-write reply is shorter than its headers")
    out, pos = [], 8 * count
    for k in range(count):
        code, length = struct.unpack_from("<II", data, 8 * k)
        if pos + length > len(data):
            raise ValueError("sum read-write reply is shorter than the lengths it announces")
        out.append((code, data[pos : pos + length]))
        pos += length
    return out
