"""Struct and array symbols derived from the PLC leaves' names and offsets."""

from __future__ import annotations

import struct
from typing import Any

import pytest

from cnc_objects.objects.address_space import AddressSpace
from cnc_objects.objects.model import Access, CncObject
from cnc_objects.objects.plc_structs import HANDLE_BASE, Node, PlcStructs, struct_members
from cnc_objects.protocol.datatypes import BOOLEAN, REAL64, UNS16, DataType
from cnc_objects.protocol.errors import AdsReturnCode

PLC = 851
LEAVES = [  # name, offset, type, access
    ("gpX[0].a.flag", 0x100, BOOLEAN, Access.READ_WRITE),
    ("gpX[0].a.count", 0x102, UNS16, Access.READ),
    ("gpX[0].b[0].v", 0x110, REAL64, Access.READ),
    ("gpX[0].b[1].v", 0x120, REAL64, Access.READ),
    ("gpX[1].a.flag", 0x200, BOOLEAN, Access.READ_WRITE),
    ("gpX[1].a.count", 0x202, UNS16, Access.READ),
    ("gpX[1].b[0].v", 0x210, REAL64, Access.READ),
    ("gpX[1].b[1].v", 0x220, REAL64, Access.READ),
]


def node(structs: PlcStructs, name: str) -> Node:
    """The struct symbol ``name``, which the test's layout has."""
    found = structs.by_name(name)
    assert found is not None, name
    return found


def leaf(name: str, offset: int, dtype: DataType, access: Access) -> CncObject:
    return CncObject(name, name, PLC, 0x4020, offset, dtype, access, "-", name)


@pytest.fixture
def built() -> tuple[PlcStructs, dict[str, Any]]:
    values: dict[str, Any] = {name: 0 for name, *_ in LEAVES}
    values["gpX[1].a.count"] = 7
    space = AddressSpace()
    for name, offset, dtype, access in LEAVES:
        space.add(leaf(name, offset, dtype, access), lambda n=name: values[n],
                  (lambda v: None) if access.writable else None)
    return PlcStructs(space), values


def test_every_prefix_is_a_symbol_with_a_handle_of_its_own(built: tuple[PlcStructs, dict[str, Any]]) -> None:
    structs, _ = built
    names = [node.name for node in structs.symbols]
    assert names == ["gpX", "gpX[0]", "gpX[0].a", "gpX[0].b", "gpX[0].b[0]", "gpX[0].b[1]",
                     "gpX[1]", "gpX[1].a", "gpX[1].b", "gpX[1].b[0]", "gpX[1].b[1]"]
    assert [node.handle for node in structs.symbols] == [HANDLE_BASE + k for k in range(11)]
    assert structs.by_handle(HANDLE_BASE + 1) is structs.by_name("GPX[0]")
    assert structs.by_name("gpX[0]^.a") is structs.symbols[2]
    assert structs.by_handle(1) is None and structs.by_name("gpX[0].a.flag") is None


def test_layout_strides_and_padding(built: tuple[PlcStructs, dict[str, Any]]) -> None:
    structs, _ = built
    gpx, element, b = (node(structs, n) for n in ("gpX", "gpX[1]", "gpX[1].b"))
    assert (element.start, element.size) == (0x200, 0x100)  # the stride between elements
    assert (gpx.start, gpx.size, gpx.type_name) == (0x100, 0x200, "ARRAY [0..1] OF ST_gpX")
    assert (b.start, b.size, b.type_name) == (0x210, 0x20, "ARRAY [0..1] OF ST_gpX_b")
    assert node(structs, "gpX[0].a").size == 4
    assert not node(structs, "gpX[0].b").writable and node(structs, "gpX[0]").writable


def test_read_places_members_at_their_offsets(built: tuple[PlcStructs, dict[str, Any]]) -> None:
    structs, values = built
    values["gpX[1].b[1].v"] = 2.5
    code, data = structs.read(node(structs, "gpX[1]"), 0xFFFF_FFFF)
    assert code == 0 and len(data) == 0x100
    assert data[:4] == b"\x00\x00\x07\x00" and data[0x20:0x28] == struct.pack("<d", 2.5)
    assert structs.read(node(structs, "gpX[1]"), 0xFF)[0] == AdsReturnCode.DEVICE_INVALIDSIZE


