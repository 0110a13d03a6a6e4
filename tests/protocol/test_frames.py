"""Frames (protocol/frames.py): requests, replies and notifications as msgpack arrays.

Every request type must survive encode/decode unchanged; every malformed frame must be
refused with ``ProtocolError`` carrying as much as could be read (invoke id, command,
ADS code) so that the server can still answer its sender, and nothing else may escape.
"""

from __future__ import annotations

import msgpack
import pytest
from hypothesis import given
from hypothesis import strategies as st

from cnc_objects.protocol.constants import AdsCommand
from cnc_objects.protocol.errors import AdsReturnCode, ProtocolError
from cnc_objects.protocol.frames import (
    REQUEST_TYPES,
    U32_MAX,
    AddNotificationRequest,
    BrowseRequest,
    DeleteNotificationRequest,
    Notification,
    RawSample,
    ReadDeviceInfoRequest,
    ReadRequest,
    ReadStateRequest,
    ReadWriteRequest,
    Response,
    WriteControlRequest,
    WriteRequest,
    decode_incoming,
    decode_request,
    encode_error,
    encode_notification,
    encode_response,
)


def pack(obj: object) -> bytes:
    """msgpack bytes of ``obj`` as a peer would send them (bytes as bin, str as str)."""
    return msgpack.packb(obj, use_bin_type=True)


#: One request of every type, with values that exercise each field's full range.
REQUESTS = [
    ReadDeviceInfoRequest(1, 553),
    ReadRequest(7, 551, 0x121302, 0x30017, 2),
    WriteRequest(U32_MAX, 553, 0x120101, 0x09, b"\xe8\x03"),
    WriteRequest(3, 553, 0x120101, 0x09, b""),
    ReadStateRequest(4, 0),
    WriteControlRequest(5, 0xFFFF, 5, 0, b"\x00\x01"),
    AddNotificationRequest(6, 551, 0x121301, 0x56, 8, 4, 0, U32_MAX),
    DeleteNotificationRequest(7, 551, 12),
    ReadWriteRequest(8, 553, 0xF080, 2, 20, b"\x01\x02\x03"),
    BrowseRequest(9, 553, "ch1.*"),
    BrowseRequest(10, 553, ""),
]


def _id(request: object) -> str:
    return type(request).__name__


# --------------------------------------------------------------------------- requests


@pytest.mark.parametrize("request_", REQUESTS, ids=_id)
def test_every_request_type_round_trips(request_: object) -> None:
    decoded = decode_request(request_.encode())
    assert decoded == request_
    assert type(decoded) is type(request_)


@pytest.mark.parametrize("request_", REQUESTS, ids=_id)
def test_request_frame_layout_is_invoke_id_command_port_fields(request_: object) -> None:
    frame = msgpack.unpackb(request_.encode(), raw=False)
    assert frame == [request_.invoke_id, int(request_.COMMAND), *request_[1:]]


def test_data_travels_as_msgpack_bin() -> None:
    raw = WriteRequest(1, 553, 2, 3, b"\x00\xff").encode()
    assert msgpack.unpackb(raw, raw=True)[-1] == b"\x00\xff"
    assert b"\xc4\x02\x00\xff" in raw  # bin 8, two bytes


def test_request_table_covers_the_documented_commands() -> None:
    assert set(REQUEST_TYPES) == {1, 2, 3, 4, 5, 6, 7, 9, 0x100}
    for command, cls in REQUEST_TYPES.items():
        assert cls.COMMAND == command


def test_decode_request_builds_the_request_from_a_peer_frame() -> None:
    request = decode_request(pack([42, 2, 551, 0x121302, 0x30017, 2]))
    assert request == ReadRequest(42, 551, 0x121302, 0x30017, 2)
    assert (request.group, request.offset, request.length) == (0x121302, 0x30017, 2)


@pytest.mark.parametrize(
    "raw", [b"", b"\xc1", b"\x93\x01", b"\xdd\xff\xff\xff\xff", b"not msgpack at all \xc1"]
)
def test_decode_request_refuses_bytes_that_are_not_msgpack(raw: bytes) -> None:
    with pytest.raises(ProtocolError) as info:
        decode_request(raw)
    assert info.value.invoke_id is None


def test_decode_request_refuses_trailing_bytes() -> None:
    with pytest.raises(ProtocolError):
        decode_request(ReadStateRequest(1, 553).encode() + b"\x00")


@pytest.mark.parametrize(
    "obj", [7, "read", None, {"invoke_id": 1}, b"\x01\x02\x03", [], [0, 2], ["1", 2]], ids=repr
)
def test_decode_request_refuses_non_arrays_and_arrays_without_an_invoke_id(obj: object) -> None:
    with pytest.raises(ProtocolError) as info:
        decode_request(pack(obj))
    assert info.value.invoke_id is None


