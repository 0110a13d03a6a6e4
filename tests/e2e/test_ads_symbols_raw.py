"""Symbol and data type information over real ADS: raw AMS frames and pyads.

A service runs with ADS on a loopback address of its own. The raw client (frames built
by hand, ``tests/e2e/test_ads_raw.py``) reads 0xF00F, 0xF00C, 0xF00B, 0xF00E, 0xF009 and
0xF011 and parses every answer field by field with ``struct`` here, from Beckhoff's
layouts (TcAdsDef.h), not with the project's decoders; the catalog to compare against
comes from the other front end (ZeroMQ browse). pyads then does what its users do:
``get_all_symbols()`` and ``read_by_name`` without a type (pyads asks 0xF009 for it).
"""

from __future__ import annotations

import re
import struct
from collections.abc import Iterator
from dataclasses import dataclass

import pytest

from cnc_objects.clients import Client, ObjectInfo
from cnc_objects.testing import ServiceProcess, start_service
from tests.support.ads_raw import READ, READ_WRITE, RawAds, read, read_write
from tests.support.ads_symbols import DEFAULT_MACHINE_OBJECTS
from tests.support.ads_symbols_raw import BIGTYPE, cstrings, parse_symbol, parse_symbols

pyads = pytest.importorskip("pyads")

PLC, GEO, COM = 851, 551, 553
VALUE_BY_HANDLE, PLC_MEMORY = 0xF005, 0x4020
SYM_VERSION, SYM_INFO_BY_NAME_EX, SYM_UPLOAD, SYM_UPLOAD_INFO = 0xF008, 0xF009, 0xF00B, 0xF00C
SYM_DT_UPLOAD, SYM_UPLOAD_INFO2, DT_INFO_BY_NAME_EX = 0xF00E, 0xF00F, 0xF011
ADSSYMBOLFLAG_READONLY = 0x20  # AdsDef.h: 1 << 5
ADSDATATYPEFLAG_DATATYPE = 0x1
SYMBOLNOTFOUND, INVALIDSIZE = 0x710, 0x705

# ISG type -> (TwinCAT type name, ADST id), TcAdsDef.h ADST_*
TWINCAT = {
    "BOOLEAN": ("BOOL", 33), "UNS16": ("UINT", 18), "SGN16": ("INT", 2),
    "UNS32": ("UDINT", 19), "SGN32": ("DINT", 3), "REAL64": ("LREAL", 5),
    "REAL32": ("REAL", 4), "UNS08": ("USINT", 17), "SGN08": ("SINT", 16),
    "UNS64": ("ULINT", 21), "SGN64": ("LINT", 20),
}




def struct_names(catalog: list[ObjectInfo]) -> set[str]:
    """The struct and array symbols above the PLC symbols: every prefix of a PLC path
    that ends before a ``.`` or a ``[`` (``gpCh``, ``gpCh[0]``, ``gpCh[0].bahn_state``)."""
    names = set()
    for info in catalog:
        if info.port == PLC:
            for k, char in enumerate(info.name):
                if char in ".[":
                    names.add(info.name[:k])
    return names


def twincat(info: ObjectInfo) -> tuple[str, int]:
    """TwinCAT name and ADST id of an object's ISG type; STRING(n) is STRING(n-1)."""
    if info.type.startswith("STRING("):
        return f"STRING({info.length - 1})", 30
    return TWINCAT[info.type]


# ----------------------------------------------------------------------- parsing by hand










@dataclass(frozen=True)
class DataType:
    entry_length: int
    version: int
    hash_value: int
    type_hash_value: int
    size: int
    offset: int
    data_type: int
    flags: int
    array_dims: int
    sub_items: int
    name: str
    type_name: str
    comment: str


def parse_data_type(data: bytes, at: int) -> DataType:
    """AdsDatatypeEntry: 8 x u32, 5 x u16, then name, type and comment with NULs."""
    fields = struct.unpack_from("<8I", data, at)
    name_length, type_length, comment_length, dims, items = struct.unpack_from("<5H", data, at + 32)
    strings = cstrings(data, at + 42, name_length, type_length, comment_length)
    return DataType(*fields, dims, items, *strings)


def read_ok(ads: RawAds, group: int, length: int, port: int = PLC, offset: int = 0) -> bytes:
    """Read over ADS: result 0 and the data of the announced length."""
    got = ads.call(READ, read(group, offset, length), port=port)
    result, size = struct.unpack_from("<II", got.data)
    assert result == 0, hex(result)
    assert len(got.data) == 8 + size
    return got.data[8:]


