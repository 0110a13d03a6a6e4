"""The HLI's structs and arrays as a PLC's symbols, over real ADS (issue 26, item 4).

Every level of the HLI hierarchy is a symbol (``gpCh``, ``gpCh[0]``,
``gpCh[0].contour_lookahead``, ...) whose data type (0xF011) lists its members with
offsets and sizes that match the bytes a read of the struct returns. Structs are read,
written (their writable members), subscribed and used in sum commands like any symbol.
Frames are built and parsed by hand here (``test_ads_raw``, ``test_ads_symbols_raw``).
"""

from __future__ import annotations

import re
import struct
from dataclasses import dataclass
from pathlib import Path

from tests.support.ads_answers import ANY, INVALIDSIZE, OK, answer
from tests.support.ads_raw import (
    ADD_NOTIFICATION,
    DELETE_NOTIFICATION,
    READ,
    READ_WRITE,
    WRITE,
    RawAds,
    add_notification,
    read,
    read_write,
    write,
)
from tests.support.ads_symbols_raw import BIGTYPE, cstrings, parse_symbol, parse_symbols

REQUEST = "gpCh[0].contour_lookahead.request"  # start_position, length: LREAL, writable
STATE = "gpCh[0].contour_lookahead.state"  # read-only members
INVALIDACCESS = 0x704


@dataclass(frozen=True)
class Item:
    """An AdsDatatypeEntry with its array bounds and sub items, parsed by hand."""

    name: str
    type_name: str
    size: int
    offset: int
    data_type: int
    flags: int
    array: tuple[tuple[int, int], ...]
    members: tuple[Item, ...]
    length: int


def parse_type(data: bytes, at: int = 0) -> Item:
    """8 x u32, 5 x u16, the strings, array infos (2 x u32 each), sub items."""
    length, _, _, _, size, offset, data_type, flags = struct.unpack_from("<8I", data, at)
    name_length, type_length, comment_length, dims, items = struct.unpack_from("<5H", data, at + 32)
    name, type_name, _ = cstrings(data, at + 42, name_length, type_length, comment_length)
    pos = at + 42 + name_length + type_length + comment_length + 3
    array = tuple(struct.unpack_from("<II", data, pos + 8 * k) for k in range(dims))
    pos += 8 * dims
    members = []
    for _ in range(items):
        member = parse_type(data, pos)
        members.append(member)
        pos += member.length
    assert pos <= at + length
    return Item(name, type_name, size, offset, data_type, flags, array, tuple(members), length)


def symbol(ads: RawAds, name: str):
    result, data = answer(ads, READ_WRITE, read_write(0xF009, 0, ANY, name.encode() + b"\0"))
    assert result == OK, (name, hex(result))
    return parse_symbol(data, 0)


def data_type(ads: RawAds, name: str) -> Item:
    result, data = answer(ads, READ_WRITE, read_write(0xF011, 0, ANY, name.encode() + b"\0"))
    assert result == OK, (name, hex(result))
    return parse_type(data)


def value(ads: RawAds, name: str) -> bytes:
    result, data = answer(ads, READ_WRITE, read_write(0xF004, 0, ANY, name.encode() + b"\0"))
    assert result == OK, (name, hex(result))
    return data




def test_a_struct_symbol_and_its_type(ads: RawAds) -> None:
    entry = symbol(ads, REQUEST)
    assert (entry.size, entry.data_type, entry.type_name) == (
        16, BIGTYPE, "HLI_CONTOUR_LOOKAHEAD_REQUEST")
    assert entry.flags & 0x20 == 0  # writable members
    assert symbol(ads, STATE).flags & 0x20  # read-only
    request = data_type(ads, entry.type_name)
    assert request.size == 16 and request.flags & 0x1
    assert [(m.name, m.type_name, m.offset, m.size) for m in request.members] == [
        ("start_position", "LREAL", 0, 8), ("length", "LREAL", 8, 8)]
    assert all(m.flags & 0x2 for m in request.members)  # ADSDATATYPEFLAG_DATAITEM
    assert symbol(ads, "gpCh[0]^.contour_lookahead.request") == entry


