"""The address space (objects/address_space.py) and the COM directory (objects/directory.py).

Built from a handful of hand-made objects bound to a plain dict through getters and
setters: lookups by address, name, handle and glob; reads and write-decoding that
answer with ADS codes (0x6, 0x702..0x706, 0x700) and never raise.
"""

from __future__ import annotations

import struct
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from cnc_objects.objects.address_space import AddressSpace, Entry
from cnc_objects.objects.directory import DESCRIPTOR_SIZE, ObjectDirectory, encode_descriptor
from cnc_objects.objects.model import Access, CncObject
from cnc_objects.protocol.datatypes import BOOLEAN, REAL32, REAL64, SGN16, STRING, UNS16, UNS32, DataType
from cnc_objects.protocol.errors import AdsReturnCode

GEO, COM = 551, 553
E = AdsReturnCode


def make(
    name: str,
    port: int,
    group: int,
    offset: int,
    dtype: DataType,
    access: Access,
    element: str | None = None,
) -> CncObject:
    return CncObject(
        name, element or name.rsplit(".", 1)[-1], port, group, offset, dtype, access, "-", name
    )


LINK = make("ch1.ax1.actual_link_to_physical_axis", GEO, 0x121301, 0x10017, UNS16, Access.READ)
DIST = make("ch1.dist_prog_start", GEO, 0x121301, 0x56, REAL64, Access.READ)
FEED_W = make("ch1.mc_command_feed_override_w", COM, 0x120101, 0x09, UNS16, Access.WRITE)
MODE = make("ch1.mode", COM, 0x120101, 0x50, SGN16, Access.READ_WRITE)
FLAG = make("ch1.flag", COM, 0x120101, 0x51, BOOLEAN, Access.READ_WRITE)
NAME = make("ch1.program_name", COM, 0x120101, 0x52, STRING(8), Access.READ_WRITE)
BROKEN = make("ch1.broken", COM, 0x120101, 0x53, UNS32, Access.READ)


class Space:
    """An address space over a dict of values, recording every setter call."""

    def __init__(self) -> None:
        self.values: dict[str, Any] = {
            LINK.name: 2,
            DIST.name: 1234.5,
            MODE.name: -3,
            FLAG.name: True,
            NAME.name: "MAIN",
        }
        self.written: list[tuple[str, Any]] = []
        self.space = AddressSpace()
        self.space.add(LINK, self.getter(LINK), aliases=(0x021301,))
        self.space.add(DIST, self.getter(DIST), aliases=(0x021301,))
        self.space.add(FEED_W, write=self.setter(FEED_W))
        for obj in (MODE, FLAG, NAME):
            self.space.add(obj, self.getter(obj), self.setter(obj))
        self.space.add(BROKEN, self.failing_getter)

    def getter(self, obj: CncObject):
        return lambda: self.values[obj.name]

    def setter(self, obj: CncObject):
        return lambda value: self.written.append((obj.name, value))

    @staticmethod
    def failing_getter() -> int:
        raise RuntimeError("kernel state is gone")


@pytest.fixture
def bound() -> Space:
    return Space()


@pytest.fixture
def space(bound: Space) -> AddressSpace:
    return bound.space


# --------------------------------------------------------------------------- lookup


def test_find_by_address(space: AddressSpace) -> None:
    entry = space.find(GEO, 0x121301, 0x10017)
    assert isinstance(entry, Entry)
    assert entry.obj is LINK


def test_find_by_alias_gives_the_same_entry(space: AddressSpace) -> None:
    assert space.find(GEO, 0x021301, 0x10017) is space.find(GEO, 0x121301, 0x10017)
    assert space.find(GEO, 0x021301, 0x56).obj is DIST


def test_read_by_alias(space: AddressSpace) -> None:
    assert space.read(GEO, 0x021301, 0x10017, 2) == (0, b"\x02\x00")