def read_write_reply(ads: RawAds, group: int, data: bytes, length: int) -> tuple[int, bytes]:
    """ReadWrite over ADS: (result, data); an error reply is 8 bytes, length 0."""
    got = ads.call(READ_WRITE, read_write(group, 0, length, data), port=PLC)
    result, size = struct.unpack_from("<II", got.data)
    assert len(got.data) == 8 + size
    assert result == 0 or size == 0
    return result, got.data[8:]


# ----------------------------------------------------------------------- fixtures


@pytest.fixture(scope="module")
def service(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServiceProcess]:
    """One service, ADS on 127.0.0.<n>:48898 (pyads tells servers apart by IP)."""
    running = start_service(program_dir=tmp_path_factory.mktemp("ads-symbols"), ads=True)
    yield running
    assert running.stop() == 0, running.log_text


@pytest.fixture(scope="module")
def catalog(service: ServiceProcess) -> list[ObjectInfo]:
    """Every object, as the ZeroMQ front end describes it."""
    with Client(service.endpoint) as cnc:
        return cnc.browse("*")


@pytest.fixture
def ads(service: ServiceProcess) -> Iterator[RawAds]:
    connection = RawAds(service)
    yield connection
    connection.close()


@pytest.fixture(scope="module")
def plc(service: ServiceProcess) -> Iterator[object]:
    host, _ = service.ads_address  # type: ignore[misc]
    connection = pyads.Connection(service.ams_net_id, PLC, host)
    connection.open()
    yield connection
    connection.close()


# ----------------------------------------------------------------------- raw: upload info


def test_upload_info_64_bytes_field_by_field(ads: RawAds, catalog: list[ObjectInfo]) -> None:
    data = read_ok(ads, SYM_UPLOAD_INFO2, 64)
    assert len(data) == 64
    (symbols, symbol_bytes, types, type_bytes, max_dynamic, used_dynamic, invalid_dynamic,
     code_page, flags) = struct.unpack_from("<9I", data)
    # + technology units and spindle, manual mode, tools and offsets (issue 28), alarms
    # (issue 29: 6 + 13 fields x (16 active + 32 history slots))
    assert len(catalog) == DEFAULT_MACHINE_OBJECTS
    assert symbols == len(catalog) + len(struct_names(catalog))
    assert symbol_bytes == len(read_ok(ads, SYM_UPLOAD, symbol_bytes))
    assert type_bytes == len(read_ok(ads, SYM_DT_UPLOAD, type_bytes))
    struct_types = {s.type_name for s in parse_symbols(read_ok(ads, SYM_UPLOAD, symbol_bytes))
                    if s.data_type == BIGTYPE}
    # and the padding members' types, ARRAY [0..n-1] OF BYTE, with BYTE (issue 41)
    paddings = set(re.findall(rb"ARRAY \[0\.\.\d+\] OF BYTE\x00", read_ok(
        ads, SYM_DT_UPLOAD, type_bytes)))
    assert paddings
    assert types == len({twincat(info)[0] for info in catalog}) + len(struct_types) + len(
        paddings) + 1
    assert (max_dynamic, used_dynamic, invalid_dynamic) == (0, 0, 0)
    assert code_page == 1252
    assert flags & 0x2  # includes base types
    assert data[36:] == bytes(28)


def test_upload_info_forms_by_read_length(ads: RawAds) -> None:
    full = read_ok(ads, SYM_UPLOAD_INFO2, 64)
    assert read_ok(ads, SYM_UPLOAD_INFO2, 1024) == full  # pyads' string buffer
    assert read_ok(ads, SYM_UPLOAD_INFO2, 24) == full[:24]  # AdsSymbolUploadInfo2
    assert read_ok(ads, SYM_UPLOAD_INFO, 8) == full[:8]  # AdsSymbolUploadInfo
    assert read_ok(ads, SYM_UPLOAD_INFO2, 64, port=GEO) == full  # every port serves it
    assert read_ok(ads, SYM_VERSION, 1) != b"\x00"  # one byte, from the table's contents


def test_upload_info_read_too_short_is_0x705_and_the_connection_goes_on(ads: RawAds) -> None:
    got = ads.call(READ, read(SYM_UPLOAD_INFO2, 0, 23), port=PLC)
    assert got.data == struct.pack("<II", INVALIDSIZE, 0)
    assert len(read_ok(ads, SYM_UPLOAD_INFO2, 24)) == 24


