"""ADS symbol and data-type information: TwinCAT type names, ADST ids, and the entries
of the symbol upload services, encoded and decoded as TwinCAT lays them out.

Layouts (Beckhoff TcAdsDef.h / AdsDef.h; all little-endian, strings CP1252 with NUL)::

    AdsSymbolEntry (0xF009 out, 0xF00B entries back to back)
      0  u32 entryLength    whole entry, padding included: the next entry starts here
      4  u32 iGroup         where the value is read: index group ...
      8  u32 iOffs          ... and index offset
     12  u32 size           value size in bytes
     16  u32 dataType       ADST_* id (AdsDataType)
     20  u32 flags          ADSSYMBOLFLAG_* (AdsSymbolFlag)
     24  u16 nameLength     name length without the NUL
     26  u16 typeLength     type name length without the NUL
     28  u16 commentLength  comment length without the NUL
     30  name NUL, type NUL, comment NUL, then NUL padding up to entryLength

    AdsDatatypeEntry (0xF011 out, 0xF00E entries back to back)
      0  u32 entryLength, 4 u32 version (1), 8 u32 hashValue, 12 u32 typeHashValue,
     16  u32 size, 20 u32 offs (in the parent type), 24 u32 dataType (ADST_*),
     28  u32 flags (ADSDATATYPEFLAG_*), 32 u16 nameLength, 34 u16 typeLength,
     36  u16 commentLength, 38 u16 arrayDim, 40 u16 subItems,
     42  name NUL, type NUL, comment NUL, arrayDim x (u32 lBound, u32 elements),
         subItems x AdsDatatypeEntry, then NUL padding up to entryLength

    Upload info (0xF00C: 8 bytes; 0xF00F: 24 or 64 bytes, the form chosen by length)
      u32 nSymbols, u32 nSymSize                            | AdsSymbolUploadInfo (8)
      u32 nDatatypes, u32 nDatatypeSize,                    |
      u32 nMaxDynSymbols, u32 nUsedDynSymbols               | AdsSymbolUploadInfo2 (24)
      u32 nInvalidDynSymbols, u32 encodingCodePage,         |
      u32 flags (SymbolUploadFlag), 7 x u32 reserved        | the TwinCAT 3 form (64)

Padding: the header declares none; TwinCAT 3 pads its entries (pyads documents a TwinCAT
entry of 84 bytes of content with entryLength 88), and every client walks the upload by
entryLength, so entries are NUL-padded to a multiple of ``ENTRY_ALIGNMENT`` (8).

Strings: TwinCAT STRING(n) holds n characters plus the NUL, n + 1 bytes. An ISG
STRING(n) is n bytes including the NUL, so it is TwinCAT STRING(n-1), size n.
"""

from __future__ import annotations

import re
import struct
from dataclasses import dataclass, field
from enum import IntEnum, IntFlag

from .datatypes import SCALAR_TYPES, STRING, STRING_ENCODING, DataType

ENTRY_ALIGNMENT = 8
#: TwinCAT's plain ``STRING`` is STRING(80).
DEFAULT_STRING_CHARS = 80
#: Longest TwinCAT string the mapping names: ISG STRING(65536) holds 65535 characters.
MAX_STRING_CHARS = 65535

_SYMBOL_HEADER = struct.Struct("<6I3H")  # 30 bytes
_DATATYPE_HEADER = struct.Struct("<8I5H")  # 42 bytes
_ARRAY_INFO = struct.Struct("<II")
_U32 = struct.Struct("<I")


class SymbolGroup(IntEnum):
    """Reserved index groups of the symbol information services (ADSIGRP_SYM_*)."""

    INFO_BY_NAME = 0xF007  # ReadWrite: name in, AdsSymbolInfoByName (group, offset, size) out
    VERSION = 0xF008  # Read: the symbol version, one byte
    INFO_BY_NAME_EX = 0xF009  # ReadWrite: name in, AdsSymbolEntry out
    UPLOAD = 0xF00B  # Read: every AdsSymbolEntry, back to back
    UPLOAD_INFO = 0xF00C  # Read: AdsSymbolUploadInfo (8 bytes)
    DT_UPLOAD = 0xF00E  # Read: every AdsDatatypeEntry, back to back
    UPLOAD_INFO2 = 0xF00F  # Read: AdsSymbolUploadInfo2 (24 bytes) or its 64-byte form
    DT_INFO_BY_NAME_EX = 0xF011  # ReadWrite: type name in, AdsDatatypeEntry out