@pytest.mark.parametrize(("obj", "command"), [([1], None), ([1, 2], 2), ([1, "x"], None)], ids=repr)
def test_decode_request_refuses_short_arrays_naming_what_it_could_read(
    obj: list, command: int | None
) -> None:
    # ProtocolError carries the invoke id and command whenever they could be read.
    with pytest.raises(ProtocolError) as info:
        decode_request(pack(obj))
    assert info.value.invoke_id == 1
    assert info.value.command == command


@pytest.mark.parametrize(
    "invoke_id", [0, -1, U32_MAX + 1, 2**64 - 1, "1", 1.0, True, None, b"\x01"], ids=repr
)
def test_decode_request_refuses_bad_invoke_ids_without_naming_one(invoke_id: object) -> None:
    with pytest.raises(ProtocolError) as info:
        decode_request(pack([invoke_id, 4, 553]))
    assert info.value.invoke_id is None


@pytest.mark.parametrize("invoke_id", [1, U32_MAX])
def test_invoke_id_limits_are_accepted(invoke_id: int) -> None:
    assert decode_request(pack([invoke_id, 4, 553])) == ReadStateRequest(invoke_id, 553)


@pytest.mark.parametrize("command", [0, 8, 10, 0xFF, 0x101, U32_MAX, -1])
def test_unsupported_command_ids_answer_service_not_supported(command: int) -> None:
    with pytest.raises(ProtocolError) as info:
        decode_request(pack([77, command, 553]))
    assert info.value.code == AdsReturnCode.DEVICE_SRVNOTSUPP == 0x701
    assert info.value.invoke_id == 77
    assert info.value.command == command


@pytest.mark.parametrize("command", ["2", 2.0, None, [2]], ids=repr)
def test_a_command_that_is_not_an_integer_keeps_the_invoke_id(command: object) -> None:
    with pytest.raises(ProtocolError) as info:
        decode_request(pack([78, command, 553]))
    assert info.value.invoke_id == 78
    assert info.value.command is None


@pytest.mark.parametrize("port", [-1, 0x10000, "553", 553.0, None, True], ids=repr)
def test_port_out_of_range_or_not_an_integer_is_refused(port: object) -> None:
    with pytest.raises(ProtocolError) as info:
        decode_request(pack([79, 2, port, 1, 2, 3]))
    assert info.value.invoke_id == 79
    assert info.value.command == 2
    assert info.value.code == AdsReturnCode.DEVICE_INVALIDPARM


@pytest.mark.parametrize("port", [0, 0xFFFF])
def test_port_limits_are_accepted(port: int) -> None:
    assert decode_request(pack([1, 2, port, 1, 2, 3])).port == port


@pytest.mark.parametrize(
    "frame",
    [
        [5, 1, 553, 0],  # READ_DEVICE_INFO takes no fields
        [5, 2, 553, 1, 2],  # READ needs group, offset, length
        [5, 2, 553, 1, 2, 3, 4],
        [5, 3, 553, 1, 2],
        [5, 4, 553, 1],
        [5, 5, 553, 5, 0],
        [5, 6, 553, 1, 2, 3, 4, 5],
        [5, 7, 553],
        [5, 7, 553, 1, 2],
        [5, 9, 553, 1, 2, 3],
        [5, 0x100, 553],
        [5, 0x100, 553, "a", "b"],
    ],
    ids=repr,
)
def test_wrong_number_of_fields_is_refused_with_invoke_id_and_command(frame: list) -> None:
    with pytest.raises(ProtocolError) as info:
        decode_request(pack(frame))
    assert info.value.invoke_id == 5
    assert info.value.command == frame[1]
    assert info.value.code == AdsReturnCode.DEVICE_INVALIDPARM


@pytest.mark.parametrize(
    "frame",
    [
        [6, 2, 553, "1", 2, 3],  # group as text
        [6, 2, 553, 1, 2.0, 3],  # offset as float
        [6, 2, 553, 1, 2, -1],  # negative length
        [6, 2, 553, U32_MAX + 1, 2, 3],  # group beyond 32 bits
        [6, 2, 553, True, 2, 3],  # bool is not an integer
        [6, 3, 553, 1, 2, "text"],  # data as str, not bin
        [6, 3, 553, 1, 2, [1, 2]],
        [6, 3, 553, 1, 2, None],
        [6, 5, 553, 5, 0, "x"],
        [6, 6, 553, 1, 2, 3, 4, 5, -6],
        [6, 7, 553, "handle"],
        [6, 9, 553, 1, 2, 3, "data"],
        [6, 0x100, 553, b"ch1.*"],  # pattern as bin, not str
        [6, 0x100, 553, 12],
    ],
    ids=repr,
)
def test_wrong_field_types_are_refused_with_invoke_id_and_command(frame: list) -> None:
    with pytest.raises(ProtocolError) as info:
        decode_request(pack(frame))
    assert info.value.invoke_id == 6
    assert info.value.command == frame[1]


