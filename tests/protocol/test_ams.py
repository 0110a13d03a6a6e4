"""AMS/TCP framing, the AMS header and the ADS command payloads (protocol/ams.py,
protocol/ads_commands.py).

Layouts are checked against bytes built by hand with ``struct`` from the Beckhoff
specification, as well as by round trips; the stream parser is fed the same frames cut
at every position and in random chunks, and must give the same frames every time.
"""

from __future__ import annotations

import struct

import pytest
from hypothesis import given
from hypothesis import strategies as st

from cnc_objects.protocol import ads_commands as cmd
from cnc_objects.protocol.ams import (
    AmsFrame,
    AmsHeader,
    AmsStreamParser,
    FrameProblem,
    RouterFrame,
    SkippedFrame,
    StreamItem,
    encode_frame,
    encode_reply_frame,
    format_net_id,
    parse_net_id,
)
from cnc_objects.protocol.ams_router import (
    decode_port,
    describe,
    encode_local_net_id_reply,
    encode_port_connect_reply,
)
from cnc_objects.protocol.errors import ProtocolError
from cnc_objects.protocol.frames import (
    DeleteNotificationRequest,
    ReadDeviceInfoRequest,
    ReadRequest,
    ReadStateRequest,
    ReadWriteRequest,
    WriteControlRequest,
    WriteRequest,
)

u16 = st.integers(min_value=0, max_value=0xFFFF)
u32 = st.integers(min_value=0, max_value=0xFFFF_FFFF)
net_ids = st.binary(min_size=6, max_size=6)
payloads = st.binary(max_size=300)

CLIENT = bytes([10, 1, 2, 3, 1, 1])
SERVER = bytes([127, 0, 0, 1, 1, 1])


def request_frame(command: int, data: bytes, invoke_id: int = 7, port: int = 851) -> bytes:
    """A request frame built by hand from the specification's table."""
    header = struct.pack("<6sH6sHHHIII", SERVER, port, CLIENT, 32905, command, 0x0004,
                         len(data), 0, invoke_id)
    return struct.pack("<HI", 0, 32 + len(data)) + header + data


# --------------------------------------------------------------------------- net ids


@given(net_ids)
def test_net_id_text_round_trip(raw: bytes) -> None:
    assert parse_net_id(format_net_id(raw)) == raw


def test_net_id_text() -> None:
    assert parse_net_id("127.0.0.1.1.1") == bytes([127, 0, 0, 1, 1, 1])
    assert format_net_id(bytes([192, 168, 0, 7, 1, 1])) == "192.168.0.7.1.1"


@pytest.mark.parametrize("text", ["", "1.2.3.4.5", "1.2.3.4.5.6.7", "1.2.3.4.5.256",
                                  "a.b.c.d.e.f", "1.2.3.4.5.-1", "1..3.4.5.6"])
def test_bad_net_ids_are_refused(text: str) -> None:
    with pytest.raises(ValueError, match="AMS Net ID"):
        parse_net_id(text)


# --------------------------------------------------------------------------- header


@given(st.tuples(net_ids, u16, net_ids, u16, u16, u16, u32, u32, u32))
def test_header_round_trip(fields: tuple) -> None:
    header = AmsHeader(*fields)
    raw = header.encode()
    assert len(raw) == 32
    assert AmsHeader.decode(raw) == header
    assert raw == struct.pack("<6sH6sHHHIII", *fields)


def test_frame_layout_follows_the_specification() -> None:
    raw = encode_frame(SERVER, 851, CLIENT, 30000, 2, 0x0004, 0x01020304, b"\xaa\xbb")
    assert raw[:6] == struct.pack("<HI", 0, 34)  # reserved, length after these 6 bytes
    assert raw[6:12] == SERVER and raw[12:14] == struct.pack("<H", 851)
    assert raw[14:20] == CLIENT and raw[20:22] == struct.pack("<H", 30000)
    assert raw[22:24] == b"\x02\x00"  # command id
    assert raw[24:26] == b"\x04\x00"  # state flags: request
    assert raw[26:30] == struct.pack("<I", 2)  # data length
    assert raw[30:34] == bytes(4)  # error code
    assert raw[34:38] == b"\x04\x03\x02\x01"  # invoke id
    assert raw[38:] == b"\xaa\xbb"