class AdsDataType(IntEnum):
    """ADS data type ids (ADST_*), the ``dataType`` of symbol and data type entries."""

    VOID = 0  # ADST_VOID: no value
    INT16 = 2  # ADST_INT16: INT
    INT32 = 3  # ADST_INT32: DINT
    REAL32 = 4  # ADST_REAL32: REAL
    REAL64 = 5  # ADST_REAL64: LREAL
    INT8 = 16  # ADST_INT8: SINT
    UINT8 = 17  # ADST_UINT8: USINT, BYTE
    UINT16 = 18  # ADST_UINT16: UINT, WORD
    UINT32 = 19  # ADST_UINT32: UDINT, DWORD
    INT64 = 20  # ADST_INT64: LINT
    UINT64 = 21  # ADST_UINT64: ULINT, LWORD
    STRING = 30  # ADST_STRING: STRING(n), n characters + NUL
    WSTRING = 31  # ADST_WSTRING: WSTRING(n), UTF-16
    REAL80 = 32  # ADST_REAL80: 80-bit real
    BIT = 33  # ADST_BIT: BOOL (one byte in a symbol)
    BIGTYPE = 65  # ADST_BIGTYPE: structures, arrays, function blocks


class AdsSymbolFlag(IntFlag):
    """Symbol entry flags (ADSSYMBOLFLAG_*)."""

    PERSISTENT = 0x1  # value kept across restarts
    BITVALUE = 0x2  # size counts bits, not bytes
    REFERENCETO = 0x4  # the symbol is a REFERENCE TO
    TYPEGUID = 0x8  # a 16-byte type GUID follows the comment
    TCCOMIFACEPTR = 0x10  # TcCOM interface pointer
    READONLY = 0x20  # writes are refused
    ITFMETHODACCESS = 0x40  # interface method access
    METHODDEREF = 0x80  # method dereference
    CONTEXTMASK = 0xF00  # task context (4 bits)
    ATTRIBUTES = 0x1000  # attribute entries follow
    STATIC = 0x2000  # static variable
    INITONRESET = 0x4000  # initialised on reset
    EXTENDEDFLAGS = 0x8000  # a u32 of extended flags follows


class AdsDataTypeFlag(IntFlag):
    """Data type entry flags (ADSDATATYPEFLAG_*)."""

    DATATYPE = 0x1  # the entry is a type
    DATAITEM = 0x2  # the entry is a member of a type
    REFERENCETO = 0x4  # REFERENCE TO
    METHODDEREF = 0x8  # method dereference
    OVERSAMPLE = 0x10  # oversampling type
    BITVALUES = 0x20  # size counts bits
    PROPITEM = 0x40  # property item
    TYPEGUID = 0x80  # a type GUID follows the sub items
    PERSISTENT = 0x100  # persistent
    COPYMASK = 0x200  # a copy mask of ``size`` bytes follows
    TCCOMINTERFACEPTR = 0x400  # TcCOM interface pointer
    METHODINFOS = 0x800  # method infos follow
    ATTRIBUTES = 0x1000  # attributes follow
    ENUMINFOS = 0x2000  # enumeration values follow


class SymbolUploadFlag(IntFlag):
    """Flags of the 64-byte upload info (TwinCAT 3)."""

    NONE = 0x0  # no flag
    IS_64BIT_PLATFORM = 0x1  # pointers on the target are 8 bytes
    INCLUDES_BASE_TYPES = 0x2  # the data type upload lists the base types too


@dataclass(frozen=True, slots=True)
class TwinCatType:
    """A type as TwinCAT names it: ``name`` (``UDINT``, ``STRING(83)``), the ADST id and
    the size in bytes."""

    name: str
    data_type: AdsDataType
    size: int