@pytest.mark.parametrize(
    "name", [LINK.name, LINK.name.upper(), "CH1.Ax1.Actual_Link_To_Physical_Axis"]
)
def test_find_by_name_is_case_insensitive(space: AddressSpace, name: str) -> None:
    entry = space.by_name(name)
    assert entry is not None and entry.obj is LINK


def test_unknown_name(space: AddressSpace) -> None:
    assert space.by_name("ch9.nothing") is None


def test_handles_are_stable_and_find_their_entry(space: AddressSpace) -> None:
    for obj in space.objects():
        entry = space.by_name(obj.name)
        assert space.by_handle(entry.handle) is entry
    assert sorted(space.by_name(o.name).handle for o in space.objects()) == list(
        range(1, len(space) + 1)
    )


@pytest.mark.parametrize("handle", [0, -1, 8, 10**6])
def test_unknown_handles(space: AddressSpace, handle: int) -> None:
    assert len(space) == 7
    assert space.by_handle(handle) is None


def test_objects_in_registration_order_and_ports(space: AddressSpace) -> None:
    assert space.objects() == [LINK, DIST, FEED_W, MODE, FLAG, NAME, BROKEN]
    assert space.ports == frozenset({GEO, COM})


@pytest.mark.parametrize(
    ("port", "group", "offset", "code"),
    [
        (552, 0x121301, 0x56, 0x6),  # no object on the SDA port
        (851, 0x4020, 0, 0x6),
        (GEO, 0x121302, 0x56, 0x702),  # channel 2 is not configured
        (GEO, 0x120101, 0x09, 0x702),  # a COM group on the GEO port
        (GEO, 0x121301, 0x57, 0x703),
        (GEO, 0x021301, 0x20017, 0x703),  # alias group known, offset not
        (COM, 0x120101, 0x0A, 0x703),
    ],
)
def test_misses_answer_port_group_or_offset(
    space: AddressSpace, port: int, group: int, offset: int, code: int
) -> None:
    found = space.find(port, group, offset)
    assert isinstance(found, tuple)
    assert found[0] == code
    assert isinstance(found[1], str) and found[1]
    assert space.read(port, group, offset, 8)[0] == code
    assert space.decode_write(port, group, offset, b"\x00" * 8)[0] == code


@pytest.mark.parametrize(
    ("pattern", "expected"),
    [
        ("*", [LINK, DIST, FEED_W, MODE, FLAG, NAME, BROKEN]),
        ("", [LINK, DIST, FEED_W, MODE, FLAG, NAME, BROKEN]),
        ("ch1.ax*", [LINK]),
        ("ch1.ax?.*", [LINK]),
        ("*feed*", [FEED_W]),
        ("*FEED*", [FEED_W]),
        ("CH1.MODE", [MODE]),
        ("ch1.*_w", [FEED_W]),
        ("ch1.[fm]*", [FEED_W, MODE, FLAG]),
        ("ch1", []),  # a glob matches whole names
        ("ch2.*", []),
        ("**ch1.**feed***", [FEED_W]),  # runs of stars are one star
        ("*" * 40 + "q", []),  # many stars: answered (linear), nothing matches
        ("*?*?*?*?*?*?*?*?*?*?*?*?*?*_w", [FEED_W]),
        ("ch1.[!f]*", [LINK, DIST, FEED_W, MODE, NAME, BROKEN]),
    ],
)
def test_match_globs(space: AddressSpace, pattern: str, expected: list[CncObject]) -> None:
    assert space.match(pattern) == expected


@pytest.mark.parametrize("pattern", ["gpch*", "GPCH*", "gpCh?0?.*", "*.COUNT_LOGGED_BLOCKS",
                                     "gpCh[0].*", "*[0]*"])
def test_match_ignores_the_case_of_mixed_case_names(pattern: str) -> None:
    hli = make("gpCh[0].count_logged_blocks", 851, 0x4020, 0, UNS32, Access.READ)
    space = AddressSpace()
    space.add(hli, lambda: 0)
    assert space.match(pattern) == [hli]