def test_protocol_error_is_a_value_error_with_a_message() -> None:
    with pytest.raises(ValueError, match="port"):
        decode_request(pack([1, 2, 70000, 1, 2, 3]))


# --------------------------------------------------------------------------- peek


# --------------------------------------------------------------------------- replies


def reply_parts(reply: object) -> tuple:
    """(invoke_id, command, result, fields as a tuple, message) of a decoded reply."""
    assert isinstance(reply, Response)
    return reply.invoke_id, reply.command, reply.result, tuple(reply.fields), reply.message


def test_encode_response_round_trips() -> None:
    raw = encode_response(21, AdsCommand.READ, b"\x34\x12")
    assert msgpack.unpackb(raw, raw=False) == [21, 2, 0, b"\x34\x12"]
    assert reply_parts(decode_incoming(raw)) == (21, 2, 0, (b"\x34\x12",), "")


def test_device_info_reply_fields() -> None:
    raw = encode_response(1, AdsCommand.READ_DEVICE_INFO, 1, 2, 3, "cnc-objects")
    assert reply_parts(decode_incoming(raw)) == (1, 1, 0, (1, 2, 3, "cnc-objects"), "")


def test_reply_without_fields() -> None:
    assert reply_parts(decode_incoming(encode_response(2, AdsCommand.WRITE))) == (2, 3, 0, (), "")


def test_browse_reply_keeps_descriptors() -> None:
    descriptor = ["ch1.dist_prog_start", 551, 0x121301, 0x56, "REAL64", 8, "r", "0.1 um", "d", []]
    state = ["ch1.mc_active_state_r", 553, 0x120101, 0x3002, "UNS32", 4, "r", "-", "d",
             [[1, "DESELECTED"], [3, "READY"]]]
    reply = decode_incoming(encode_response(3, AdsCommand.BROWSE, [descriptor, state]))
    assert tuple(reply.fields) == ([descriptor, state],)


def test_value_names_travel_as_pairs_because_integer_map_keys_are_refused() -> None:
    """Why a descriptor's value names are [[value, name], ...] and not a map."""
    with pytest.raises(ProtocolError):
        decode_incoming(encode_response(3, AdsCommand.BROWSE, [{3: "READY"}]))


def test_encode_error_round_trips_code_and_message() -> None:
    raw = encode_error(22, AdsCommand.WRITE, AdsReturnCode.DEVICE_INVALIDACCESS, "read-only")
    assert msgpack.unpackb(raw, raw=False) == [22, 3, 0x704, "read-only"]
    assert reply_parts(decode_incoming(raw)) == (22, 3, 0x704, (), "read-only")


def test_error_reply_without_a_message() -> None:
    assert reply_parts(decode_incoming(pack([23, 2, 0x702]))) == (23, 2, 0x702, (), "")


def test_error_reply_with_a_message_that_is_not_text_keeps_the_code() -> None:
    assert reply_parts(decode_incoming(pack([24, 2, 0x705, 17]))) == (24, 2, 0x705, (), "")


@pytest.mark.parametrize(
    "response",
    [
        Response(1, 2, 0, (b"\x01\x02",)),
        Response(2, 4, 0, (5, 0)),
        Response(3, 3, 0),
        Response(4, 2, 0x703, (), "index offset 0x99 is unknown"),
    ],
    ids=repr,
)
def test_response_encode_round_trips(response: Response) -> None:
    assert reply_parts(decode_incoming(response.encode())) == reply_parts(response)


def test_error_response_encode_drops_fields() -> None:
    raw = Response(5, 2, 0x705, (b"ignored",), "wrong size").encode()
    assert msgpack.unpackb(raw, raw=False) == [5, 2, 0x705, "wrong size"]


# --------------------------------------------------------------------------- notifications


def test_notification_round_trips_its_samples() -> None:
    samples = [[1, 10, 133_000_000_000_000_000, b"\x01\x00"], [2, 11, 133_000_000_000_000_001, b""]]
    raw = encode_notification(551, samples)
    assert msgpack.unpackb(raw, raw=False) == [0, 8, 551, samples]
    note = decode_incoming(raw)
    assert note == Notification(
        551,
        (
            RawSample(1, 10, 133_000_000_000_000_000, b"\x01\x00"),
            RawSample(2, 11, 133_000_000_000_000_001, b""),
        ),
    )


