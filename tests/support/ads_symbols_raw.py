"""ADS symbol entries parsed by hand from the raw bytes of an upload (no ADS library)."""

from __future__ import annotations

import struct
from dataclasses import dataclass

BIGTYPE = 65  # ADST_BIGTYPE: structs and arrays


@dataclass(frozen=True)
class Symbol:
    entry_length: int
    group: int
    offset: int
    size: int
    data_type: int
    flags: int
    name: str
    type_name: str
    comment: str


def cstrings(data: bytes, at: int, *lengths: int) -> list[str]:
    """Strings of ``lengths`` at ``at``, each followed by its NUL."""
    out = []
    for length in lengths:
        assert data[at + length] == 0, "a string must end in NUL"
        out.append(data[at:at + length].decode("cp1252"))
        at += length + 1
    return out


def parse_symbol(data: bytes, at: int) -> Symbol:
    """AdsSymbolEntry: 6 x u32, 3 x u16, then name, type and comment with NULs."""
    length, group, offset, size, data_type, flags = struct.unpack_from("<6I", data, at)
    name_length, type_length, comment_length = struct.unpack_from("<3H", data, at + 24)
    assert 30 + name_length + type_length + comment_length + 3 <= length
    strings = cstrings(data, at + 30, name_length, type_length, comment_length)
    return Symbol(length, group, offset, size, data_type, flags, *strings)


def parse_symbols(data: bytes) -> list[Symbol]:
    out, at = [], 0
    while at < len(data):
        symbol = parse_symbol(data, at)
        out.append(symbol)
        at += symbol.entry_length
    assert at == len(data), "entries must fill the upload exactly"
    return out