def test_reply_frame_swaps_addresses_and_keeps_the_invoke_id() -> None:
    request = AmsHeader(SERVER, 553, CLIENT, 30001, 4, 0x0004, 0, 0, 99)
    reply = encode_reply_frame(request, b"", 0x6)
    header = AmsHeader.decode(reply, 6)
    assert (header.target_net_id, header.target_port) == (CLIENT, 30001)
    assert (header.source_net_id, header.source_port) == (SERVER, 553)
    assert header.command_id == 4 and header.invoke_id == 99
    assert header.state_flags == 0x0005 and header.is_response
    assert header.error_code == 0x6 and header.data_length == 0 and len(reply) == 38


# --------------------------------------------------------------------------- stream


def frames_of(items: list[StreamItem]) -> list[tuple[int, bytes]]:
    """(invoke id, data) of the frames; fails on a SkippedFrame."""
    assert all(isinstance(i, AmsFrame) for i in items), items
    return [(i.header.invoke_id, i.data) for i in items]  # type: ignore[union-attr]


def test_one_frame_in_one_segment() -> None:
    items = AmsStreamParser().feed(request_frame(2, cmd.encode_read_request(1, 2, 4)))
    assert len(items) == 1
    frame = items[0]
    assert isinstance(frame, AmsFrame)
    assert frame.header.target_port == 851 and frame.header.source_net_id == CLIENT
    assert frame.data == struct.pack("<III", 1, 2, 4)


def test_a_frame_split_at_every_position() -> None:
    raw = request_frame(3, cmd.encode_write_request(5, 6, b"hello"), invoke_id=11)
    for cut in range(1, len(raw)):
        parser = AmsStreamParser()
        assert parser.feed(raw[:cut]) == []
        assert parser.buffered == cut
        assert frames_of(parser.feed(raw[cut:])) == [(11, raw[38:])]
        assert parser.buffered == 0


def test_a_frame_fed_byte_by_byte() -> None:
    raw = request_frame(9, cmd.encode_read_write_request(0xF003, 0, 4, b"name\x00"))
    parser = AmsStreamParser()
    got = [item for k in range(len(raw)) for item in parser.feed(raw[k:k + 1])]
    assert frames_of(got) == [(7, raw[38:])]


def test_several_frames_in_one_segment() -> None:
    raws = [request_frame(2, cmd.encode_read_request(1, k, 4), invoke_id=k) for k in (1, 2, 3)]
    assert [i for i, _ in frames_of(AmsStreamParser().feed(b"".join(raws)))] == [1, 2, 3]


@given(st.lists(st.tuples(u32, payloads), min_size=1, max_size=8), st.data())
def test_any_chunking_gives_the_same_frames(frames: list[tuple[int, bytes]], data) -> None:
    stream = b"".join(request_frame(1, body, invoke_id=i) for i, body in frames)
    cuts = sorted(data.draw(st.lists(st.integers(0, len(stream)), max_size=12)))
    parser = AmsStreamParser()
    got = []
    for start, stop in zip([0, *cuts], [*cuts, len(stream)]):
        got += parser.feed(stream[start:stop])
    assert frames_of(got) == frames


def test_a_frame_over_the_maximum_ends_the_stream() -> None:
    parser = AmsStreamParser(max_frame_bytes=100)
    ok = request_frame(2, cmd.encode_read_request(1, 2, 4))
    # Only the 6-byte AMS/TCP header of the long frame has arrived: that is enough.
    items = parser.feed(ok + struct.pack("<HI", 0, 101))
    assert isinstance(items[0], AmsFrame)
    assert isinstance(items[1], SkippedFrame) and items[1].problem is FrameProblem.TOO_LONG
    assert items[1].length == 101 and "exceeds" in str(items[1])
    assert parser.closed
    assert parser.feed(ok) == []


