"""The symbol and data type information services that ADS clients use to browse a device.

Every object of the address space is a symbol under its name, with the TwinCAT type
name, ADS data type id and size of its ISG type and its description as the comment.
What a symbol entry gives as the value's address:

* PLC (HLI) symbols (port 851): their own address, group 0x4020 and the offset in the
  PLC memory area, as a TwinCAT PLC gives its variables.
* Every other object (ports 551, 552, 553): group 0xF005 (value by handle) with the
  object's handle as offset. Handles are global in this service and stable for its
  life, and the dispatcher serves 0xF005 on every port, so a client connected to port
  851 (where ADS clients upload symbols) reads and subscribes to a GEO or COM object
  with the entry's iGroup/iOffs as they stand.

The catalog is fixed for the life of the service, so every answer is encoded once, when
the service is built; a request is a dictionary lookup. Answers are ``(0, bytes)`` or
``(code, message)`` with ADS codes, never exceptions:

====== ========= ==============================================================
group  command   answer
====== ========= ==============================================================
0xF007 ReadWrite name in, AdsSymbolInfoByName out (group, offset, size: 12 bytes)
0xF008 Read      symbol version, one byte
0xF009 ReadWrite name in, AdsSymbolEntry out
0xF00B Read      every AdsSymbolEntry, back to back
0xF00C Read      AdsSymbolUploadInfo, 8 bytes (count and size of 0xF00B)
0xF00E Read      an AdsDatatypeEntry per type the symbols use (base types, structs
                 and arrays, the padding members' ARRAY [0..n-1] OF BYTE and BYTE)
0xF00F Read      upload info, 64 bytes if the read length allows, else 24
0xF011 ReadWrite type name in, AdsDatatypeEntry out (any elementary type, STRING(n))
====== ========= ==============================================================

Bad input: an unknown symbol or type 0x710 (what TwinCAT answers for both), a read
length below the answer's size 0x705, a name that is not CP1252 0x706, an index offset
other than 0 on an upload 0x703 (the high bit, which TwinCAT's .NET client sets, is
ignored), Read of a ReadWrite service or ReadWrite with data of a Read service 0x701,
and any Write 0x704 (the information is read-only).
"""

from __future__ import annotations

import logging
import struct
import sys
import time
import zlib
from collections.abc import Callable

from cnc_objects.objects import AddressSpace
from cnc_objects.objects.address_space import Entry, name_key
from cnc_objects.objects.catalog import PLC_GROUP
from cnc_objects.objects.plc_structs import (
    Member,
    Node,
    PlcStructs,
    padding_type,
    struct_members,
)
from cnc_objects.protocol.ads_symbols import (
    AdsDataType,
    AdsDataTypeFlag,
    AdsSymbolFlag,
    DataTypeEntry,
    SymbolEntry,
    SymbolGroup,
    SymbolUploadFlag,
    TwinCatType,
    UploadInfo,
    encode_datatype_entry,
    encode_symbol_entry,
    encode_symbol_version,
    encode_upload_info,
    parse_twincat_type,
    twincat_type,
)
from cnc_objects.protocol.constants import CncPort
from cnc_objects.protocol.constants import ReservedIndexGroup as RIG
from cnc_objects.protocol.datatypes import STRING_ENCODING
from cnc_objects.protocol.errors import AdsReturnCode

log = logging.getLogger(__name__)

_E = AdsReturnCode
Result = tuple[int, bytes | str]

#: CP1252, the code page of every name, type and comment (64-byte upload info).
CODE_PAGE = 1252
_OFFSET_HIGH_BIT = 0x8000_0000  # set by TwinCAT.Ads in the offset of its upload reads
_INFO_BY_NAME = struct.Struct("<III")