# ISG name -> (TwinCAT name, ADST id); sizes are the ISG sizes, equal to TwinCAT's.
_SCALARS: dict[str, tuple[str, AdsDataType]] = {
    "BOOLEAN": ("BOOL", AdsDataType.BIT),
    "UNS08": ("USINT", AdsDataType.UINT8),
    "SGN08": ("SINT", AdsDataType.INT8),
    "UNS16": ("UINT", AdsDataType.UINT16),
    "SGN16": ("INT", AdsDataType.INT16),
    "UNS32": ("UDINT", AdsDataType.UINT32),
    "SGN32": ("DINT", AdsDataType.INT32),
    "UNS64": ("ULINT", AdsDataType.UINT64),
    "SGN64": ("LINT", AdsDataType.INT64),
    "REAL32": ("REAL", AdsDataType.REAL32),
    "REAL64": ("LREAL", AdsDataType.REAL64),
}
# TwinCAT elementary type names -> TwinCatType; BYTE/WORD/DWORD/LWORD are the bit
# strings of the unsigned sizes, answered by data type info but used by no symbol.
_ELEMENTARY: dict[str, TwinCatType] = {
    **{tc: TwinCatType(tc, ads, SCALAR_TYPES[isg].size) for isg, (tc, ads) in _SCALARS.items()},
    "BYTE": TwinCatType("BYTE", AdsDataType.UINT8, 1),
    "WORD": TwinCatType("WORD", AdsDataType.UINT16, 2),
    "DWORD": TwinCatType("DWORD", AdsDataType.UINT32, 4),
    "LWORD": TwinCatType("LWORD", AdsDataType.UINT64, 8),
}
_ISG_BY_ADS = {ads: SCALAR_TYPES[isg] for isg, (_, ads) in _SCALARS.items()}
_TC_STRING = re.compile(r"^STRING\s*(?:\(\s*(\d+)\s*\))?$", re.IGNORECASE)


def twincat_type(dtype: DataType) -> TwinCatType:
    """The TwinCAT name, ADST id and size of an ISG type (STRING(n) -> STRING(n-1))."""
    if dtype.kind == "str":
        return TwinCatType(f"STRING({dtype.size - 1})", AdsDataType.STRING, dtype.size)
    name, ads_type = _SCALARS[dtype.name]
    return TwinCatType(name, ads_type, dtype.size)


def parse_twincat_type(name: str) -> TwinCatType:
    """A TwinCAT elementary type by name (any case, ``STRING`` alone is STRING(80)), in
    TwinCAT's spelling; ``ValueError`` for a name that is not one this mapping knows."""
    text = name.strip()
    found = _ELEMENTARY.get(text.upper())
    if found is not None:
        return found
    match = _TC_STRING.match(text)
    if match:
        chars = int(match.group(1)) if match.group(1) else DEFAULT_STRING_CHARS
        if 1 <= chars <= MAX_STRING_CHARS:
            return TwinCatType(f"STRING({chars})", AdsDataType.STRING, chars + 1)
    raise ValueError(f"{name!r} is not a TwinCAT type this service knows")


def isg_type(twincat_name: str) -> DataType:
    """The ISG type that holds a TwinCAT elementary type (``UDINT`` -> UNS32,
    ``STRING(83)`` -> STRING(84), ``WORD`` -> UNS16); ``ValueError`` otherwise."""
    tc = parse_twincat_type(twincat_name)
    if tc.data_type == AdsDataType.STRING:
        return STRING(tc.size)
    return _ISG_BY_ADS[tc.data_type]


def _text(value: str, what: str) -> bytes:
    """CP1252 bytes of a name, type or comment; characters CP1252 lacks become '?'."""
    raw = value.encode(STRING_ENCODING, errors="replace")
    if b"\x00" in raw or len(raw) > 0xFFFF:
        raise ValueError(f"{what} {value[:40]!r} has a NUL or is over 65535 bytes")
    return raw


