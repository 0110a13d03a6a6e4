"""The symbol information services (service/ads/symbols.py) over the default machine.

The address space is the one the service builds (service/binding.py over the default
configuration's kernel, not started); every answer is parsed with the protocol decoders
and checked field by field against the catalog: names, TwinCAT types, sizes, flags,
comments and the addresses a client reads the values at.
"""

from __future__ import annotations

import struct
import zlib
from collections.abc import Iterator

import pytest

from cnc_objects.objects import AddressSpace
from cnc_objects.objects.model import Access, CncObject
from cnc_objects.objects.plc_structs import PlcStructs
from cnc_objects.protocol.ads_symbols import (
    AdsDataType,
    AdsDataTypeFlag,
    AdsSymbolFlag,
    SymbolEntry,
    SymbolGroup,
    SymbolUploadFlag,
    decode_datatype_entries,
    decode_datatype_entry,
    decode_symbol_entries,
    decode_symbol_entry,
    decode_upload_info,
    twincat_type,
)
from cnc_objects.protocol.constants import CncPort
from cnc_objects.protocol.errors import AdsReturnCode
from cnc_objects.service.ads.symbols import SymbolService
from cnc_objects.service.binding import build_address_space
from cnc_objects.service.config import build_config
from cnc_objects.service.kernel.clock import VirtualClock
from cnc_objects.service.kernel.kernel import Kernel
from tests.support.ads_symbols import DEFAULT_MACHINE_OBJECTS

E = AdsReturnCode
PYADS_SYMBOL_ENTRY_BYTES = 30 + 3 * 256  # what pyads' adsGetSymbolInfo asks for
VALUE_BY_HANDLE = 0xF005
PLC_GROUP = 0x4020



@pytest.fixture(scope="module")
def space() -> Iterator[AddressSpace]:
    config = build_config()
    kernel = Kernel(config, VirtualClock(config.cycle_ms / 1000.0))
    yield build_address_space(kernel)


@pytest.fixture(scope="module")
def service(space: AddressSpace) -> SymbolService:
    return SymbolService(space)


def ok(result: tuple[int, bytes | str]) -> bytes:
    code, payload = result
    assert code == 0, payload
    assert isinstance(payload, bytes)
    return payload


def refused(result: tuple[int, bytes | str], code: int) -> str:
    got, message = result
    assert (got, isinstance(message, str)) == (code, True), message
    return message


def info_by_name(service: SymbolService, name: bytes, length: int = PYADS_SYMBOL_ENTRY_BYTES):
    return service.read_write(SymbolGroup.INFO_BY_NAME_EX, 0, name, length)


def first(space: AddressSpace, predicate) -> CncObject:
    return next(obj for obj in space.objects() if predicate(obj))


# ------------------------------------------------------------------------- upload info


def test_upload_info_64_bytes_describes_both_uploads(service: SymbolService, space) -> None:
    data = ok(service.read(SymbolGroup.UPLOAD_INFO2, 0, 1024))  # pyads asks for 1024
    assert len(data) == 64
    info = decode_upload_info(data)
    symbols = ok(service.read(SymbolGroup.UPLOAD, 0, 1 << 20))
    types = ok(service.read(SymbolGroup.DT_UPLOAD, 0, 1 << 20))
    assert info.symbol_count == len(space) == DEFAULT_MACHINE_OBJECTS
    assert info.symbol_size == len(symbols) == service.upload_bytes
    assert info.datatype_count == len(decode_datatype_entries(types))
    assert info.datatype_size == len(types) == service.datatype_upload_bytes
    assert (info.max_dynamic_symbols, info.used_dynamic_symbols) == (0, 0)
    assert info.invalid_dynamic_symbols == 0
    assert info.encoding_code_page == 1252
    assert info.flags & SymbolUploadFlag.INCLUDES_BASE_TYPES
    assert data[36:] == bytes(28)  # reserved


@pytest.mark.parametrize("length", [24, 25, 63])
def test_upload_info2_is_24_bytes_below_64(service: SymbolService, length: int) -> None:
    data = ok(service.read(SymbolGroup.UPLOAD_INFO2, 0, length))
    assert data == ok(service.read(SymbolGroup.UPLOAD_INFO2, 0, 64))[:24]