def test_every_struct_type_places_its_members_where_a_read_finds_them(ads: RawAds) -> None:
    """For every struct and array of the upload: each member of its type, at its offset
    in the struct's bytes, is what a read of the member by name returns."""
    info = answer(ads, READ, read(0xF00F, 0, 64))[1]
    upload = parse_symbols(answer(ads, READ, read(0xF00B, 0, struct.unpack_from("<I", info, 4)[0]))[1])
    structs = [s for s in upload if s.data_type == BIGTYPE]
    assert {s.name for s in structs} >= {"gpCh", "gpCh[0]", "gpCh[1]", "gpAx", "gpAx[0].lr_state",
                                         "gpCh[0].contour_lookahead.response.block"}
    for entry in structs:
        whole = value(ads, entry.name)
        assert len(whole) == entry.size, entry.name
        item = data_type(ads, entry.type_name)
        assert item.size == entry.size
        if item.array:  # the elements: contiguous, each the element type's size
            ((lower, count),) = item.array
            stride = entry.size // count
            assert data_type(ads, item.type_name).size == stride
            for k in range(lower, lower + count):
                assert whole[k * stride : (k + 1) * stride] == value(
                    ads, f"{entry.name}[{k}]"), (entry.name, k)
            continue
        for member in item.members:
            assert member.offset + member.size <= item.size, (entry.name, member.name)
            if member.name.startswith("_pad_"):  # padding: no symbol of its own
                continue
            assert whole[member.offset : member.offset + member.size] == value(
                ads, f"{entry.name}.{member.name}"), (entry.name, member.name)


def test_an_array_symbol(ads: RawAds) -> None:
    gpch = symbol(ads, "gpCh")
    assert gpch.type_name.startswith("ARRAY [0..1] OF ")
    array = data_type(ads, gpch.type_name)
    assert array.array == ((0, 2),) and array.type_name == gpch.type_name.split(" OF ")[1]
    element = data_type(ads, array.type_name)
    assert gpch.size == 2 * element.size
    assert data_type(ads, gpch.type_name.replace(" ", "")).size == gpch.size  # any spacing


def test_write_a_whole_struct_then_read_its_members(ads: RawAds) -> None:
    entry = symbol(ads, REQUEST)
    data = struct.pack("<dd", 12.5, 40.0)
    assert ads.call(WRITE, write(entry.group, entry.offset, data)).result == OK
    assert value(ads, REQUEST + ".start_position") == struct.pack("<d", 12.5)
    assert value(ads, REQUEST + ".length") == struct.pack("<d", 40.0)
    assert answer(ads, READ, read(entry.group, entry.offset, entry.size)) == (OK, data)
    # At the address, 8 bytes are the first member (same offset); a write must cover one
    # symbol exactly.
    assert ads.call(WRITE, write(entry.group, entry.offset, struct.pack("<d", 1.0))).result == OK
    assert value(ads, REQUEST + ".start_position") == struct.pack("<d", 1.0)
    assert ads.call(WRITE, write(entry.group, entry.offset, data[:12])).result == INVALIDSIZE
    state = symbol(ads, STATE)  # nothing writable: other bytes than its own are refused
    assert ads.call(WRITE, write(state.group, state.offset, b"\xff" * state.size)).result == (
        INVALIDACCESS)


def test_a_struct_handle_reads_and_a_buffer_too_small_is_0x705(ads: RawAds) -> None:
    result, data = answer(ads, READ_WRITE, read_write(0xF003, 0, ANY, REQUEST.encode() + b"\0"))
    handle, size, _, type_length = struct.unpack_from("<IIIH", data)
    assert result == OK and size == 16
    assert data[14 : 14 + type_length] == b"HLI_CONTOUR_LOOKAHEAD_REQUEST"
    assert answer(ads, READ, read(0xF005, handle, 16))[0] == OK
    assert answer(ads, READ, read(0xF005, handle, 15)) == (INVALIDSIZE, b"")
    assert ads.call(WRITE, write(0xF005, handle, bytes(8))).result == INVALIDSIZE