# --------------------------------------------------------------------------- building


def test_duplicate_names_are_refused_case_insensitively(space: AddressSpace) -> None:
    twin = make(LINK.name.upper(), GEO, 0x121301, 0x99, UNS16, Access.READ)
    with pytest.raises(ValueError):
        space.add(twin, lambda: 0)


def test_duplicate_addresses_are_refused(space: AddressSpace) -> None:
    twin = make("ch1.other", GEO, 0x121301, 0x56, REAL64, Access.READ)
    with pytest.raises(ValueError):
        space.add(twin, lambda: 0.0)


def test_an_alias_that_collides_is_refused(space: AddressSpace) -> None:
    other = make("ch1.other", GEO, 0x121309, 0x56, REAL64, Access.READ)
    with pytest.raises(ValueError):
        space.add(other, lambda: 0.0, aliases=(0x021301,))


def test_a_refused_add_leaves_the_space_as_it_was(space: AddressSpace) -> None:
    # The object's own address is free; only its alias collides with DIST.
    other = make("ch1.other", GEO, 0x121309, 0x56, REAL64, Access.READ)
    with pytest.raises(ValueError):
        space.add(other, lambda: 0.0, aliases=(0x021301,))
    assert len(space) == 7
    assert space.by_name("ch1.other") is None
    found = space.find(GEO, 0x121309, 0x56)
    assert isinstance(found, tuple), f"refused object left behind at its address: {found}"
    assert found[0] == E.DEVICE_INVALIDGRP
    # and the next object gets the next free handle, findable at its address
    late = make("ch1.late", GEO, 0x121301, 0x60, UNS16, Access.READ)
    entry = space.add(late, lambda: 1)
    assert space.by_handle(entry.handle) is entry
    assert space.find(GEO, 0x121301, 0x60) is entry


def test_readable_objects_need_a_getter_and_writable_ones_a_setter() -> None:
    space = AddressSpace()
    with pytest.raises(ValueError):
        space.add(make("a", COM, 1, 1, UNS16, Access.READ))
    with pytest.raises(ValueError):
        space.add(make("b", COM, 1, 2, UNS16, Access.WRITE))
    with pytest.raises(ValueError):
        space.add(make("c", COM, 1, 3, UNS16, Access.READ_WRITE), read=lambda: 0)
    assert len(space) == 0


# --------------------------------------------------------------------------- read


@pytest.mark.parametrize(
    ("obj", "raw"),
    [
        (LINK, b"\x02\x00"),
        (DIST, struct.pack("<d", 1234.5)),
        (MODE, b"\xfd\xff"),
        (FLAG, b"\x01"),
        (NAME, b"MAIN\x00\x00\x00\x00"),
    ],
    ids=lambda v: v.name if isinstance(v, CncObject) else None,
)
def test_read_gives_the_live_value_as_bytes(
    space: AddressSpace, obj: CncObject, raw: bytes
) -> None:
    assert space.read(obj.port, obj.group, obj.offset, obj.length) == (0, raw)


def test_read_follows_the_state_it_points_at(bound: Space) -> None:
    bound.values[LINK.name] = 3
    assert bound.space.read(GEO, 0x121301, 0x10017, 2) == (0, b"\x03\x00")


def test_read_of_a_write_only_object_is_refused(space: AddressSpace) -> None:
    code, message = space.read(COM, 0x120101, 0x09, 2)
    assert code == E.DEVICE_INVALIDACCESS == 0x704
    assert FEED_W.name in message


@pytest.mark.parametrize("length", [0, 1, 3, 8])
def test_read_with_the_wrong_length_is_refused(space: AddressSpace, length: int) -> None:
    code, message = space.read(GEO, 0x121301, 0x10017, length)
    assert code == E.DEVICE_INVALIDSIZE == 0x705
    assert "UNS16" in message