def test_upload_info_0xf00c_is_the_8_byte_form(service: SymbolService) -> None:
    data = ok(service.read(SymbolGroup.UPLOAD_INFO, 0, 64))
    assert data == struct.pack("<II", DEFAULT_MACHINE_OBJECTS, service.upload_bytes)
    assert ok(service.read(SymbolGroup.UPLOAD_INFO, 0, 8)) == data


@pytest.mark.parametrize(("group", "length"), [(0xF00F, 23), (0xF00F, 0), (0xF00C, 7)])
def test_upload_info_read_too_short_is_0x705(service: SymbolService, group: int, length: int) -> None:
    refused(service.read(group, 0, length), E.DEVICE_INVALIDSIZE)


# ------------------------------------------------------------------------- symbol upload


def test_symbol_upload_lists_every_object_field_by_field(service: SymbolService, space) -> None:
    entries = decode_symbol_entries(ok(service.read(SymbolGroup.UPLOAD, 0, service.upload_bytes)))
    assert [e.name for e in entries] == [o.name for o in space.objects()]
    for entry, obj in zip(entries, space.objects()):
        tc = twincat_type(obj.dtype)
        assert entry.type_name == tc.name, obj.name
        assert entry.data_type == tc.data_type, obj.name
        assert entry.size == obj.length, obj.name
        assert entry.comment == obj.description, obj.name
        readonly = bool(entry.flags & AdsSymbolFlag.READONLY)
        assert readonly == (obj.access is Access.READ), obj.name
        assert entry.flags & ~AdsSymbolFlag.READONLY == 0, obj.name


def test_symbol_addresses_lead_back_to_the_object(service: SymbolService, space) -> None:
    entries = decode_symbol_entries(ok(service.read(SymbolGroup.UPLOAD, 0, service.upload_bytes)))
    ports = set()
    for entry, obj in zip(entries, space.objects()):
        if obj.port == CncPort.PLC:  # the PLC's own memory area on port 851
            assert (entry.group, entry.offset) == (PLC_GROUP, obj.offset), obj.name
            found = space.find(CncPort.PLC, entry.group, entry.offset)
            assert not isinstance(found, tuple) and found.obj is obj
        else:  # value by handle, served on every port
            assert entry.group == VALUE_BY_HANDLE, obj.name
            assert space.by_handle(entry.offset).obj is obj
        ports.add(obj.port)
    assert ports == {CncPort.GEO, CncPort.COM, CncPort.PLC}


def test_readable_symbols_read_at_their_address_with_their_size(service: SymbolService, space) -> None:
    entries = decode_symbol_entries(ok(service.read(SymbolGroup.UPLOAD, 0, service.upload_bytes)))
    for entry, obj in zip(entries, space.objects()):
        if not obj.access.readable:
            continue
        if entry.group == VALUE_BY_HANDLE:
            code, data = space.read_entry(space.by_handle(entry.offset), entry.size)
        else:
            code, data = space.read(CncPort.PLC, entry.group, entry.offset, entry.size)
        assert code == 0 and len(data) == entry.size, (obj.name, data)


def test_symbol_upload_read_length_must_hold_it(service: SymbolService) -> None:
    message = refused(service.read(SymbolGroup.UPLOAD, 0, service.upload_bytes - 1), E.DEVICE_INVALIDSIZE)
    assert str(service.upload_bytes) in message
    assert len(ok(service.read(SymbolGroup.UPLOAD, 0, service.upload_bytes + 100))) == service.upload_bytes


def test_upload_offsets(service: SymbolService) -> None:
    # TwinCAT's .NET client sets the high bit of the offset; any other offset is refused
    assert ok(service.read(SymbolGroup.UPLOAD, 0x8000_0000, 1 << 20)) == ok(
        service.read(SymbolGroup.UPLOAD, 0, 1 << 20)
    )
    refused(service.read(SymbolGroup.UPLOAD, 4, 1 << 20), E.DEVICE_INVALIDOFFSET)
    refused(service.read(SymbolGroup.DT_UPLOAD, 1, 1 << 20), E.DEVICE_INVALIDOFFSET)