# ----------------------------------------------------------------------- raw: symbol upload


def test_symbol_upload_field_by_field(ads: RawAds, catalog: list[ObjectInfo]) -> None:
    size = struct.unpack_from("<I", read_ok(ads, SYM_UPLOAD_INFO, 8), 4)[0]
    symbols = parse_symbols(read_ok(ads, SYM_UPLOAD, size))
    assert [s.name for s in symbols[: len(catalog)]] == [info.name for info in catalog]
    structs = symbols[len(catalog):]  # the structs and arrays of the HLI follow
    assert {s.name for s in structs} == struct_names(catalog)
    for symbol in structs:
        assert (symbol.group, symbol.data_type) == (PLC_MEMORY, BIGTYPE), symbol.name
        assert symbol.entry_length % 8 == 0
    for symbol, info in zip(symbols, catalog):
        assert (symbol.type_name, symbol.data_type) == twincat(info), info.name
        assert symbol.size == info.length, info.name
        assert symbol.comment == info.description, info.name
        assert symbol.flags == (ADSSYMBOLFLAG_READONLY if info.access == "r" else 0), info.name
        assert symbol.entry_length % 8 == 0  # NUL-padded like TwinCAT's
        if info.port == PLC:
            assert (symbol.group, symbol.offset) == (PLC_MEMORY, info.offset), info.name
        else:
            assert symbol.group == VALUE_BY_HANDLE, info.name


def test_every_symbol_reads_at_its_address_on_port_851(
    ads: RawAds, catalog: list[ObjectInfo]
) -> None:
    """Write-only command objects too: they read back the value last written."""
    size = struct.unpack_from("<I", read_ok(ads, SYM_UPLOAD_INFO, 8), 4)[0]
    symbols = parse_symbols(read_ok(ads, SYM_UPLOAD, size))
    assert any(info.access == "w" for info in catalog)
    assert len(symbols) > len(catalog)  # the structs and arrays too
    for symbol in symbols:
        value = read_ok(ads, symbol.group, symbol.size, offset=symbol.offset)
        assert len(value) == symbol.size, symbol.name


def test_a_geo_symbol_by_handle_reads_what_its_own_address_reads(
    ads: RawAds, catalog: list[ObjectInfo]
) -> None:
    info = next(i for i in catalog if i.name == "ch1.ax1.vel_max")
    result, data = read_write_reply(ads, SYM_INFO_BY_NAME_EX, info.name.encode() + b"\0", 798)
    symbol = parse_symbol(data, 0)
    by_symbol = read_ok(ads, symbol.group, symbol.size, offset=symbol.offset)  # on port 851
    by_address = read_ok(ads, info.group, info.length, port=info.port, offset=info.offset)
    assert by_symbol == by_address
    assert struct.unpack("<d", by_symbol)[0] > 0


# ----------------------------------------------------------------------- raw: data types


def test_data_type_upload_field_by_field(ads: RawAds, catalog: list[ObjectInfo]) -> None:
    info = read_ok(ads, SYM_UPLOAD_INFO2, 24)
    count, size = struct.unpack_from("<II", info, 8)
    data = read_ok(ads, SYM_DT_UPLOAD, size)
    types, at = [], 0
    while at < len(data):
        entry = parse_data_type(data, at)
        types.append(entry)
        at += entry.entry_length
    assert at == len(data) and len(types) == count
    expected = {twincat(i)[0]: (twincat(i)[1], i.length) for i in catalog}
    expected["BYTE"] = (17, 1)  # the element of the padding members' arrays (issue 41)
    base = [t for t in types if t.data_type != BIGTYPE]
    assert {t.name: (t.data_type, t.size) for t in base} == expected
    for t in base:
        assert (t.version, t.offset, t.flags) == (1, 0, ADSDATATYPEFLAG_DATATYPE)
        assert (t.array_dims, t.sub_items, t.type_name, t.comment) == (0, 0, "", "")