def test_string_reads_need_the_whole_buffer(space: AddressSpace) -> None:
    assert space.read(COM, 0x120101, 0x52, 5)[0] == 0x705
    assert space.read(COM, 0x120101, 0x52, 8)[0] == 0


def test_a_getter_that_raises_answers_device_error(space: AddressSpace) -> None:
    code, message = space.read(COM, 0x120101, 0x53, 4)
    assert code == E.DEVICE_ERROR == 0x700
    assert BROKEN.name in message


@pytest.mark.parametrize("bad", [70000, -1, "two", None, 1.5], ids=repr)
def test_a_getter_value_the_type_cannot_hold_answers_device_error(bound: Space, bad: Any) -> None:
    bound.values[LINK.name] = bad
    assert bound.space.read(GEO, 0x121301, 0x10017, 2)[0] == 0x700


def test_read_entry(space: AddressSpace) -> None:
    assert AddressSpace.read_entry(space.by_name(MODE.name), 2) == (0, b"\xfd\xff")


# --------------------------------------------------------------------------- decode_write


def test_decode_write(bound: Space) -> None:
    code, entry, value = bound.space.decode_write(COM, 0x120101, 0x09, b"\xe8\x03")
    assert code == 0
    assert entry.obj is FEED_W
    assert value == 1000
    # decoding does not write: applying is the caller's business
    assert bound.written == []
    entry.write(value)
    assert bound.written == [(FEED_W.name, 1000)]


def test_decode_write_of_a_signed_value(space: AddressSpace) -> None:
    assert space.decode_write(COM, 0x120101, 0x50, b"\xfe\xff")[2] == -2


def test_decode_write_to_a_read_only_object_is_refused(space: AddressSpace) -> None:
    code, message, value = space.decode_write(GEO, 0x121301, 0x10017, b"\x01\x00")
    assert code == E.DEVICE_INVALIDACCESS == 0x704
    assert LINK.name in message
    assert value is None


@pytest.mark.parametrize("data", [b"", b"\x01", b"\x01\x00\x00"])
def test_decode_write_of_the_wrong_size_is_refused(space: AddressSpace, data: bytes) -> None:
    code, message, value = space.decode_write(COM, 0x120101, 0x09, data)
    assert code == E.DEVICE_INVALIDSIZE == 0x705
    assert value is None


@pytest.mark.parametrize(("data", "expected"), [(b"\x00", False), (b"\x01", True)])
def test_boolean_writes(space: AddressSpace, data: bytes, expected: bool) -> None:
    code, _, value = space.decode_write(COM, 0x120101, 0x51, data)
    assert code == 0
    assert value is expected


@pytest.mark.parametrize("data", [b"\x02", b"\xff"])
def test_boolean_writes_other_than_zero_or_one_are_invalid_data(
    space: AddressSpace, data: bytes
) -> None:
    code, message, value = space.decode_write(COM, 0x120101, 0x51, data)
    assert code == E.DEVICE_INVALIDDATA == 0x706
    assert value is None


@pytest.mark.parametrize(
    ("data", "expected"),
    [
        (b"SUB", "SUB"),
        (b"SUB\x00", "SUB"),
        (b"", ""),
        (b"ABCDEFG\x00", "ABCDEFG"),
        (b"\x80", "€"),
    ],
)
def test_string_writes_shorter_than_the_buffer_are_padded(
    space: AddressSpace, data: bytes, expected: str
) -> None:
    code, entry, value = space.decode_write(COM, 0x120101, 0x52, data)
    assert code == 0
    assert value == expected
    assert entry.obj.dtype.encode(value) == data.ljust(8, b"\x00")


def test_string_writes_longer_than_the_buffer_are_refused(space: AddressSpace) -> None:
    code, _, value = space.decode_write(COM, 0x120101, 0x52, b"ABCDEFGH\x00")
    assert code == E.DEVICE_INVALIDSIZE == 0x705
    assert value is None