# ------------------------------------------------------------------------- data type upload


def test_data_type_upload_has_every_type_the_symbols_use(service: SymbolService, space) -> None:
    types = decode_datatype_entries(ok(service.read(SymbolGroup.DT_UPLOAD, 0, 1 << 20)))
    used = {twincat_type(o.dtype) for o in space.objects()}
    assert {t.name for t in types} == {tc.name for tc in used}
    assert {"BOOL", "UINT", "UDINT", "DINT", "LREAL", "STRING(83)", "STRING(255)"} <= {
        t.name for t in types
    }
    by_name = {tc.name: tc for tc in used}
    for t in types:
        tc = by_name[t.name]
        assert (t.size, t.data_type) == (tc.size, tc.data_type)
        assert (t.version, t.flags, t.offset) == (1, AdsDataTypeFlag.DATATYPE, 0)
        assert (t.type_name, t.comment, t.array, t.sub_items) == ("", "", (), ())
        assert t.hash_value == zlib.crc32(t.name.encode())


def test_data_type_upload_read_length_must_hold_it(service: SymbolService) -> None:
    size = service.datatype_upload_bytes
    refused(service.read(SymbolGroup.DT_UPLOAD, 0, size - 1), E.DEVICE_INVALIDSIZE)
    assert len(ok(service.read(SymbolGroup.DT_UPLOAD, 0, size))) == size


# ------------------------------------------------------------------------- symbol by name

OBJECT_KINDS = {
    "BOOLEAN on 851": lambda o: o.dtype.name == "BOOLEAN" and o.port == CncPort.PLC,
    "BOOLEAN on 553": lambda o: o.dtype.name == "BOOLEAN" and o.port == CncPort.COM,
    "UNS16 on 551": lambda o: o.dtype.name == "UNS16" and o.port == CncPort.GEO,
    "UNS32 on 851": lambda o: o.dtype.name == "UNS32" and o.port == CncPort.PLC,
    "SGN32": lambda o: o.dtype.name == "SGN32",
    "REAL64 on 551": lambda o: o.dtype.name == "REAL64" and o.port == CncPort.GEO,
    "STRING(84) read-only": lambda o: o.dtype.name == "STRING(84)" and o.access is Access.READ,
    "STRING write-only": lambda o: o.dtype.kind == "str" and o.access is Access.WRITE,
    "read-write": lambda o: o.access is Access.READ_WRITE,
    "write-only": lambda o: o.access is Access.WRITE and o.dtype.kind != "str",
}


@pytest.mark.parametrize("kind", sorted(OBJECT_KINDS))
def test_symbol_info_by_name_per_object_kind(service: SymbolService, space, kind: str) -> None:
    obj = first(space, OBJECT_KINDS[kind])
    handle = space.by_name(obj.name).handle
    data = ok(info_by_name(service, obj.name.encode() + b"\x00"))  # pyads sends the NUL
    entry, length = decode_symbol_entry(data)
    assert length == len(data) <= PYADS_SYMBOL_ENTRY_BYTES  # pyads checks entryLength
    tc = twincat_type(obj.dtype)
    plc = obj.port == CncPort.PLC
    assert entry == SymbolEntry(
        group=PLC_GROUP if plc else VALUE_BY_HANDLE,
        offset=obj.offset if plc else handle,
        size=obj.length,
        data_type=tc.data_type,
        flags=AdsSymbolFlag.READONLY if obj.access is Access.READ else 0,
        name=obj.name,
        type_name=tc.name,
        comment=obj.description,
    )
    upload = ok(service.read(SymbolGroup.UPLOAD, 0, service.upload_bytes))
    assert data in upload  # the same bytes as its upload entry


def test_symbol_names_are_found_in_any_case_with_or_without_nul(service: SymbolService, space) -> None:
    name = first(space, lambda o: o.port == CncPort.PLC and "[0]" in o.name).name
    expected = ok(info_by_name(service, name.encode()))
    assert ok(info_by_name(service, name.upper().encode() + b"\x00garbage")) == expected
    assert decode_symbol_entry(expected)[0].name == name  # the catalog's spelling