def test_the_default_maximum_is_one_mebibyte() -> None:
    parser = AmsStreamParser()
    assert parser.feed(struct.pack("<HI", 0, 1 << 20))[:1] == []  # allowed, incomplete
    parser = AmsStreamParser()
    (error,) = parser.feed(struct.pack("<HI", 0, (1 << 20) + 1))
    assert isinstance(error, SkippedFrame) and error.problem is FrameProblem.TOO_LONG


def test_a_truncated_header_is_reported_and_the_stream_goes_on() -> None:
    short = struct.pack("<HI", 0, 20) + bytes(20)  # no room for the 32-byte AMS header
    after = request_frame(4, b"", invoke_id=5)
    items = AmsStreamParser().feed(short + after)
    assert isinstance(items[0], SkippedFrame)
    assert items[0].problem is FrameProblem.TRUNCATED_HEADER and items[0].header is None
    assert frames_of(items[1:]) == [(5, b"")]


def test_a_data_length_that_does_not_match_is_reported_with_the_header() -> None:
    raw = bytearray(request_frame(2, cmd.encode_read_request(1, 2, 4), invoke_id=9))
    raw[26:30] = struct.pack("<I", 11)  # the AMS header says 11 bytes of data; 12 follow
    after = request_frame(4, b"", invoke_id=10)
    items = AmsStreamParser().feed(bytes(raw) + after)
    error = items[0]
    assert isinstance(error, SkippedFrame) and error.problem is FrameProblem.LENGTH_MISMATCH
    assert error.header is not None and error.header.invoke_id == 9
    assert frames_of(items[1:]) == [(10, b"")]


def test_a_frame_for_the_router_is_its_command_and_data() -> None:
    router_frame = struct.pack("<HI", 0x1000, 2) + b"\x01\x02"  # AMS/TCP port connect
    items = AmsStreamParser().feed(router_frame + request_frame(4, b"", invoke_id=3))
    assert items[0] == RouterFrame(0x1000, b"\x01\x02")  # no AMS header
    assert frames_of(items[1:]) == [(3, b"")]
    short = struct.pack("<HI", 0x1002, 0)  # no data at all
    assert AmsStreamParser().feed(short) == [RouterFrame(0x1002, b"")]


def test_router_replies_as_ads_client_and_ads_rs_read_them() -> None:
    net_id = parse_net_id("127.0.0.1.1.1")
    reply = encode_port_connect_reply(net_id, 32768)
    # ads-rs checks the first 6 bytes literally: [0, 16, 8, 0, 0, 0]
    assert reply == bytes([0, 16, 8, 0, 0, 0, 127, 0, 0, 1, 1, 1, 0, 0x80])
    assert encode_local_net_id_reply(net_id) == struct.pack("<HI", 0x1002, 6) + net_id
    assert [decode_port(d) for d in (b"\x00\x80", b"", b"\x01", b"\x00\x00\x00")] == [
        32768, 0, None, None]
    assert describe(0x1000) == "0x1000 (port connect)" and describe(0x2345) == "0x2345"


# --------------------------------------------------------------------------- requests


@given(u32, u32, u32)
def test_read_request(group: int, offset: int, length: int) -> None:
    data = cmd.encode_read_request(group, offset, length)
    assert data == struct.pack("<III", group, offset, length)
    assert cmd.decode_request(2, 5, 551, data) == ReadRequest(5, 551, group, offset, length)


@given(u32, u32, payloads)
def test_write_request(group: int, offset: int, body: bytes) -> None:
    data = cmd.encode_write_request(group, offset, body)
    assert data == struct.pack("<III", group, offset, len(body)) + body
    assert cmd.decode_request(3, 5, 553, data) == WriteRequest(5, 553, group, offset, body)


