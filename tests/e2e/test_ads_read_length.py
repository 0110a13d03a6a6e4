"""The read length of ADS is a buffer size, as TwinCAT answers it (issue 26, item 1).

A TwinCAT runtime answers a read with the data's real length whenever the read length
is at least that large; clients that do not know the size send 0xFFFFFFFF (jisotalo's
ads-client for symbol info, data type info, handles and values by name), or 0xFFFF per
item of a sum command. A buffer too small still gets 0x705; an unknown name 0x710.
Each test sends the frames byte by byte with the raw client of ``test_ads_raw``.
"""

from __future__ import annotations

import struct

import pytest

from tests.support.ads_answers import ANY, INVALIDSIZE, OK, PER_ITEM, SYMBOLNOTFOUND, answer
from tests.support.ads_raw import (
    ADD_NOTIFICATION,
    CH1_COM,
    COM,
    DELETE_NOTIFICATION,
    READ,
    READ_WRITE,
    RawAds,
    add_notification,
    read,
    read_write,
)

UINT_NAME = b"ch1.mc_command_feed_override_r\x00"  # UINT, 1000 at start
LREAL_NAME = b"gpCh[0].contour_lookahead.request.length\x00"  # LREAL, 0.0 at start
STRING_NAME = b"ch1.mc_active_program_name_r\x00"  # STRING(84)
UNKNOWN = b"gpCh[0].no_such_member\x00"






@pytest.mark.parametrize("group, size", [(0xF009, None), (0xF007, 12)])
def test_symbol_info_by_name_with_an_unknown_size(ads: RawAds, group: int, size: int | None) -> None:
    result, data = answer(ads, READ_WRITE, read_write(group, 0, ANY, UINT_NAME))
    assert result == OK
    if size is None:  # an AdsSymbolEntry: its entry length is its first u32
        assert struct.unpack_from("<I", data)[0] == len(data)
        assert b"ch1.mc_command_feed_override_r\x00UINT\x00" in data
    else:
        assert len(data) == size and struct.unpack_from("<I", data, 8)[0] == 2
    assert answer(ads, READ_WRITE, read_write(group, 0, len(data) - 1, UINT_NAME)) == (
        INVALIDSIZE, b"")
    assert answer(ads, READ_WRITE, read_write(group, 0, ANY, UNKNOWN)) == (SYMBOLNOTFOUND, b"")


def test_data_type_by_name_with_an_unknown_size(ads: RawAds) -> None:
    result, data = answer(ads, READ_WRITE, read_write(0xF011, 0, ANY, b"LREAL\x00"))
    assert result == OK and struct.unpack_from("<I", data)[0] == len(data)
    assert struct.unpack_from("<I", data, 16)[0] == 8  # size
    assert answer(ads, READ_WRITE, read_write(0xF011, 0, ANY, b"ST_None\x00")) == (
        SYMBOLNOTFOUND, b"")


def test_value_by_name_answers_the_values_length(ads: RawAds) -> None:
    assert answer(ads, READ_WRITE, read_write(0xF004, 0, ANY, UINT_NAME)) == (
        OK, struct.pack("<H", 1000))
    assert answer(ads, READ_WRITE, read_write(0xF004, 0, 100, LREAL_NAME)) == (
        OK, struct.pack("<d", 0.0))
    assert answer(ads, READ_WRITE, read_write(0xF004, 0, 1, UINT_NAME)) == (INVALIDSIZE, b"")
    assert answer(ads, READ_WRITE, read_write(0xF004, 0, ANY, UNKNOWN)) == (SYMBOLNOTFOUND, b"")
    result, text = answer(ads, READ_WRITE, read_write(0xF004, 0, ANY, STRING_NAME))
    assert result == OK and len(text) == 84


def test_value_by_handle_answers_the_values_length(ads: RawAds) -> None:
    result, handle = answer(ads, READ_WRITE, read_write(0xF003, 0, 4, UINT_NAME))
    assert result == OK
    offset = struct.unpack("<I", handle)[0]
    assert answer(ads, READ, read(0xF005, offset, ANY)) == (OK, struct.pack("<H", 1000))
    assert answer(ads, READ, read(0xF005, offset, 1)) == (INVALIDSIZE, b"")


def test_a_notification_by_handle_with_an_unknown_size_sends_the_value(ads: RawAds) -> None:
    _, handle = answer(ads, READ_WRITE, read_write(0xF003, 0, 4, UINT_NAME))
    offset = struct.unpack("<I", handle)[0]
    got = ads.call(ADD_NOTIFICATION, add_notification(0xF005, offset, ANY, 4, 10_000))
    assert got.result == OK
    notification_handle = struct.unpack_from("<I", got.data, 4)[0]
    try:
        sample = ads.notification().data
        # length, stamps, then one stamp: FILETIME, samples, then handle, size, data
        handle, size = struct.unpack_from("<II", sample, 20)
        assert (handle, size) == (notification_handle, 2)
        assert sample[28:30] == struct.pack("<H", 1000)
    finally:
        ads.call(DELETE_NOTIFICATION, struct.pack("<I", notification_handle))


def test_sum_read_write_items_answer_their_own_lengths(ads: RawAds) -> None:
    """0xF082 with 0xFFFFFFFF in all and 0xFFFF per item, as ads-client sends it."""
    names = [UINT_NAME, UNKNOWN, LREAL_NAME]
    head = b"".join(struct.pack("<IIII", 0xF004, 0, PER_ITEM, len(n)) for n in names)
    result, body = answer(ads, READ_WRITE, read_write(0xF082, 3, ANY, head + b"".join(names)))
    assert result == OK
    assert struct.unpack_from("<6I", body) == (OK, 2, SYMBOLNOTFOUND, 0, OK, 8)
    assert body[24:] == struct.pack("<Hd", 1000, 0.0)


def test_a_sum_read_write_reply_longer_than_its_buffer_is_0x705(ads: RawAds) -> None:
    head = struct.pack("<IIII", 0xF004, 0, PER_ITEM, len(LREAL_NAME))
    assert answer(ads, READ_WRITE, read_write(0xF082, 1, 8 + 7, head + LREAL_NAME)) == (
        INVALIDSIZE, b"")


@pytest.mark.parametrize("offset, expected", [(0, b"\x05\x00\x00\x00"), (2, b"\x00\x00")])
def test_device_data_answers_what_follows_the_offset(ads: RawAds, offset: int, expected: bytes) -> None:
    assert answer(ads, READ, read(0xF100, offset, ANY)) == (OK, expected)


def test_symbol_services_read_with_an_unknown_size(ads: RawAds) -> None:
    assert answer(ads, READ, read(0xF008, 0, ANY))[1] != b""
    result, info = answer(ads, READ, read(0xF00F, 0, ANY))
    assert result == OK and len(info) == 64
    symbol_bytes = struct.unpack_from("<I", info, 4)[0]
    result, upload = answer(ads, READ, read(0xF00B, 0, ANY))
    assert result == OK and len(upload) == symbol_bytes


def test_read_write_without_data_on_an_object_reads_it(ads: RawAds) -> None:
    """ch1.mc_command_feed_override_r at its COM address."""
    assert answer(ads, READ_WRITE, read_write(CH1_COM, 0xA, ANY, b""), port=COM) == (
        OK, struct.pack("<H", 1000))
    assert answer(ads, READ_WRITE, read_write(CH1_COM, 0xA, 1, b""), port=COM) == (
        INVALIDSIZE, b"")