def test_base_types_are_the_twincat_types_pyads_knows(service: SymbolService, space) -> None:
    seen = {}
    for isg in ("BOOLEAN", "UNS32", "SGN32", "REAL64", "STRING(84)"):
        obj = first(space, lambda o, isg=isg: o.dtype.name == isg and o.access.readable)
        seen[isg] = decode_symbol_entry(ok(info_by_name(service, obj.name.encode())))[0]
    assert {k: (e.type_name, e.data_type) for k, e in seen.items()} == {
        "BOOLEAN": ("BOOL", AdsDataType.BIT),
        "UNS32": ("UDINT", AdsDataType.UINT32),
        "SGN32": ("DINT", AdsDataType.INT32),
        "REAL64": ("LREAL", AdsDataType.REAL64),
        "STRING(84)": ("STRING(83)", AdsDataType.STRING),
    }


def test_unknown_symbol_is_0x710(service: SymbolService) -> None:
    message = refused(info_by_name(service, b"gpCh[99].nothing\x00"), E.DEVICE_SYMBOLNOTFOUND)
    assert "gpCh[99].nothing" in message
    refused(info_by_name(service, b""), E.DEVICE_SYMBOLNOTFOUND)
    refused(info_by_name(service, b"\x00ch1.ax1.requested_link_to_physical_axis"), E.DEVICE_SYMBOLNOTFOUND)


def test_symbol_entry_read_length_must_hold_the_entry(service: SymbolService, space) -> None:
    name = space.objects()[0].name.encode()
    size = len(ok(info_by_name(service, name)))
    refused(info_by_name(service, name, size - 1), E.DEVICE_INVALIDSIZE)
    refused(info_by_name(service, name, 0), E.DEVICE_INVALIDSIZE)
    assert len(ok(info_by_name(service, name, size))) == size


def test_name_that_is_not_cp1252_is_0x706(service: SymbolService) -> None:
    refused(info_by_name(service, b"ch1.\x81x"), E.DEVICE_INVALIDDATA)  # 0x81: no CP1252 char


def test_symbol_info_by_name_0xf007_is_group_offset_size(service: SymbolService, space) -> None:
    obj = first(space, lambda o: o.port == CncPort.GEO and o.dtype.name == "REAL64")
    data = ok(service.read_write(SymbolGroup.INFO_BY_NAME, 0, obj.name.encode(), 12))
    assert struct.unpack("<III", data) == (VALUE_BY_HANDLE, space.by_name(obj.name).handle, 8)
    refused(service.read_write(SymbolGroup.INFO_BY_NAME, 0, obj.name.encode(), 11), E.DEVICE_INVALIDSIZE)
    refused(service.read_write(SymbolGroup.INFO_BY_NAME, 0, b"nope", 12), E.DEVICE_SYMBOLNOTFOUND)


# ------------------------------------------------------------------------- type by name


def type_info(service: SymbolService, name: bytes, length: int = 1024):
    return service.read_write(SymbolGroup.DT_INFO_BY_NAME_EX, 0, name, length)


@pytest.mark.parametrize(
    ("asked", "name", "size", "ads"),
    [
        (b"BOOL", "BOOL", 1, AdsDataType.BIT),
        (b"UINT\x00", "UINT", 2, AdsDataType.UINT16),
        (b"udint", "UDINT", 4, AdsDataType.UINT32),
        (b"DINT", "DINT", 4, AdsDataType.INT32),
        (b"LREAL", "LREAL", 8, AdsDataType.REAL64),
        (b"STRING(80)", "STRING(80)", 81, AdsDataType.STRING),
        (b"STRING", "STRING(80)", 81, AdsDataType.STRING),
        (b"string(83)", "STRING(83)", 84, AdsDataType.STRING),
        (b"SINT", "SINT", 1, AdsDataType.INT8),
        (b"ULINT", "ULINT", 8, AdsDataType.UINT64),
        (b"REAL", "REAL", 4, AdsDataType.REAL32),
        (b"WORD", "WORD", 2, AdsDataType.UINT16),
    ],
)
def test_data_type_info_by_name_answers_base_types(
    service: SymbolService, asked: bytes, name: str, size: int, ads: AdsDataType
) -> None:
    data = ok(type_info(service, asked))
    entry, length = decode_datatype_entry(data)
    assert length == len(data)
    assert (entry.name, entry.size, entry.data_type) == (name, size, ads)
    assert (entry.version, entry.flags, entry.sub_items) == (1, AdsDataTypeFlag.DATATYPE, ())