def test_a_notification_on_a_struct_sends_its_bytes_when_a_member_changes(ads: RawAds) -> None:
    entry = symbol(ads, REQUEST)
    got = ads.call(ADD_NOTIFICATION, add_notification(entry.group, entry.offset, entry.size, 4,
                                                      10_000))
    assert got.result == OK
    handle = struct.unpack_from("<I", got.data, 4)[0]
    try:
        first = _sample(ads, handle)
        assert first == value(ads, REQUEST)
        changed = struct.pack("<d", struct.unpack_from("<d", first, 8)[0] + 1.0)
        member = symbol(ads, REQUEST + ".length")
        assert ads.call(WRITE, write(member.group, member.offset, changed)).result == OK
        assert _sample(ads, handle) == first[:8] + changed
    finally:
        ads.call(DELETE_NOTIFICATION, struct.pack("<I", handle))


def _sample(ads: RawAds, handle: int) -> bytes:
    """The data of the next sample of notification ``handle``."""
    while True:
        body = ads.notification().data
        _, stamps = struct.unpack_from("<II", body)
        at = 8
        for _ in range(stamps):
            _, samples = struct.unpack_from("<QI", body, at)
            at += 12
            for _ in range(samples):
                got, size = struct.unpack_from("<II", body, at)
                if got == handle:
                    return body[at + 8 : at + 8 + size]
                at += 8 + size


def test_sum_read_and_sum_write_of_structs(ads: RawAds) -> None:
    request, state = symbol(ads, REQUEST), symbol(ads, STATE)
    items = [(request.group, request.offset, request.size), (state.group, state.offset, state.size)]
    head = b"".join(struct.pack("<III", *item) for item in items)
    result, body = answer(ads, READ_WRITE, read_write(0xF080, 2, ANY, head))
    assert result == OK and struct.unpack_from("<II", body) == (OK, OK)
    assert body[8 : 8 + request.size] == value(ads, REQUEST)
    assert body[8 + request.size :] == value(ads, STATE)
    data = struct.pack("<dd", 2.0, 3.0)
    writes = (struct.pack("<III", request.group, request.offset, 16)
              + struct.pack("<III", state.group, state.offset, state.size) + data
              + b"\xff" * state.size)
    result, codes = answer(ads, READ_WRITE, read_write(0xF081, 2, 8, writes))
    assert result == OK and struct.unpack("<II", codes) == (OK, INVALIDACCESS)
    assert value(ads, REQUEST) == data


def test_the_plc_memory_area_reads_as_a_plc_reads_it(ads: RawAds) -> None:
    """At a PLC address the read length says how many bytes of memory: a struct's
    members share its first member's offset, and a longer read takes the symbols that
    follow; a range past the end of the memory area is 0x705, an offset where no symbol
    starts 0x703."""
    request, first = symbol(ads, REQUEST), symbol(ads, REQUEST + ".start_position")
    assert (first.group, first.offset) == (request.group, request.offset) == (0x4020, first.offset)
    whole = answer(ads, READ, read(0x4020, first.offset, 16))
    assert whole == (OK, value(ads, REQUEST))
    assert answer(ads, READ, read(0x4020, first.offset, 8)) == (OK, whole[1][:8])
    assert answer(ads, READ, read(0x4020, first.offset, ANY)) == (INVALIDSIZE, b"")
    assert answer(ads, READ, read(0x4020, first.offset + 1, 4))[0] == 0x703
    gpch = symbol(ads, "gpCh")
    assert answer(ads, READ, read(0x4020, gpch.offset, gpch.size)) == (OK, value(ads, "gpCh"))


def _type_upload(ads: RawAds) -> dict[str, Item]:
    """Every entry of the data type upload (0xF00E), by name."""
    info = answer(ads, READ, read(0xF00F, 0, 64))[1]
    count, size = struct.unpack_from("<II", info, 8)
    result, data = answer(ads, READ, read(0xF00E, 0, size))
    assert result == OK
    types: dict[str, Item] = {}
    at = 0
    while at < len(data):
        item = parse_type(data, at)
        types[item.name] = item
        at += item.length
    assert len(types) == count
    return types