def _padded(body: bytes) -> bytes:
    """``body`` (its first 4 bytes a placeholder) with the entry length and padding."""
    length = -(-len(body) // ENTRY_ALIGNMENT) * ENTRY_ALIGNMENT
    return _U32.pack(length) + body[4:] + bytes(length - len(body))


def _strings(data: bytes, start: int, end: int, lengths: tuple[int, ...]) -> tuple[list[str], int]:
    """Decode NUL-terminated strings of ``lengths`` from ``data[start:end]``."""
    out = []
    for length in lengths:
        stop = start + length
        if stop >= end or data[stop] != 0:
            raise ValueError("a string of the entry is longer than the entry or lacks its NUL")
        out.append(data[start:stop].decode(STRING_ENCODING))
        start = stop + 1
    return out, start


@dataclass(frozen=True, slots=True)
class SymbolEntry:
    """One AdsSymbolEntry: where the value lives, its size, type and flags."""

    group: int
    offset: int
    size: int
    data_type: int
    flags: int
    name: str
    type_name: str
    comment: str = ""


def encode_symbol_entry(entry: SymbolEntry) -> bytes:
    """The AdsSymbolEntry bytes, padded; ``ValueError`` for a string over 65535 bytes."""
    name = _text(entry.name, "name")
    type_name = _text(entry.type_name, "type")
    comment = _text(entry.comment, "comment")
    header = _SYMBOL_HEADER.pack(
        0, entry.group, entry.offset, entry.size, entry.data_type, entry.flags,
        len(name), len(type_name), len(comment),
    )
    return _padded(b"".join((header, name, b"\x00", type_name, b"\x00", comment, b"\x00")))


def decode_symbol_entry(data: bytes, start: int = 0) -> tuple[SymbolEntry, int]:
    """The entry at ``data[start:]`` and its entry length; ``ValueError`` if malformed."""
    if len(data) - start < _SYMBOL_HEADER.size:
        raise ValueError(f"a symbol entry needs {_SYMBOL_HEADER.size} header bytes")
    length, group, offset, size, data_type, flags, *lengths = _SYMBOL_HEADER.unpack_from(data, start)
    end = start + length
    if length < _SYMBOL_HEADER.size or end > len(data):
        raise ValueError(f"symbol entry length {length} does not fit the data")
    (name, type_name, comment), _ = _strings(data, start + _SYMBOL_HEADER.size, end, tuple(lengths))
    return SymbolEntry(group, offset, size, data_type, flags, name, type_name, comment), length


def decode_symbol_entries(data: bytes) -> list[SymbolEntry]:
    """Every entry of a symbol upload (0xF00B)."""
    entries, at = [], 0
    while at < len(data):
        entry, length = decode_symbol_entry(data, at)
        entries.append(entry)
        at += length
    return entries


@dataclass(frozen=True, slots=True)
class DataTypeEntry:
    """One AdsDatatypeEntry. ``array`` holds (lower bound, element count) per dimension;
    ``sub_items`` the members of a structure (each with its ``offset`` in the parent)."""

    name: str
    size: int
    data_type: int
    flags: int = AdsDataTypeFlag.DATATYPE
    type_name: str = ""
    comment: str = ""
    offset: int = 0
    version: int = 1
    hash_value: int = 0
    type_hash_value: int = 0
    array: tuple[tuple[int, int], ...] = ()
    sub_items: tuple[DataTypeEntry, ...] = field(default=())


def encode_datatype_entry(entry: DataTypeEntry) -> bytes:
    """The AdsDatatypeEntry bytes, sub items included, padded."""
    name = _text(entry.name, "name")
    type_name = _text(entry.type_name, "type")
    comment = _text(entry.comment, "comment")
    if len(entry.array) > 0xFFFF or len(entry.sub_items) > 0xFFFF:
        raise ValueError("a data type has at most 65535 dimensions and sub items")
    header = _DATATYPE_HEADER.pack(
        0, entry.version, entry.hash_value, entry.type_hash_value, entry.size, entry.offset,
        entry.data_type, entry.flags, len(name), len(type_name), len(comment),
        len(entry.array), len(entry.sub_items),
    )
    parts = [header, name, b"\x00", type_name, b"\x00", comment, b"\x00"]
    parts += [_ARRAY_INFO.pack(lower, count) for lower, count in entry.array]
    parts += [encode_datatype_entry(item) for item in entry.sub_items]
    return _padded(b"".join(parts))


def decode_datatype_entry(data: bytes, start: int = 0) -> tuple[DataTypeEntry, int]:
    """The entry at ``data[start:]`` and its entry length; ``ValueError`` if malformed."""
    return _decode_datatype(data, start, len(data))


def _decode_datatype(data: bytes, start: int, limit: int) -> tuple[DataTypeEntry, int]:
    """The entry at ``data[start:]`` that must end by ``limit`` (its parent's end)."""
    if limit - start < _DATATYPE_HEADER.size:
        raise ValueError(f"a data type entry needs {_DATATYPE_HEADER.size} header bytes")
    (length, version, hash_value, type_hash, size, offset, data_type, flags,
     name_length, type_length, comment_length, dims, items) = _DATATYPE_HEADER.unpack_from(data, start)
    end = start + length
    if length < _DATATYPE_HEADER.size or end > limit:
        raise ValueError(f"data type entry length {length} does not fit the data")
    (name, type_name, comment), at = _strings(
        data, start + _DATATYPE_HEADER.size, end, (name_length, type_length, comment_length)
    )
    if at + dims * _ARRAY_INFO.size > end:
        raise ValueError(f"{dims} array dimensions do not fit the entry")
    array = tuple(_ARRAY_INFO.unpack_from(data, at + k * _ARRAY_INFO.size) for k in range(dims))
    at += dims * _ARRAY_INFO.size
    sub_items = []
    for _ in range(items):
        item, item_length = _decode_datatype(data, at, end)
        sub_items.append(item)
        at += item_length
    entry = DataTypeEntry(
        name, size, data_type, flags, type_name, comment, offset, version, hash_value,
        type_hash, array, tuple(sub_items),
    )
    return entry, length


def decode_datatype_entries(data: bytes) -> list[DataTypeEntry]:
    """Every entry of a data type upload (0xF00E)."""
    entries, at = [], 0
    while at < len(data):
        entry, length = decode_datatype_entry(data, at)
        entries.append(entry)
        at += length
    return entries


#: The sizes of the three upload info forms: AdsSymbolUploadInfo, ...Info2, TwinCAT 3.
UPLOAD_INFO_SIZES = (8, 24, 64)


@dataclass(frozen=True, slots=True)
class UploadInfo:
    """What a client needs before an upload: counts and byte sizes of the symbol and
    data type uploads; dynamic symbols (created at run time) and the string code page
    and flags of the 64-byte form."""

    symbol_count: int
    symbol_size: int
    datatype_count: int = 0
    datatype_size: int = 0
    max_dynamic_symbols: int = 0
    used_dynamic_symbols: int = 0
    invalid_dynamic_symbols: int = 0
    encoding_code_page: int = 0
    flags: int = SymbolUploadFlag.NONE


def encode_upload_info(info: UploadInfo, size: int) -> bytes:
    """The ``size``-byte form (8, 24 or 64) of ``info``."""
    fields = (
        info.symbol_count, info.symbol_size, info.datatype_count, info.datatype_size,
        info.max_dynamic_symbols, info.used_dynamic_symbols, info.invalid_dynamic_symbols,
        info.encoding_code_page, info.flags,
    )
    if size not in UPLOAD_INFO_SIZES:
        raise ValueError(f"upload info is 8, 24 or 64 bytes, not {size}")
    words = (fields + (0,) * 7)[: size // 4]
    return struct.pack(f"<{len(words)}I", *words)


def decode_upload_info(data: bytes) -> UploadInfo:
    """An upload info of any of the three forms (chosen by its length)."""
    if len(data) not in UPLOAD_INFO_SIZES:
        raise ValueError(f"upload info is 8, 24 or 64 bytes, not {len(data)}")
    words = struct.unpack(f"<{len(data) // 4}I", data)
    return UploadInfo(*words[:9])


_HANDLE_INFO = struct.Struct("<IIIH")


def encode_handle_info(handle: int, size: int, type_name: str, decoration: int = 0) -> bytes:
    """TwinCAT 3's extended answer to handle by name (0xF003) for a read length over 4::

        u32 handle, u32 size, u32 type decoration, u16 type name length, type name NUL

    (the layout jisotalo's ads-client reads; the decoration's meaning is undocumented
    and no client uses it)."""
    name = _text(type_name, "type")
    return _HANDLE_INFO.pack(handle, size, decoration, len(name)) + name + b"\x00"


def decode_handle_info(data: bytes) -> tuple[int, int, int, str]:
    """(handle, size, decoration, type name) of an extended handle answer."""
    if len(data) < _HANDLE_INFO.size + 1:
        raise ValueError(f"an extended handle answer has at least {_HANDLE_INFO.size + 1} bytes")
    handle, size, decoration, length = _HANDLE_INFO.unpack_from(data)
    (type_name,), _ = _strings(data, _HANDLE_INFO.size, len(data), (length,))
    return handle, size, decoration, type_name


def encode_symbol_version(version: int) -> bytes:
    """The symbol version (0xF008): one byte."""
    return bytes((version,))