def symbol_address(entry: Entry) -> tuple[int, int]:
    """Where a client reads ``entry``'s value: its own PLC address on port 851, value by
    handle (0xF005, handle) for every other port."""
    obj = entry.obj
    if obj.port == CncPort.PLC:
        return obj.group, obj.offset
    return RIG.SYM_VALUE_BY_HANDLE, entry.handle


def symbol_entry(entry: Entry) -> SymbolEntry:
    """The AdsSymbolEntry of an address-space entry."""
    obj = entry.obj
    tc = twincat_type(obj.dtype)
    group, offset = symbol_address(entry)
    flags = AdsSymbolFlag(0) if obj.access.writable else AdsSymbolFlag.READONLY
    return SymbolEntry(group, offset, tc.size, tc.data_type, flags, obj.name, tc.name, obj.description)


def struct_symbol_entry(node: Node) -> SymbolEntry:
    """The AdsSymbolEntry of a struct or array: its address in the PLC memory area (0x4020,
    its first member's offset), read-only when no member below may be written."""
    flags = AdsSymbolFlag(0) if node.writable else AdsSymbolFlag.READONLY
    return SymbolEntry(PLC_GROUP, node.start, node.size, AdsDataType.BIGTYPE,
                       flags, node.name, node.type_name, "")


def _member(member: Member) -> DataTypeEntry:
    """A sub item of a struct's type: a member at its offset, or padding."""
    node = member.node
    if node is not None and node.entry is not None:
        tc = twincat_type(node.entry.obj.dtype)
        return DataTypeEntry(member.name, tc.size, tc.data_type, AdsDataTypeFlag.DATAITEM,
                             tc.name, node.entry.obj.description, member.offset)
    comment = "padding" if node is None else ""
    return DataTypeEntry(member.name, member.size, AdsDataType.BIGTYPE, AdsDataTypeFlag.DATAITEM,
                         member.type_name, comment, member.offset)


def padding_datatype_entry(size: int) -> DataTypeEntry:
    """The type of a padding member: ``ARRAY [0..size-1] OF BYTE``."""
    name = padding_type(size)
    return DataTypeEntry(name, size, AdsDataType.BIGTYPE, AdsDataTypeFlag.DATATYPE, "BYTE",
                         hash_value=zlib.crc32(name.encode()), array=((0, size),))


def struct_datatype_entry(node: Node) -> DataTypeEntry:
    """The AdsDatatypeEntry of a struct's type (its members as sub items, at their
    offsets) or of an array's (its element type, bounds and count)."""
    hash_value = zlib.crc32(node.type_name.encode())
    if node.is_array:
        (first, element), *_ = node.children()
        lower, count = min(node.elements), len(node.elements)
        element_type = (twincat_type(element.entry.obj.dtype).name if element.entry is not None
                        else element.type_name)
        return DataTypeEntry(node.type_name, node.size, AdsDataType.BIGTYPE,
                             AdsDataTypeFlag.DATATYPE, element_type, hash_value=hash_value,
                             array=((lower, count),))
    members = tuple(_member(member) for member in struct_members(node))
    return DataTypeEntry(node.type_name, node.size, AdsDataType.BIGTYPE, AdsDataTypeFlag.DATATYPE,
                         hash_value=hash_value, sub_items=members)


def datatype_entry(tc: TwinCatType) -> DataTypeEntry:
    """The AdsDatatypeEntry of a base type: TwinCAT name, size, ADST id; the hash is the
    CRC-32 of the name, so that clients comparing types by hash tell them apart."""
    return DataTypeEntry(tc.name, tc.size, tc.data_type, hash_value=zlib.crc32(tc.name.encode()))


def _type_key(name: str) -> str:
    """A type name as it is looked up: any case, without blanks (``ARRAY[0..1] OF X`` is
    ``ARRAY [0..1] OF X``)."""
    return "".join(name.split()).upper()


def _name(data: bytes) -> str | None:
    """The name a client wrote (up to the first NUL, CP1252), or None if not CP1252."""
    try:
        return data.split(b"\x00", 1)[0].decode(STRING_ENCODING)
    except UnicodeDecodeError:
        return None