@given(u32, u32, u32, payloads)
def test_read_write_request(group: int, offset: int, read_length: int, body: bytes) -> None:
    data = cmd.encode_read_write_request(group, offset, read_length, body)
    assert data == struct.pack("<IIII", group, offset, read_length, len(body)) + body
    assert cmd.decode_request(9, 5, 851, data) == ReadWriteRequest(
        5, 851, group, offset, read_length, body)


@given(u16, u16, payloads)
def test_write_control_request(ads_state: int, device_state: int, body: bytes) -> None:
    data = cmd.encode_write_control_request(ads_state, device_state, body)
    assert data == struct.pack("<HHI", ads_state, device_state, len(body)) + body
    assert cmd.decode_request(5, 5, 851, data) == WriteControlRequest(
        5, 851, ads_state, device_state, body)


@given(st.tuples(u32, u32, u32, u32, u32, u32))
def test_add_notification_request(fields: tuple[int, ...]) -> None:
    data = cmd.encode_add_notification_request(*fields)
    assert len(data) == 40 and data == struct.pack("<6I", *fields) + bytes(16)
    request = cmd.decode_request(6, 5, 851, data)
    assert request == cmd.AmsAddNotificationRequest(5, 851, *fields)
    assert request.cycle_time_100ns == fields[5] and request.max_delay_100ns == fields[4]


def test_requests_without_data() -> None:
    assert cmd.decode_request(1, 3, 10000, b"") == ReadDeviceInfoRequest(3, 10000)
    assert cmd.decode_request(4, 3, 851, b"") == ReadStateRequest(3, 851)
    assert cmd.decode_request(7, 3, 851, cmd.encode_delete_notification_request(12)) == \
        DeleteNotificationRequest(3, 851, 12)


@pytest.mark.parametrize(("command", "data"), [
    (1, b"\x00"),  # ReadDeviceInfo carries nothing
    (2, bytes(11)),  # Read: 12 bytes
    (2, bytes(13)),
    (3, bytes(8)),  # Write shorter than its head
    (3, struct.pack("<III", 1, 2, 5) + b"1234"),  # announces 5, carries 4
    (3, struct.pack("<III", 1, 2, 3) + b"1234"),  # announces 3, carries 4
    (4, b"\x00\x00"),  # ReadState carries nothing
    (5, struct.pack("<HHI", 5, 0, 1)),  # WriteControl announces 1 byte, carries none
    (6, bytes(24)),  # AddDeviceNotification is 40 bytes (16 reserved)
    (7, bytes(8)),  # DeleteDeviceNotification: the handle only
    (9, struct.pack("<IIII", 1, 2, 4, 2) + b"x"),  # ReadWrite announces 2, carries 1
    (9, bytes(15)),
])
def test_data_of_the_wrong_size_is_0x705(command: int, data: bytes) -> None:
    with pytest.raises(ProtocolError) as caught:
        cmd.decode_request(command, 77, 851, data)
    assert caught.value.code == 0x705
    assert (caught.value.invoke_id, caught.value.command) == (77, command)


@pytest.mark.parametrize("command", [0, 8, 10, 0x100, 0xFFFF])
def test_commands_not_served_are_0x701(command: int) -> None:
    with pytest.raises(ProtocolError) as caught:
        cmd.decode_request(command, 78, 851, b"")
    assert caught.value.code == 0x701 and caught.value.invoke_id == 78


# --------------------------------------------------------------------------- responses


def test_response_layouts() -> None:
    assert cmd.encode_response(2, b"\x01\x02") == struct.pack("<II", 0, 2) + b"\x01\x02"
    assert cmd.encode_response(9, b"abc") == struct.pack("<II", 0, 3) + b"abc"
    assert cmd.encode_response(3) == cmd.encode_response(5) == cmd.encode_response(7) == bytes(4)
    assert cmd.encode_response(4, 5, 0) == struct.pack("<IHH", 0, 5, 0)
    assert cmd.encode_response(6, 42) == struct.pack("<II", 0, 42)
    info = cmd.encode_response(1, 0, 1, 2, "cnc-objects")
    assert info == struct.pack("<IBBH16s", 0, 0, 1, 2, b"cnc-objects")