def test_string_writes_cp1252_cannot_decode_are_invalid_data(space: AddressSpace) -> None:
    code, _, value = space.decode_write(COM, 0x120101, 0x52, b"\x81")
    assert code == E.DEVICE_INVALIDDATA == 0x706
    assert value is None


WRITABLE_TYPES = [UNS16, SGN16, UNS32, BOOLEAN, REAL32, REAL64, STRING(8)]


@given(data=st.data())
@pytest.mark.parametrize("dtype", WRITABLE_TYPES, ids=lambda t: t.name)
def test_an_accepted_write_can_be_read_back(dtype: DataType, data: st.DataObject) -> None:
    """Whatever decode_write accepts, the same object can serve on its next read."""
    obj = make("ch1.value", COM, 0x120101, 0x70, dtype, Access.READ_WRITE)
    stored: list[Any] = []
    space = AddressSpace()
    space.add(obj, lambda: stored[-1], stored.append)
    raw = data.draw(st.binary(min_size=0, max_size=dtype.size + 1))
    code, entry, value = space.decode_write(COM, 0x120101, 0x70, raw)
    if code != 0:
        assert code in (E.DEVICE_INVALIDSIZE, E.DEVICE_INVALIDDATA)
        return
    entry.write(value)
    read_code, read_back = space.read(COM, 0x120101, 0x70, dtype.size)
    assert read_code == 0, read_back


def test_a_full_string_buffer_without_terminator_is_refused_or_readable(bound: Space) -> None:
    """8 characters and no NUL in a STRING(8): either refused, or served on the next read."""
    code, entry, value = bound.space.decode_write(COM, 0x120101, 0x52, b"ABCDEFGH")
    if code == 0:
        bound.values[NAME.name] = value
        assert bound.space.read(COM, 0x120101, 0x52, 8)[0] == 0
    else:
        assert code in (E.DEVICE_INVALIDSIZE, E.DEVICE_INVALIDDATA)


# --------------------------------------------------------------------------- directory


DIRECTORY_OBJECTS = [
    make("ch1.mc_command_execution_mode_w", COM, 0x120101, 0x3F, UNS32, Access.WRITE),
    make("ch1.mc_active_feed_override_r", COM, 0x120101, 0x0C, UNS16, Access.READ),
    make("ch1.dist_prog_start", GEO, 0x121301, 0x56, REAL64, Access.READ_WRITE),
    make("ch1.program_name", COM, 0x120101, 0x52, STRING(84), Access.READ),
]


def _descriptor(raw: bytes) -> tuple:
    ordinal, size, writable, pad, group, offset = struct.unpack_from("<IIHHII", raw)
    name = raw[20:52]
    iec = raw[52:84]
    return ordinal, size, writable, pad, group, offset, name, iec


def test_directory_count_at_offset_zero() -> None:
    directory = ObjectDirectory(DIRECTORY_OBJECTS)
    assert len(directory) == 4
    assert directory.read(0, 4) == (0, b"\x04\x00\x00\x00")


def test_empty_directory() -> None:
    directory = ObjectDirectory([])
    assert directory.read(0, 4) == (0, b"\x00\x00\x00\x00")
    assert directory.read(1, DESCRIPTOR_SIZE)[0] == 0x703


def test_descriptor_layout() -> None:
    code, raw = ObjectDirectory(DIRECTORY_OBJECTS).read(1, 84)
    assert code == 0
    assert DESCRIPTOR_SIZE == 84 == len(raw)
    assert raw[:20] == (
        b"\x01\x00\x00\x00"  # id 1
        b"\x04\x00\x00\x00"  # 4 bytes
        b"\x01\x00"  # writable
        b"\x00\x00"  # padding
        b"\x01\x01\x12\x00"  # group 0x120101
        b"\x3f\x00\x00\x00"  # offset 0x3f
    )
    assert raw[20:52] == b"mc_command_execution_mode_w".ljust(32, b"\x00")
    assert raw[52:84] == b"UDINT".ljust(32, b"\x00")


