"""Handle by name (0xF003) as TwinCAT 3 answers it, and paths with ``^`` (issue 26, item 2).

TwinCAT 3 answers a handle request whose read length is over 4 with the handle, the
symbol's size, a type decoration and the type name; jisotalo's ads-client asks that way
(0xFFFFFFFF, or 0xFFFF per item of a sum read-write) and reads every field. pyads and
AdsLib ask with 4 and get the handle alone. ISG's HLI documentation writes paths through
the pointers (``gpCh[0]^.contour_lookahead``): every by-name service accepts them.
"""

from __future__ import annotations

import struct

import pytest

from tests.support.ads_answers import ANY, INVALIDSIZE, OK, PER_ITEM, SYMBOLNOTFOUND, answer
from tests.support.ads_raw import READ, READ_WRITE, RawAds, read, read_write

LENGTH = b"gpCh[0].contour_lookahead.request.length"  # LREAL, read-write
LENGTH_DEREF = b"gpCh[0]^.contour_lookahead.request.length"
OVERRIDE = b"ch1.mc_command_feed_override_r"  # UINT, 1000


def extended(data: bytes) -> tuple[int, int, int, str]:
    """handle, size, type decoration, type name, read as ads-client reads them."""
    handle, size, decoration, length = struct.unpack_from("<IIIH", data)
    assert data[14 + length] == 0, "the type name ends with a NUL"
    return handle, size, decoration, data[14 : 14 + length].decode()




def test_a_large_buffer_gets_handle_size_and_type(ads: RawAds) -> None:
    result, data = answer(ads, READ_WRITE, read_write(0xF003, 0, ANY, OVERRIDE + b"\x00"))
    assert result == OK and len(data) == 14 + len("UINT") + 1
    handle, size, decoration, type_name = extended(data)
    assert (size, decoration, type_name) == (2, 0, "UINT")
    assert answer(ads, READ, read(0xF005, handle, size)) == (OK, struct.pack("<H", 1000))


def test_a_four_byte_buffer_gets_the_handle_alone(ads: RawAds) -> None:
    _, data = answer(ads, READ_WRITE, read_write(0xF003, 0, ANY, OVERRIDE + b"\x00"))
    handle = struct.unpack_from("<I", data)[0]
    for length in (4, 10):  # 10: not room for the extended answer
        assert answer(ads, READ_WRITE, read_write(0xF003, 0, length, OVERRIDE + b"\x00")) == (
            OK, struct.pack("<I", handle))
    assert answer(ads, READ_WRITE, read_write(0xF003, 0, 3, OVERRIDE + b"\x00")) == (
        INVALIDSIZE, b"")
    assert answer(ads, READ_WRITE, read_write(0xF003, 0, ANY, b"no.such\x00")) == (
        SYMBOLNOTFOUND, b"")


def test_handles_in_a_sum_read_write_are_extended_per_item(ads: RawAds) -> None:
    names = [OVERRIDE + b"\x00", b"no.such\x00", LENGTH + b"\x00"]
    head = b"".join(struct.pack("<IIII", 0xF003, 0, PER_ITEM, len(n)) for n in names)
    result, body = answer(ads, READ_WRITE, read_write(0xF082, 3, ANY, head + b"".join(names)))
    assert result == OK
    codes_lengths = struct.unpack_from("<6I", body)
    assert codes_lengths[0::2] == (OK, SYMBOLNOTFOUND, OK)
    first_length, third_length = codes_lengths[1], codes_lengths[5]
    first = extended(body[24 : 24 + first_length])
    third = extended(body[24 + first_length : 24 + first_length + third_length])
    assert (first[1], first[3]) == (2, "UINT") and (third[1], third[3]) == (8, "LREAL")


@pytest.mark.parametrize("group, read_length", [
    (0xF003, 4), (0xF004, 8), (0xF007, 12), (0xF009, ANY),
])
def test_a_path_with_dereferences_names_the_same_symbol(
    ads: RawAds, group: int, read_length: int,
) -> None:
    plain = answer(ads, READ_WRITE, read_write(group, 0, read_length, LENGTH + b"\x00"))
    through = answer(ads, READ_WRITE, read_write(group, 0, read_length, LENGTH_DEREF + b"\x00"))
    assert plain[0] == OK and through == plain