def test_data_type_info_is_the_upload_entry_for_used_types(service: SymbolService) -> None:
    upload = ok(service.read(SymbolGroup.DT_UPLOAD, 0, 1 << 20))
    for entry in decode_datatype_entries(upload):
        assert ok(type_info(service, entry.name.lower().encode())) in upload


@pytest.mark.parametrize("name", [b"TIME", b"ST_Unknown", b"STRING(0)", b"", b"ARRAY [0..1] OF INT"])
def test_unknown_data_type_is_0x710(service: SymbolService, name: bytes) -> None:
    refused(type_info(service, name), E.DEVICE_SYMBOLNOTFOUND)


def test_data_type_read_length_must_hold_the_entry(service: SymbolService) -> None:
    size = len(ok(type_info(service, b"LREAL")))
    refused(type_info(service, b"LREAL", size - 1), E.DEVICE_INVALIDSIZE)


# ------------------------------------------------------------------------- the rest


def test_symbol_version_is_one_byte(service: SymbolService) -> None:
    version = bytes((service.version,))
    assert ok(service.read(SymbolGroup.VERSION, 0, 1)) == version != b"\x00"
    assert ok(service.read(SymbolGroup.VERSION, 0, 4)) == version
    refused(service.read(SymbolGroup.VERSION, 0, 0), E.DEVICE_INVALIDSIZE)


def test_symbol_version_changes_with_the_table(space: AddressSpace) -> None:
    """Another table (here: the same objects without the HLI structs) gives another
    version, so that clients watching 0xF008 reload their symbols."""
    with_structs = SymbolService(space, PlcStructs(space))
    without = SymbolService(space)
    assert with_structs.version != without.version
    assert SymbolService(space, PlcStructs(space)).version == with_structs.version


def test_handles_exactly_the_symbol_groups(service: SymbolService) -> None:
    for group in SymbolGroup:
        assert service.handles(group)
    for group in (0xF003, 0xF004, 0xF005, 0xF006, 0xF00A, 0xF010, 0xF080, 0xF100, 0x4020):
        assert not service.handles(group)


def test_wrong_command_for_a_service(service: SymbolService) -> None:
    refused(service.read(SymbolGroup.INFO_BY_NAME_EX, 0, 1024), E.DEVICE_SRVNOTSUPP)
    refused(service.read(SymbolGroup.DT_INFO_BY_NAME_EX, 0, 1024), E.DEVICE_SRVNOTSUPP)
    refused(service.read_write(SymbolGroup.UPLOAD, 0, b"x", 1 << 20), E.DEVICE_SRVNOTSUPP)
    # a ReadWrite that writes nothing is a Read
    assert ok(service.read_write(SymbolGroup.UPLOAD_INFO2, 0, b"", 24)) == ok(
        service.read(SymbolGroup.UPLOAD_INFO2, 0, 24)
    )
    for group in SymbolGroup:
        refused(service.write(group, 0, b"\x00"), E.DEVICE_INVALIDACCESS)
    refused(service.read(0xF0FF, 0, 4), E.DEVICE_INVALIDGRP)
    refused(service.read_write(0xF0FF, 0, b"x", 4), E.DEVICE_INVALIDGRP)


def test_build_is_measured(service: SymbolService) -> None:
    # the numbers go into the notes; only their presence is checked here (speed targets
    # live in benchmarks, not in timed tests)
    assert service.build_ns > 0
    assert service.upload_bytes == service.info.symbol_size