@pytest.mark.parametrize(
    ("name", "expected"),
    [
        (b"BOOL", ("BOOL", 33, 1)),
        (b"UINT", ("UINT", 18, 2)),
        (b"UDINT\x00", ("UDINT", 19, 4)),
        (b"DINT", ("DINT", 3, 4)),
        (b"LREAL", ("LREAL", 5, 8)),
        (b"STRING(80)", ("STRING(80)", 30, 81)),
        (b"STRING", ("STRING(80)", 30, 81)),
        (b"STRING(83)", ("STRING(83)", 30, 84)),
    ],
)
def test_data_type_info_by_name_field_by_field(
    ads: RawAds, name: bytes, expected: tuple[str, int, int]
) -> None:
    result, data = read_write_reply(ads, DT_INFO_BY_NAME_EX, name, 1024)
    assert result == 0
    entry = parse_data_type(data, 0)
    assert entry.entry_length == len(data)
    assert (entry.name, entry.data_type, entry.size) == expected
    assert (entry.version, entry.flags, entry.sub_items) == (1, ADSDATATYPEFLAG_DATATYPE, 0)


def test_unknown_data_type_is_0x710_and_the_connection_goes_on(ads: RawAds) -> None:
    assert read_write_reply(ads, DT_INFO_BY_NAME_EX, b"ST_Nothing", 1024) == (SYMBOLNOTFOUND, b"")
    assert read_write_reply(ads, DT_INFO_BY_NAME_EX, b"LREAL", 1024)[0] == 0


# ----------------------------------------------------------------------- raw: symbol by name


def test_symbol_info_by_name_and_its_errors(ads: RawAds, catalog: list[ObjectInfo]) -> None:
    info = next(i for i in catalog if i.name == "gpCh[0].contour_lookahead.state.count_logged_blocks")
    result, data = read_write_reply(ads, SYM_INFO_BY_NAME_EX, info.name.encode(), 798)
    symbol = parse_symbol(data, 0)
    assert result == 0 and symbol.entry_length == len(data)
    assert (symbol.group, symbol.offset, symbol.size) == (PLC_MEMORY, info.offset, 4)
    assert (symbol.type_name, symbol.data_type, symbol.comment) == ("UDINT", 19, info.description)
    assert read_write_reply(ads, SYM_INFO_BY_NAME_EX, b"gpCh[0].nothing", 798) == (SYMBOLNOTFOUND, b"")
    too_short = read_write_reply(ads, SYM_INFO_BY_NAME_EX, info.name.encode(), len(data) - 1)
    assert too_short == (INVALIDSIZE, b"")
    assert read_write_reply(ads, SYM_INFO_BY_NAME_EX, info.name.encode(), 798) == (0, data)


# ----------------------------------------------------------------------- pyads


def test_pyads_get_all_symbols_lists_every_object(plc, catalog: list[ObjectInfo]) -> None:
    symbols = plc.get_all_symbols()
    assert [s.name for s in symbols[: len(catalog)]] == [info.name for info in catalog]
    assert {s.name for s in symbols[len(catalog):]} == struct_names(catalog)
    for symbol, info in zip(symbols, catalog):
        assert symbol.symbol_type == twincat(info)[0], info.name
        assert symbol.comment == info.description, info.name
        if info.port == PLC:
            assert (symbol.index_group, symbol.index_offset) == (PLC_MEMORY, info.offset)
        else:
            assert symbol.index_group == VALUE_BY_HANDLE


@pytest.mark.parametrize(
    ("name", "twincat_type"),
    [
        ("ch1.mc_active_single_block_r", "BOOL"),
        ("gpCh[0].contour_lookahead.state.count_logged_blocks", "UDINT"),
        ("ch1.ax1.command_position_acs", "DINT"),
        ("ch1.ax1.vel_max", "LREAL"),
        ("ch1.mc_active_program_name_r", "STRING(83)"),
    ],
)
def test_pyads_read_by_name_without_a_type(
    plc, service: ServiceProcess, name: str, twincat_type: str
) -> None:
    info = plc.get_symbol(name)  # looked up with 0xF009
    assert info.symbol_type == twincat_type
    value = plc.read_by_name(name)  # no plc_datatype: pyads takes it from 0xF009
    with Client(service.endpoint) as cnc:
        expected = cnc.read(name)  # the ZeroMQ front end reads the same, idle
    assert (value, type(value)) == (expected, type(expected))


def test_pyads_unknown_symbol_raises_0x710_and_the_connection_goes_on(plc) -> None:
    with pytest.raises(pyads.ADSError) as raised:
        plc.read_by_name("gpCh[0].no_such_element")
    assert raised.value.err_code == SYMBOLNOTFOUND
    assert plc.read_by_name("ch1.ax1.vel_max", pyads.PLCTYPE_LREAL) > 0