def _fits(answer: bytes, length: int, what: str) -> Result:
    if length < len(answer):
        return _E.DEVICE_INVALIDSIZE, f"{what} is {len(answer)} bytes; read length is {length}"
    return 0, answer


class SymbolService:
    """Symbol version, symbol and data type uploads and lookups over an address space."""

    def __init__(
        self, space: AddressSpace, structs: PlcStructs | None = None, version: int | None = None,
    ) -> None:
        """``structs``: the HLI's struct and array symbols, listed after the objects;
        ``version``: the symbol version (default: from the table's bytes, so that it
        changes when the table does)."""
        started_ns = time.perf_counter_ns()
        nodes = structs.symbols if structs is not None else []
        entries = [e for obj in space.objects() if (e := space.by_name(obj.name)) is not None]
        symbols = [symbol_entry(e) for e in entries] + [struct_symbol_entry(n) for n in nodes]
        encoded = [encode_symbol_entry(s) for s in symbols]
        self._by_name = {name_key(s.name): blob for s, blob in zip(symbols, encoded)}
        self._info_by_name = {
            name_key(s.name): _INFO_BY_NAME.pack(s.group, s.offset, s.size) for s in symbols
        }
        self._upload = b"".join(encoded)
        if version is None:  # 1..255, from the table: another table, another version
            version = zlib.crc32(self._upload) % 255 + 1
        self.version = version
        self._version = encode_symbol_version(version)
        types = {twincat_type(e.obj.dtype) for e in entries}
        type_blobs = {
            tc.name: encode_datatype_entry(datatype_entry(tc))
            for tc in sorted(types, key=lambda tc: (tc.data_type, tc.size))
        }
        for node in nodes:  # struct and array types, each once (instances share them)
            if node.type_name not in type_blobs:
                type_blobs[node.type_name] = encode_datatype_entry(struct_datatype_entry(node))
        paddings = {m.size for node in nodes if not node.is_array for m in struct_members(node)
                    if m.node is None}
        if paddings:  # the padding members' types, and their element type
            byte = parse_twincat_type("BYTE")
            type_blobs.setdefault(byte.name, encode_datatype_entry(datatype_entry(byte)))
        for size in sorted(paddings):
            type_blobs[padding_type(size)] = encode_datatype_entry(padding_datatype_entry(size))
        self._types_by_name = {_type_key(name): blob for name, blob in type_blobs.items()}
        self._datatype_upload = b"".join(type_blobs.values())
        info = UploadInfo(
            symbol_count=len(symbols),
            symbol_size=len(self._upload),
            datatype_count=len(type_blobs),
            datatype_size=len(self._datatype_upload),
            encoding_code_page=CODE_PAGE,
            flags=SymbolUploadFlag.INCLUDES_BASE_TYPES
            | (SymbolUploadFlag.IS_64BIT_PLATFORM if sys.maxsize > 2**32 else 0),
        )
        self.info = info
        self._infos = {size: encode_upload_info(info, size) for size in (8, 24, 64)}
        self.build_ns = time.perf_counter_ns() - started_ns
        # Read services: what they answer and what to call it in a refusal
        self._reads: dict[int, tuple[bytes, str]] = {
            SymbolGroup.VERSION: (self._version, "the symbol version"),
            SymbolGroup.UPLOAD: (self._upload, "the symbol upload"),
            SymbolGroup.UPLOAD_INFO: (self._infos[8], "the upload info"),
            SymbolGroup.DT_UPLOAD: (self._datatype_upload, "the data type upload"),
            SymbolGroup.UPLOAD_INFO2: (self._infos[24], "the upload info"),  # or 64 bytes
        }
        self._read_writes: dict[int, Callable[[str, int], Result]] = {
            SymbolGroup.INFO_BY_NAME: self._info_by_name_answer,
            SymbolGroup.INFO_BY_NAME_EX: self._symbol_by_name,
            SymbolGroup.DT_INFO_BY_NAME_EX: self._type_by_name,
        }
        log.debug(
            "symbol service: %d symbols (%d bytes), %d types (%d bytes), built in %.1f ms",
            info.symbol_count, info.symbol_size, info.datatype_count, info.datatype_size,
            self.build_ns / 1e6,
        )

    # ------------------------------------------------------------------ entry points

    def handles(self, group: int) -> bool:
        """True for the index groups this service answers."""
        return group in self._reads or group in self._read_writes

    def read(self, group: int, offset: int, length: int) -> Result:
        """ADS Read of ``group``: (0, data) or (code, message)."""
        answer = self._reads.get(group)
        if answer is None:
            if group in self._read_writes:
                return _E.DEVICE_SRVNOTSUPP, f"index group 0x{group:x} takes ReadWrite with a name"
            return _E.DEVICE_INVALIDGRP, f"index group 0x{group:x} is not a symbol service"
        if offset & ~_OFFSET_HIGH_BIT:
            return _E.DEVICE_INVALIDOFFSET, f"index group 0x{group:x} is read at offset 0"
        if group == SymbolGroup.UPLOAD_INFO2 and length >= len(self._infos[64]):
            return 0, self._infos[64]  # the TwinCAT 3 form, to whoever has room for it
        blob, what = answer
        return _fits(blob, length, what)

    def read_write(self, group: int, offset: int, data: bytes, read_length: int) -> Result:
        """ADS ReadWrite of ``group`` with write ``data``: (0, data) or (code, message)."""
        answer = self._read_writes.get(group)
        if answer is None:
            if group in self._reads and not data:  # a ReadWrite that writes nothing reads
                return self.read(group, offset, read_length)
            if group in self._reads:
                return _E.DEVICE_SRVNOTSUPP, f"index group 0x{group:x} takes Read, not data"
            return _E.DEVICE_INVALIDGRP, f"index group 0x{group:x} is not a symbol service"
        name = _name(data)
        if name is None:
            return _E.DEVICE_INVALIDDATA, "a symbol or type name must be CP1252 text"
        return answer(name, read_length)

    def write(self, group: int, offset: int, data: bytes) -> Result:
        """ADS Write of ``group``: always refused, the information is read-only."""
        return _E.DEVICE_INVALIDACCESS, f"index group 0x{group:x} is read-only"

    # ------------------------------------------------------------------ services

    def _symbol_by_name(self, name: str, length: int) -> Result:
        blob = self._by_name.get(name_key(name))
        if blob is None:
            return _E.DEVICE_SYMBOLNOTFOUND, f"no symbol is named {name!r}"
        return _fits(blob, length, f"the symbol entry of {name}")

    def _info_by_name_answer(self, name: str, length: int) -> Result:
        blob = self._info_by_name.get(name_key(name))
        if blob is None:
            return _E.DEVICE_SYMBOLNOTFOUND, f"no symbol is named {name!r}"
        return _fits(blob, length, f"the symbol info of {name}")

    def _type_by_name(self, name: str, length: int) -> Result:
        blob = self._types_by_name.get(_type_key(name))
        if blob is None:  # an elementary type no symbol uses, or another STRING(n)
            try:
                blob = encode_datatype_entry(datatype_entry(parse_twincat_type(name)))
            except ValueError:
                return _E.DEVICE_SYMBOLNOTFOUND, f"no data type is named {name!r}"
        return _fits(blob, length, f"the data type entry of {name}")

    # ------------------------------------------------------------------ measures

    @property
    def upload_bytes(self) -> int:
        """Size of the symbol upload (0xF00B) in bytes."""
        return len(self._upload)

    @property
    def datatype_upload_bytes(self) -> int:
        """Size of the data type upload (0xF00E) in bytes."""
        return len(self._datatype_upload)