def test_the_type_upload_lays_every_struct_out_as_a_compiler_does(ads: RawAds) -> None:
    """Issue 41, item 3: a reader that lays members out one after the other (pyads'
    structure_def, a code generator) finds each where it is: in every struct type the
    members come in ascending offsets, each starts where the one before ends (gaps are
    padding members of their own) and their sizes add up to the struct's; every member's
    type is in the upload with the member's size; an array is count x element."""
    types = _type_upload(ads)
    structs = [t for t in types.values() if t.members]
    assert {"HLI_CHANNEL", "ST_gpCh_bahn_state", "ST_gpCh_spindle"} <= {t.name for t in structs}
    for item in structs:
        at = 0
        for member in item.members:
            assert member.offset == at, (item.name, member.name, member.offset, at)
            assert types[member.type_name].size == member.size, (item.name, member.name)
            at += member.size
        assert at == item.size, item.name
    for item in types.values():
        if item.array:
            ((_, count),) = item.array
            assert types[item.type_name].size * count == item.size, item.name
    info = answer(ads, READ, read(0xF00F, 0, 64))[1]
    upload = parse_symbols(answer(ads, READ, read(0xF00B, 0, struct.unpack_from("<I", info, 4)[0]))[1])
    for entry in upload:  # and each struct symbol is its type's size
        if entry.data_type == BIGTYPE:
            assert types[entry.type_name].size == entry.size, entry.name
    bahn_state = types["ST_gpCh_bahn_state"]
    assert [m.name for m in bahn_state.members][:2] == ["dist_prog_start", "coord_r"]
    spindle = types["ST_gpCh_spindle"]  # speed_reached_r (BOOL at 0x10), position_r at 0x18
    assert [(m.name, m.type_name, m.offset, m.size) for m in spindle.members][-2:] == [
        ("_pad_0x0011", "ARRAY [0..6] OF BYTE", 0x11, 7), ("position_r", "LREAL", 0x18, 8)]


def handle_of(ads: RawAds, name: str) -> tuple[int, bytes]:
    """(result, answer) of a handle by name (0xF003)."""
    return answer(ads, READ_WRITE, read_write(0xF003, 0, 4, name.encode() + b"\0"))


def test_a_dereference_is_taken_only_after_a_root_element(ads: RawAds) -> None:
    """Issue 41, item 4: ``^`` follows a pointer in TwinCAT, and ISG's HLI has its
    pointers in the root arrays' elements (``gpCh[0]^``, ``gpAx[0]^``); a ``^`` anywhere
    else is an unknown name, 0x710, in every by-name service."""
    assert handle_of(ads, f"{REQUEST}")[0] == OK
    for name in ("gpCh[0]^.contour_lookahead.request", "gpCh[0]^", "GPCH[1]^.spindle",
                 "gpAx[0]^.lr_state.position_offset_r"):
        assert handle_of(ads, name)[0] == OK, name
    for name in ("gpCh^[0].contour_lookahead.request", "gpCh[0].contour_lookahead^.request",
                 "gpCh[0]^^.spindle", "gpCh[0].spindle.override_w^", "^gpCh[0].spindle",
                 "gpCh^", "gpCh[0]^.spindle^"):
        assert handle_of(ads, name)[0] == 0x710, name
        assert answer(ads, READ_WRITE, read_write(0xF009, 0, ANY, name.encode() + b"\0"))[0] == (
            0x710), name
        assert answer(ads, READ_WRITE, read_write(0xF004, 0, ANY, name.encode() + b"\0"))[0] == (
            0x710), name


DOCS = Path(__file__).resolve().parents[2] / "docs" / "ads.md"
DOCS_COUNTS = re.compile(r"\((\d+)\s+of\s+the\s+default\s+machine's\s+(\d+)\s+symbols")


def test_the_docs_count_the_symbols_the_service_uploads(ads: RawAds) -> None:
    """Issue 41, item 5: docs/ads.md's numbers of struct/array symbols and of all
    symbols are those of the upload of the default machine (this module's service)."""
    info = answer(ads, READ, read(0xF00F, 0, 64))[1]
    upload = parse_symbols(answer(ads, READ, read(0xF00B, 0, struct.unpack_from("<I", info, 4)[0]))[1])
    found = DOCS_COUNTS.findall(DOCS.read_text())
    assert found, "docs/ads.md no longer says '(N of the default machine's M symbols'"
    structs = sum(1 for entry in upload if entry.data_type == BIGTYPE)
    assert {(int(a), int(b)) for a, b in found} == {(structs, len(upload))}
