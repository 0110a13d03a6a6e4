"""Sum commands (protocol/sum.py): the payloads of 0xF080, 0xF081 and 0xF082.

The byte layouts are TwinCAT's (little-endian UNS32 headers, then data), so they are
checked against hand-built bytes as well as round trips; a payload whose length does
not match its item count or its headers must raise ``ValueError`` (the server's 0x705).
"""

from __future__ import annotations

import struct

import pytest
from hypothesis import given
from hypothesis import strategies as st

from cnc_objects.protocol.sum import (
    SumItem,
    decode_codes,
    decode_sum_read,
    decode_sum_read_reply,
    decode_sum_read_write,
    decode_sum_read_write_reply,
    decode_sum_write,
    encode_codes,
    encode_sum_read,
    encode_sum_read_addresses,
    encode_sum_read_reply,
    encode_sum_read_write,
    encode_sum_read_write_reply,
    encode_sum_write,
)

u32 = st.integers(min_value=0, max_value=0xFFFF_FFFF)


def le(*values: int) -> bytes:
    """Little-endian UNS32s."""
    return struct.pack(f"<{len(values)}I", *values)


# --------------------------------------------------------------------------- sum read


def test_sum_read_request_layout() -> None:
    items = [SumItem(0x121302, 0x30017, read_length=2), SumItem(0x121301, 0x56, read_length=8)]
    payload, read_length = encode_sum_read(items)
    assert payload == le(0x121302, 0x30017, 2, 0x121301, 0x56, 8)
    assert read_length == 2 * 4 + 2 + 8  # N codes, then the data


def test_sum_read_request_round_trip() -> None:
    items = [SumItem(1, 2, 3), SumItem(4, 5, 6), SumItem(0xFFFF_FFFF, 0, 0)]
    payload, _ = encode_sum_read(items)
    assert decode_sum_read(3, payload) == items


def test_empty_sum_read() -> None:
    assert encode_sum_read([]) == (b"", 0)
    assert decode_sum_read(0, b"") == []


@pytest.mark.parametrize(("count", "size"), [(2, 23), (2, 25), (1, 0), (0, 12), (3, 24)])
def test_sum_read_request_of_wrong_length_is_refused(count: int, size: int) -> None:
    with pytest.raises(ValueError):
        decode_sum_read(count, b"\x00" * size)


def test_sum_read_reply_layout() -> None:
    reply = encode_sum_read_reply([(0, b"\x34\x12"), (0x703, b"\x00\x00\x00\x00")])
    assert reply == le(0, 0x703) + b"\x34\x12" + b"\x00\x00\x00\x00"


def test_sum_read_reply_round_trip() -> None:
    results = [(0, b"\x01\x02"), (0x702, b"\x00" * 8), (0, b"")]
    assert decode_sum_read_reply([2, 8, 0], encode_sum_read_reply(results)) == results


def test_sum_read_reply_shorter_than_its_items_is_refused() -> None:
    reply = encode_sum_read_reply([(0, b"\x01\x02"), (0, b"\x03\x04")])
    with pytest.raises(ValueError):
        decode_sum_read_reply([2, 2], reply[:-1])
    with pytest.raises(ValueError):
        decode_sum_read_reply([2, 2, 4], reply)


@given(st.lists(st.tuples(u32, u32, st.integers(min_value=0, max_value=64)), max_size=10))
def test_sum_read_request_property(triples: list[tuple[int, int, int]]) -> None:
    items = [SumItem(g, o, n) for g, o, n in triples]
    payload, read_length = encode_sum_read(items)
    assert len(payload) == 12 * len(items)
    assert read_length == 4 * len(items) + sum(n for _, _, n in triples)
    assert decode_sum_read(len(items), payload) == items


@given(st.lists(st.tuples(u32, st.binary(max_size=16)), max_size=10))
def test_sum_read_reply_property(results: list[tuple[int, bytes]]) -> None:
    lengths = [len(d) for _, d in results]
    assert decode_sum_read_reply(lengths, encode_sum_read_reply(results)) == results


# --------------------------------------------------------------------------- sum write


def test_sum_write_request_layout() -> None:
    items = [
        SumItem(0x120101, 0x09, data=b"\xe8\x03"),
        SumItem(0x120101, 0x3F, data=b"\x01\x00\x00\x00"),
    ]
    payload, read_length = encode_sum_write(items)
    assert payload == le(0x120101, 0x09, 2, 0x120101, 0x3F, 4) + b"\xe8\x03" + b"\x01\x00\x00\x00"
    assert read_length == 8  # one code per item


def test_sum_write_request_round_trip() -> None:
    items = [SumItem(1, 2, 0, b"ab"), SumItem(3, 4, 0, b""), SumItem(5, 6, 0, b"xyz")]
    payload, _ = encode_sum_write(items)
    assert decode_sum_write(3, payload) == items


@pytest.mark.parametrize(
    "payload",
    [
        le(1, 2, 2) + b"\x01",  # data shorter than its header says
        le(1, 2, 2) + b"\x01\x02\x03",  # data longer than its header says
        le(1, 2, 2),  # no data at all
        le(1, 2),  # header cut short
        b"",
    ],
    ids=["short-data", "long-data", "no-data", "short-header", "empty"],
)
def test_sum_write_request_of_wrong_length_is_refused(payload: bytes) -> None:
    with pytest.raises(ValueError):
        decode_sum_write(1, payload)