@pytest.mark.parametrize(
    ("ordinal", "expected"),
    [
        (2, (2, 2, 0, 0, 0x120101, 0x0C, b"mc_active_feed_override_r", b"UINT")),
        (3, (3, 8, 1, 0, 0x121301, 0x56, b"dist_prog_start", b"LREAL")),
        (4, (4, 84, 0, 0, 0x120101, 0x52, b"program_name", b"STRING")),
    ],
)
def test_descriptors_of_each_object(ordinal: int, expected: tuple) -> None:
    code, raw = ObjectDirectory(DIRECTORY_OBJECTS).read(ordinal, 84)
    assert code == 0
    *head, name, iec = _descriptor(raw)
    assert (*head, name.rstrip(b"\x00"), iec.rstrip(b"\x00")) == expected
    assert name.endswith(b"\x00") and iec.endswith(b"\x00")


def test_multiples_of_84_give_consecutive_descriptors() -> None:
    directory = ObjectDirectory(DIRECTORY_OBJECTS)
    code, raw = directory.read(2, 3 * 84)
    assert code == 0
    assert len(raw) == 3 * 84
    singles = [directory.read(n, 84)[1] for n in (1, 2, 3, 4)]
    assert [raw[k * 84 : (k + 1) * 84] for k in range(3)] == singles[1:]
    assert [_descriptor(raw[k * 84 :])[0] for k in range(3)] == [2, 3, 4]
    assert directory.read(1, 4 * 84) == (0, b"".join(singles))


def test_long_element_names_are_cut_to_fit_with_their_terminator() -> None:
    long = make("ch1.x", COM, 0x120101, 1, UNS16, Access.READ, element="e" * 40)
    raw = encode_descriptor(7, long)
    assert len(raw) == 84
    assert raw[20:52] == b"e" * 31 + b"\x00"
    assert struct.unpack_from("<I", raw)[0] == 7


@pytest.mark.parametrize("offset", [5, 100, 2**32 - 1])
def test_directory_offset_past_the_last_object(offset: int) -> None:
    assert ObjectDirectory(DIRECTORY_OBJECTS).read(offset, 84)[0] == E.DEVICE_INVALIDOFFSET == 0x703


@pytest.mark.parametrize(
    ("offset", "length"),
    [(0, 0), (0, 2), (0, 8), (0, 84), (1, 0), (1, 4), (1, 83), (1, 85), (1, 168 + 1),
     (3, 3 * 84), (4, 2 * 84), (1, 5 * 84)],
)
def test_directory_bad_lengths(offset: int, length: int) -> None:
    code = ObjectDirectory(DIRECTORY_OBJECTS).read(offset, length)[0]
    assert code == E.DEVICE_INVALIDSIZE == 0x705


def test_directory_served_as_a_group(space: AddressSpace) -> None:
    directory = ObjectDirectory(DIRECTORY_OBJECTS)
    space.add_group(COM, 0x130101, directory)
    assert space.read(COM, 0x130101, 0, 4) == (0, b"\x04\x00\x00\x00")
    assert space.read(COM, 0x130101, 2, 84) == directory.read(2, 84)
    assert space.read(COM, 0x130101, 9, 84)[0] == 0x703
    # the group is read-only: writes are refused with 0x704, not "unknown offset"
    assert space.decode_write(COM, 0x130101, 1, b"\x00" * 84)[0] == 0x704
    # a handler group on a new port makes that port known
    space.add_group(552, 0x130100, ObjectDirectory([]))
    assert 552 in space.ports
    assert space.read(552, 0x130100, 0, 4) == (0, b"\x00\x00\x00\x00")