def test_a_device_name_is_cut_to_its_field() -> None:
    info = cmd.decode_response(1, cmd.encode_response(1, 1, 2, 3, "a-very-long-device-name"))
    assert info.name == "a-very-long-dev" and (info.major, info.minor, info.build) == (1, 2, 3)


#: The lengths a client expects of an error response (result and the empty fields).
ERROR_LENGTHS = {1: 4 + 1 + 1 + 2 + 16, 2: 8, 3: 4, 4: 4 + 2 + 2, 5: 4, 6: 4 + 4, 7: 4, 9: 8}


@pytest.mark.parametrize(("command", "length"), ERROR_LENGTHS.items())
def test_error_responses_have_the_length_the_client_expects(command: int, length: int) -> None:
    data = cmd.encode_error_response(command, 0x710)
    assert len(data) == length
    assert data[:4] == struct.pack("<I", 0x710) and data[4:] == bytes(length - 4)
    decoded = cmd.decode_response(command, data)  # the client's reading of it
    result = decoded.result if isinstance(decoded, cmd.DeviceInfo) else decoded[0]
    assert result == 0x710


def test_an_unknown_command_is_answered_with_the_result_alone() -> None:
    assert cmd.encode_error_response(0x55, 0x701) == struct.pack("<I", 0x701)


@given(payloads)
def test_read_response_round_trip(body: bytes) -> None:
    assert cmd.decode_response(2, cmd.encode_response(2, body)) == (0, body)
    assert cmd.decode_response(9, cmd.encode_response(9, body)) == (0, body)


def test_a_response_of_the_wrong_length_is_refused() -> None:
    with pytest.raises(ValueError):
        cmd.decode_response(2, struct.pack("<II", 0, 4) + b"12")
    with pytest.raises(ValueError):
        cmd.decode_response(4, bytes(4))


# --------------------------------------------------------------------------- notifications


def test_notification_layout_groups_samples_per_stamp() -> None:
    data = cmd.encode_notification([(1000, 1, b"\x01\x00"), (2000, 2, b"\xff"),
                                    (1000, 3, b"\x07\x00\x00\x00")])
    expected_body = (
        struct.pack("<QI", 1000, 2)
        + struct.pack("<II", 1, 2) + b"\x01\x00"
        + struct.pack("<II", 3, 4) + b"\x07\x00\x00\x00"
        + struct.pack("<QI", 2000, 1)
        + struct.pack("<II", 2, 1) + b"\xff"
    )
    assert data == struct.pack("<II", 4 + len(expected_body), 2) + expected_body
    stamps = cmd.decode_notification(data)
    assert [s.timestamp for s in stamps] == [1000, 2000]
    assert [(x.handle, x.data) for x in stamps[0].samples] == [(1, b"\x01\x00"),
                                                              (3, b"\x07\x00\x00\x00")]


@given(st.lists(st.tuples(st.sampled_from([1, 2, 3]), u32, payloads), max_size=10))
def test_notification_round_trip(samples: list[tuple[int, int, bytes]]) -> None:
    stamps = cmd.decode_notification(cmd.encode_notification(samples))
    flat = [(s.timestamp, x.handle, x.data) for s in stamps for x in s.samples]
    assert sorted(flat) == sorted(samples)
    assert len({s.timestamp for s in stamps}) == len(stamps)


@pytest.mark.parametrize("data", [
    b"",
    struct.pack("<II", 99, 0),  # length does not count what follows
    struct.pack("<II", 16, 1) + struct.pack("<QI", 1, 1),  # a sample is missing
    struct.pack("<II", 24, 1) + struct.pack("<QI", 1, 1) + struct.pack("<II", 1, 9),
])
def test_malformed_notifications_are_refused(data: bytes) -> None:
    with pytest.raises(ValueError):
        cmd.decode_notification(data)