def test_sum_write_with_fewer_items_than_the_count_is_refused() -> None:
    payload, _ = encode_sum_write([SumItem(1, 2, 0, b"\x01\x02\x03\x04")])
    # Read as two items, the first item's data is taken as the second header: too short.
    with pytest.raises(ValueError):
        decode_sum_write(2, payload)


def test_sum_write_reply_is_one_code_per_item() -> None:
    assert encode_codes([0, 0x704, 0x705]) == le(0, 0x704, 0x705)
    assert decode_codes(3, le(0, 0x704, 0x705)) == [0, 0x704, 0x705]


def test_sum_write_reply_shorter_than_its_codes_is_refused() -> None:
    with pytest.raises(ValueError):
        decode_codes(3, le(0, 0x704))
    with pytest.raises(ValueError):
        decode_codes(1, b"\x00\x00\x00")


@given(st.lists(st.tuples(u32, u32, st.binary(max_size=16)), max_size=10))
def test_sum_write_request_property(triples: list[tuple[int, int, bytes]]) -> None:
    items = [SumItem(g, o, 0, d) for g, o, d in triples]
    payload, read_length = encode_sum_write(items)
    assert read_length == 4 * len(items)
    assert decode_sum_write(len(items), payload) == items


@given(st.lists(u32, max_size=20))
def test_codes_property(codes: list[int]) -> None:
    assert decode_codes(len(codes), encode_codes(codes)) == codes


# --------------------------------------------------------------------------- sum read-write


def test_sum_read_write_request_layout() -> None:
    items = [SumItem(0xF003, 0, read_length=4, data=b"ch1.x"), SumItem(7, 8, 2, b"")]
    payload, read_length = encode_sum_read_write(items)
    assert payload == le(0xF003, 0, 4, 5, 7, 8, 2, 0) + b"ch1.x"
    assert read_length == 2 * 8 + 4 + 2  # N x (code, length), then the data


def test_sum_read_write_request_round_trip() -> None:
    items = [SumItem(1, 2, 3, b"abc"), SumItem(4, 5, 0, b""), SumItem(6, 7, 8, b"\x00")]
    payload, _ = encode_sum_read_write(items)
    assert decode_sum_read_write(3, payload) == items


@pytest.mark.parametrize(
    "payload",
    [
        le(1, 2, 4, 2) + b"\x01",
        le(1, 2, 4, 2) + b"\x01\x02\x03",
        le(1, 2, 4),
        b"",
    ],
    ids=["short-data", "long-data", "short-header", "empty"],
)
def test_sum_read_write_request_of_wrong_length_is_refused(payload: bytes) -> None:
    with pytest.raises(ValueError):
        decode_sum_read_write(1, payload)


def test_sum_read_write_reply_layout() -> None:
    reply = encode_sum_read_write_reply([(0, b"\x05\x00\x00\x00"), (0x710, b"")])
    assert reply == le(0, 4, 0x710, 0) + b"\x05\x00\x00\x00"


def test_sum_read_write_reply_round_trip() -> None:
    results = [(0, b"\x05\x00\x00\x00"), (0x710, b""), (0, b"ab")]
    assert decode_sum_read_write_reply(3, encode_sum_read_write_reply(results)) == results


def test_sum_read_write_reply_shorter_than_its_headers_is_refused() -> None:
    with pytest.raises(ValueError):
        decode_sum_read_write_reply(2, le(0, 0, 0))


def test_sum_read_write_reply_with_less_data_than_its_headers_say_is_refused() -> None:
    # The header promises 4 bytes; only 2 follow. Handing back 2 bytes as if they were
    # the item's value would hide a truncated reply.
    with pytest.raises(ValueError):
        decode_sum_read_write_reply(1, le(0, 4) + b"\x01\x02")


@given(st.lists(st.tuples(u32, u32, st.integers(0, 64), st.binary(max_size=16)), max_size=10))
def test_sum_read_write_request_property(quads: list[tuple[int, int, int, bytes]]) -> None:
    items = [SumItem(g, o, n, d) for g, o, n, d in quads]
    payload, read_length = encode_sum_read_write(items)
    assert read_length == 8 * len(items) + sum(n for _, _, n, _ in quads)
    assert decode_sum_read_write(len(items), payload) == items


@given(st.lists(st.tuples(u32, st.binary(max_size=16)), max_size=10))
def test_sum_read_write_reply_property(results: list[tuple[int, bytes]]) -> None:
    reply = encode_sum_read_write_reply(results)
    assert decode_sum_read_write_reply(len(results), reply) == results


def test_sum_read_of_addresses_is_the_sum_read_of_their_items() -> None:
    addresses = [(0x121301, 0x10018, 4), (0x120101, 0x0C, 2), (0x4020, 0x10120, 300)]
    assert encode_sum_read_addresses(addresses) == encode_sum_read(
        [SumItem(*a) for a in addresses])