def test_a_write_touches_only_changed_writable_members(built: tuple[PlcStructs, dict[str, Any]]) -> None:
    structs, _ = built
    node_a = node(structs, "gpX[0].a")
    assert structs.decode_write(node_a, b"\x00\x00\x09\x00") == (0, "", [])  # count: read-only
    code, _, writes = structs.decode_write(node_a, b"\x01\x00\x00\x00")
    assert code == 0 and [(e.obj.name, v) for e, v in writes] == [("gpX[0].a.flag", True)]
    assert structs.decode_write(node_a, b"\x02\x00\x00\x00")[0] == AdsReturnCode.DEVICE_INVALIDDATA
    assert structs.decode_write(node_a, b"\x01")[0] == AdsReturnCode.DEVICE_INVALIDSIZE
    # nothing writable in b: its own bytes come back (a round trip), a change is 0x704
    assert structs.decode_write(node(structs, "gpX[0].b"), bytes(32)) == (0, "", [])
    assert structs.decode_write(node(structs, "gpX[0].b"), b"\x01" + bytes(31))[0] == (
        AdsReturnCode.DEVICE_INVALIDACCESS)


def test_elements_laid_out_unevenly_are_refused() -> None:
    space = AddressSpace()
    for name, offset in (("p[0].v", 0), ("p[1].v", 8), ("p[2].v", 20)):
        space.add(leaf(name, offset, UNS16, Access.READ), lambda: 0)
    with pytest.raises(ValueError, match="not evenly laid out"):
        PlcStructs(space)


def test_the_memory_area_reads_any_range_from_a_symbol_and_writes_whole_symbols(
        built: tuple[PlcStructs, dict[str, Any]]) -> None:
    structs, values = built
    values["gpX[0].a.count"] = 0x0102
    assert structs.read_memory(0x100, 4) == (0, b"\x00\x00\x02\x01")  # flag, padding, count
    assert structs.read_memory(0x102, 1) == (0, b"\x02")  # the first byte of count
    assert structs.read_memory(0x101, 1)[0] == AdsReturnCode.DEVICE_INVALIDOFFSET
    assert structs.read_memory(0x100, 0x1000)[0] == AdsReturnCode.DEVICE_INVALIDSIZE
    code, _, writes = structs.decode_memory_write(0x100, b"\x01\x00\x02\x01")  # gpX[0].a
    assert code == 0 and [e.obj.name for e, _ in writes] == ["gpX[0].a.flag"]
    assert structs.decode_memory_write(0x100, b"\x01\x00")[0] == AdsReturnCode.DEVICE_INVALIDSIZE


def test_members_that_would_overlap_are_refused() -> None:
    """Issue 41, item 3: a struct whose member reaches into the next is no PLC struct
    (``gpCh[i].bahn_state`` did, from 0x110 to its axes at 0xE40)."""
    space = AddressSpace()
    for name, offset in (("s[0].a.x", 0x10), ("s[0].b", 0x18), ("s[0].a.y", 0x40)):
        space.add(leaf(name, offset, UNS16, Access.READ), lambda: 0)
    with pytest.raises(ValueError, match=r"s\[0\]\.a .* overlaps s\[0\]\.b"):
        PlcStructs(space)


def test_struct_members_name_every_gap_and_add_up(built: tuple[PlcStructs, dict[str, Any]]) -> None:
    structs, _ = built
    element = node(structs, "gpX[0]")  # a at 0x100 (4 bytes), b at 0x110 (32), stride 0x100
    members = [(m.name, m.offset, m.size, m.type_name) for m in struct_members(element)]
    assert members == [
        ("a", 0, 4, "ST_gpX_a"), ("_pad_0x0004", 4, 12, "ARRAY [0..11] OF BYTE"),
        ("b", 0x10, 32, "ARRAY [0..1] OF ST_gpX_b"),
        ("_pad_0x0030", 0x30, 0xD0, "ARRAY [0..207] OF BYTE")]
    assert [m.name for m in struct_members(node(structs, "gpX[0].a"))] == [
        "flag", "_pad_0x0001", "count"]