def test_notification_without_samples() -> None:
    assert decode_incoming(encode_notification(553, [])) == Notification(553, ())


@pytest.mark.parametrize(
    "frame",
    [
        [0, 8, 551],  # no sample list
        [0, 8, 551, [], "extra"],
        [0, 8, 551, "samples"],
        [0, 8, 551, [[1, 2, 3]]],  # a sample with three fields
        [0, 8, 551, [[1, 2, 3, b"", 5]]],
        [0, 8, 551, [7]],  # a sample that is not an array
        [0, 8, 551, [None]],
    ],
    ids=repr,
)
def test_malformed_notifications_are_refused(frame: list) -> None:
    with pytest.raises(ProtocolError):
        decode_incoming(pack(frame))


@pytest.mark.parametrize(
    "sample",
    [
        ["h", 2, 3, b"\x00"],  # handle as text
        [1, 2.5, 3, b"\x00"],  # sequence as float
        [1, 2, None, b"\x00"],  # no timestamp
        [1, 2, 3, "data"],  # data as str, not bytes
        "abcd",  # a four-character string is not a sample
    ],
    ids=repr,
)
def test_notification_samples_with_wrong_field_types_are_refused(sample: object) -> None:
    with pytest.raises(ProtocolError):
        decode_incoming(pack([0, 8, 551, [sample]]))


@pytest.mark.parametrize(
    "obj",
    [5, "reply", None, {"a": 1}, [], [1], [1, 2], ["1", 2, 0], [1, "2", 0], [1, 2, "0"]],
    ids=repr,
)
def test_malformed_replies_are_refused(obj: object) -> None:
    with pytest.raises(ProtocolError):
        decode_incoming(pack(obj))


def test_decode_incoming_refuses_bytes_that_are_not_msgpack() -> None:
    with pytest.raises(ProtocolError):
        decode_incoming(b"\xc1\xc1")


# --------------------------------------------------------------------------- fuzzing

#: Anything msgpack can carry, nested.
msgpack_values = st.recursive(
    st.none()
    | st.booleans()
    | st.integers(min_value=-(2**63), max_value=2**64 - 1)
    | st.floats()
    | st.text(max_size=20)
    | st.binary(max_size=20),
    lambda children: st.lists(children, max_size=8)
    | st.dictionaries(st.text(max_size=8), children, max_size=4),
    max_leaves=30,
)

#: Arrays that look like requests: plausible heads, random fields of plausible kinds.
request_like = st.tuples(
    st.one_of(st.integers(min_value=-2, max_value=2**33), msgpack_values),
    st.one_of(st.sampled_from([0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 0x100]), msgpack_values),
    st.one_of(st.integers(min_value=-2, max_value=0x10001), msgpack_values),
    st.lists(
        st.one_of(
            st.integers(min_value=-2, max_value=2**33),
            st.binary(max_size=8),
            st.text(max_size=8),
            msgpack_values,
        ),
        max_size=8,
    ),
).map(lambda t: [t[0], t[1], t[2], *t[3]])


def _assert_request_or_protocol_error(raw: bytes) -> None:
    try:
        request = decode_request(raw)
    except ProtocolError as exc:
        assert exc.invoke_id is None or 0 < exc.invoke_id <= U32_MAX
        return
    assert type(request) in REQUEST_TYPES.values()
    assert 0 < request.invoke_id <= U32_MAX
    assert 0 <= request.port <= 0xFFFF
    assert decode_request(request.encode()) == request


@given(st.binary(max_size=64))
def test_decode_request_of_arbitrary_bytes(raw: bytes) -> None:
    _assert_request_or_protocol_error(raw)


@given(msgpack_values)
def test_decode_request_of_arbitrary_msgpack_values(obj: object) -> None:
    _assert_request_or_protocol_error(pack(obj))


@given(request_like)
def test_decode_request_of_request_like_arrays(obj: list) -> None:
    _assert_request_or_protocol_error(pack(obj))


@given(st.one_of(st.binary(max_size=64), msgpack_values.map(pack), request_like.map(pack)))
def test_decode_incoming_only_ever_raises_protocol_error(raw: bytes) -> None:
    try:
        reply = decode_incoming(raw)
    except ProtocolError:
        return
    assert isinstance(reply, (Response, Notification))


def test_encode_request_matches_the_request_types() -> None:
    from cnc_objects.protocol.frames import ReadRequest, WriteRequest, encode_request

    assert encode_request(7, 2, 551, (0x121301, 0x10018, 4)) == ReadRequest(
        7, 551, 0x121301, 0x10018, 4
    ).encode()
    assert encode_request(8, 3, 553, (0x120101, 9, b"\x01\x00")) == WriteRequest(
        8, 553, 0x120101, 9, b"\x01\x00"
    ).encode()
