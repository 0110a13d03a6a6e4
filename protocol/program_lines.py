"""A window of a stored program's lines (ADS ReadWrite at ``ProgramStoreOffset.READ_LINES``).

A view of a program of hundreds of MB shows a few hundred lines around the current block;
it asks for those lines only, never for the file::

    request (write data)   first_line u64 LE (from 1) | line_count u32 LE | name CP1252 | NUL
    reply (read data)      total_lines u64 LE | lines u32 LE | the lines' bytes

The reply's bytes are whole lines of the file as stored (each with its ``\\n``, the last
line of the file perhaps without), at most ``line_count`` of them and no more than the
request's read length holds (the header included); a first line beyond the end gives no
lines and still the total. A single line longer than the room left is cut to it (the
window shows its start). The service encodes replies and decodes requests, clients the
other way round; both use this module.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass

from .datatypes import STRING_ENCODING

_REQUEST = struct.Struct("<QI")
_REPLY = struct.Struct("<QI")
#: Bytes of a reply's header (total lines, lines returned).
REPLY_HEADER_BYTES = _REPLY.size
#: Most lines one request may ask for (a screen holds ~100).
LINES_MAX = 10_000


@dataclass(frozen=True, slots=True)
class LinesRequest:
    """Lines ``first_line`` .. ``first_line + line_count - 1`` of program ``name``."""

    name: str
    first_line: int
    line_count: int


@dataclass(frozen=True, slots=True)
class LinesReply:
    """The lines found (bytes as stored, ``\\n`` kept) and how many lines the program has."""

    total_lines: int
    line_count: int
    data: bytes


def encode_lines_request(request: LinesRequest) -> bytes:
    """The write data of a READ_LINES request."""
    return (_REQUEST.pack(request.first_line, request.line_count)
            + request.name.encode(STRING_ENCODING) + b"\x00")


def decode_lines_request(data: bytes) -> LinesRequest:
    """A READ_LINES request; ValueError with a sentence for one that is malformed."""
    if len(data) < _REQUEST.size + 1:
        raise ValueError("a lines request is first_line (u64), line_count (u32), name, NUL")
    first_line, line_count = _REQUEST.unpack_from(data)
    if first_line < 1:
        raise ValueError("lines are numbered from 1; first_line 0 asks for none")
    if not 0 < line_count <= LINES_MAX:
        raise ValueError(f"a lines request asks for 1..{LINES_MAX} lines, not {line_count}")
    try:
        name = data[_REQUEST.size:].split(b"\x00", 1)[0].decode(STRING_ENCODING)
    except UnicodeDecodeError:
        raise ValueError("a program name must be CP1252 text") from None
    return LinesRequest(name, first_line, line_count)


def encode_lines_reply(reply: LinesReply) -> bytes:
    """The read data of a READ_LINES reply."""
    return _REPLY.pack(reply.total_lines, reply.line_count) + reply.data


def decode_lines_reply(data: bytes) -> LinesReply:
    """A READ_LINES reply; ValueError for one shorter than its header."""
    if len(data) < _REPLY.size:
        raise ValueError(f"a lines reply has a {_REPLY.size}-byte header; {len(data)} came")
    total_lines, line_count = _REPLY.unpack_from(data)
    return LinesReply(total_lines, line_count, data[_REPLY.size:])
