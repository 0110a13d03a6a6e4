"""Wire robustness: every error a client can provoke gets the right ADS code, never a crash.

These tests speak the frame format by hand (a raw pyzmq DEALER socket and msgpack, no
client library), so they prove what the service does on the wire:

    request      [invoke_id, command, port, *fields]
    response     [invoke_id, command, 0, *fields]
    error reply  [invoke_id, command, code, message]

Frames whose invoke id can be read get an error reply carrying that invoke id; frames
without a readable invoke id get no reply, and the service keeps serving everyone.
No sleeps: every wait is a poll with a timeout.
"""

from __future__ import annotations

import itertools
import re
import struct
import uuid
from collections.abc import Iterator

import msgpack
import pytest
import zmq
from zmq.utils.monitor import recv_monitor_message

from cnc_objects.clients import Client
from cnc_objects.service.limits import LimitsConfig
from cnc_objects.testing import ServiceProcess

# --------------------------------------------------------------------------- constants

READ_DEVICE_INFO, READ, WRITE, READ_STATE = 1, 2, 3, 4
ADD_NOTIFICATION, DELETE_NOTIFICATION, NOTIFICATION, READ_WRITE, BROWSE = 6, 7, 8, 9, 0x100

TARGETPORTNOTFOUND = 0x6
SRVNOTSUPP = 0x701
INVALIDGRP = 0x702
INVALIDOFFSET = 0x703
INVALIDACCESS = 0x704
INVALIDSIZE = 0x705
INVALIDDATA = 0x706
SYMBOLNOTFOUND = 0x710
TRANSMODENOTSUPP = 0x713
NOTIFYHNDINVALID = 0x714

GEO, COM = 551, 553
PLATFORM = 0x120100  # COM platform objects (cnc_*)
CH1_COM = 0x120101  # COM objects of channel 1 (mc_*)
CH1_GEO = 0x121301  # GEO objects of channel 1

# (port, group, offset, length) of objects whose value the default machine fixes.
NUMBER_OF_CHANNELS = (COM, PLATFORM, 0x1002, 2)  # UNS16: 2 channels
NUMBER_OF_AXES = (COM, PLATFORM, 0x1003, 4)  # UNS32: 3 physical axes
CYCLE_TIME = (COM, PLATFORM, 0x1010, 4)  # UNS32 us: 1 ms default cycle
AX1_LINK = (GEO, CH1_GEO, 0x10017, 2)  # UNS16: ch1 X is linked to physical axis 1
AX1_LINK_STATE = (GEO, CH1_GEO, 0x10018, 4)  # UNS32, read-only
FEED_OVERRIDE_W = (COM, CH1_COM, 0x09, 2)  # UNS16 0.1 %, write-only
FEED_OVERRIDE_R = (COM, CH1_COM, 0x0A, 2)  # UNS16 0.1 %
EXEC_MODE_W = (COM, CH1_COM, 0x3F, 4)  # SGN32, write-only
EXEC_MODE_R = (COM, CH1_COM, 0x40, 4)  # SGN32

#: Known objects and the little-endian bytes a fresh default service returns for them.
STATIC_VALUES = {
    NUMBER_OF_CHANNELS: struct.pack("<H", 2),
    NUMBER_OF_AXES: struct.pack("<I", 3),
    CYCLE_TIME: struct.pack("<I", 1000),
    AX1_LINK: struct.pack("<H", 1),
}

REPLY_TIMEOUT_MS = 5000
SILENCE_MS = 300  # how long "no reply" is waited for
#: The server's ZMQ_MAXMSGSIZE: twice [limits] max_frame_bytes (frames between the two
#: are answered 0x70B, tests/limits/test_frame_size.py).
MAXMSGSIZE = LimitsConfig().frame_hard_cap_bytes

_invoke_ids = itertools.count(1)
_context = zmq.Context.instance()


# --------------------------------------------------------------------------- helpers


def next_id() -> int:
    """A fresh invoke id (1..2**32-1)."""
    return next(_invoke_ids)


def pack(*items: object) -> bytes:
    """One frame: a msgpack array of ``items`` (bytes as bin, str as str)."""
    return msgpack.packb(list(items), use_bin_type=True)


def read_frame(invoke_id: int, port: int, group: int, offset: int, length: int) -> bytes:
    return pack(invoke_id, READ, port, group, offset, length)


def write_frame(invoke_id: int, port: int, group: int, offset: int, data: bytes) -> bytes:
    return pack(invoke_id, WRITE, port, group, offset, data)


def read_write_frame(
    invoke_id: int, port: int, group: int, offset: int, read_length: int, data: bytes
) -> bytes:
    return pack(invoke_id, READ_WRITE, port, group, offset, read_length, data)


def add_notification_frame(
    invoke_id: int, port: int, group: int, offset: int, length: int, mode: int, cycle_ms: int
) -> bytes:
    return pack(invoke_id, ADD_NOTIFICATION, port, group, offset, length, mode, 0, cycle_ms)


def connect(endpoint: str) -> zmq.Socket:
    """A DEALER socket connected to the service."""
    sock = _context.socket(zmq.DEALER)
    sock.setsockopt(zmq.LINGER, 0)
    sock.connect(endpoint)
    return sock


@pytest.fixture
def client(cnc_shared_service: ServiceProcess) -> Iterator[zmq.Socket]:
    """A raw DEALER socket on the shared service."""
    sock = connect(cnc_shared_service.endpoint)
    yield sock
    sock.close(linger=0)


def receive(sock: zmq.Socket, timeout_ms: int = REPLY_TIMEOUT_MS) -> list | None:
    """The next frame (decoded), or None when nothing came within ``timeout_ms``."""
    if not sock.poll(timeout_ms, zmq.POLLIN):
        return None
    parts = sock.recv_multipart()
    assert len(parts) == 1, f"a reply is one ZeroMQ frame, got {len(parts)} parts"
    frame = msgpack.unpackb(parts[0], raw=False)
    assert type(frame) is list, f"a reply is a msgpack array, got {frame!r}"
    return frame


def receive_reply(sock: zmq.Socket, timeout_ms: int = REPLY_TIMEOUT_MS) -> list:
    """The next reply, skipping notifications; fails when none comes in time."""
    while True:
        frame = receive(sock, timeout_ms)
        assert frame is not None, f"no reply within {timeout_ms} ms"
        if frame[0] == 0 and frame[1] == NOTIFICATION:
            continue
        return frame


def request(sock: zmq.Socket, frame: bytes, timeout_ms: int = REPLY_TIMEOUT_MS) -> list:
    """Send one frame and return its reply (notifications in between are skipped)."""
    sock.send(frame)
    return receive_reply(sock, timeout_ms)


def assert_ok(reply: list, invoke_id: int, command: int) -> list:
    """A success reply to ``invoke_id``; returns its fields after the result."""
    assert reply[0] == invoke_id, f"reply {reply!r} is not for invoke id {invoke_id}"
    assert reply[1] == command, f"reply {reply!r} is not for command {command}"
    assert reply[2] == 0, f"expected success, got 0x{reply[2]:x}: {reply[3:]!r}"
    return reply[3:]


def assert_error(reply: list, invoke_id: int, command: int | None, code: int | None) -> None:
    """An error reply [invoke_id, command, code, message] with a non-empty message.

    ``command`` None: any command id; ``code`` None: any non-zero ADS code.
    """
    assert reply[0] == invoke_id, f"reply {reply!r} is not for invoke id {invoke_id}"
    if command is not None:
        assert reply[1] == command, f"reply {reply!r} is not for command {command}"
    assert type(reply[2]) is int and reply[2] != 0, f"expected an error reply, got {reply!r}"
    if code is not None:
        assert reply[2] == code, f"expected ADS 0x{code:x}, got 0x{reply[2]:x}: {reply!r}"
    assert len(reply) == 4, f"an error reply is [invoke_id, command, code, message]: {reply!r}"
    assert type(reply[3]) is str and reply[3].strip(), f"error message is empty: {reply!r}"


def read(sock: zmq.Socket, address: tuple[int, int, int, int]) -> bytes:
    """Read an object; fails unless the service answers with data of the right length."""
    invoke_id = next_id()
    fields = assert_ok(request(sock, read_frame(invoke_id, *address)), invoke_id, READ)
    assert len(fields) == 1 and type(fields[0]) is bytes, fields
    assert len(fields[0]) == address[3], fields
    return fields[0]


def read_error(sock: zmq.Socket, address: tuple[int, int, int, int], code: int) -> None:
    """A Read of ``address`` must fail with ``code``."""
    invoke_id = next_id()
    assert_error(request(sock, read_frame(invoke_id, *address)), invoke_id, READ, code)


def write(sock: zmq.Socket, address: tuple[int, int, int, int], data: bytes) -> list:
    """Write ``data`` at ``address``; the reply."""
    port, group, offset, _ = address
    invoke_id = next_id()
    reply = request(sock, write_frame(invoke_id, port, group, offset, data))
    assert reply[0] == invoke_id and reply[1] == WRITE, reply
    return reply


def assert_serves(sock: zmq.Socket) -> None:
    """The service answers a valid Read on ``sock`` with the right value."""
    assert read(sock, NUMBER_OF_CHANNELS) == STATIC_VALUES[NUMBER_OF_CHANNELS]


def assert_silent_then_serves(sock: zmq.Socket, endpoint: str) -> None:
    """No reply comes for what was sent; the same socket and a new one are still served.

    The valid Read after the silence is answered in order, so its reply being the next
    frame also proves that no late reply to the dropped frame was on its way.
    """
    assert receive(sock, SILENCE_MS) is None, "a frame without a readable invoke id got a reply"
    assert_serves(sock)
    other = connect(endpoint)
    try:
        assert_serves(other)
    finally:
        other.close(linger=0)


def browse(sock: zmq.Socket, pattern: str) -> list[list]:
    """Descriptors [name, port, group, offset, type, length, access, unit, description]."""
    invoke_id = next_id()
    fields = assert_ok(request(sock, pack(invoke_id, BROWSE, 0, pattern)), invoke_id, BROWSE)
    assert len(fields) == 1 and type(fields[0]) is list, fields
    return fields[0]


def address_of(sock: zmq.Socket, name: str) -> tuple[int, int, int, int]:
    """(port, group, offset, length) of the object ``name``, found by BROWSE."""
    found = [d for d in browse(sock, name) if d[0] == name]
    assert len(found) == 1, f"browse found {found!r} for {name}"
    _, port, group, offset, _, length, *_ = found[0]
    return port, group, offset, length


def u32(data: bytes) -> int:
    return struct.unpack("<I", data)[0]


def u16(data: bytes) -> int:
    return struct.unpack("<H", data)[0]


def tick(sock: zmq.Socket) -> int:
    """The kernel's cycle counter (cnc_tick_counter_r)."""
    return u32(read(sock, (COM, PLATFORM, 0x1011, 4)))


def settle(sock: zmq.Socket, timeout_polls: int = 100_000) -> None:
    """Wait until the kernel has published two more cycles, so that reads come from a
    snapshot taken after everything acknowledged so far (reads serve the last cycle)."""
    start = tick(sock)
    for _ in range(timeout_polls):
        if tick(sock) >= start + 2:
            return
    raise AssertionError("the kernel cycle counter does not advance")


def sum_read_frame(invoke_id: int, port: int, items: list[tuple[int, int, int]]) -> bytes:
    """A sum read (ReadWrite 0xF080, offset = N) of (group, offset, length) items."""
    data = b"".join(struct.pack("<III", *item) for item in items)
    read_length = 4 * len(items) + sum(length for _, _, length in items)
    return read_write_frame(invoke_id, port, 0xF080, len(items), read_length, data)


def log_barrier(service: ServiceProcess) -> None:
    """Make the service log a unique line and wait for it: every line the service wrote
    before it is then in ``service.log`` (its stderr is one ordered stream)."""
    marker = f"barrier-{uuid.uuid4().hex}.nc"
    with Client(service.endpoint) as client:  # an upload is logged, each one
        client.upload(marker, b"M30\n")
        service.wait_for_log(re.escape(marker))
        client.delete_program(marker)


def assert_no_traceback(service: ServiceProcess) -> None:
    text = "\n".join(service.log)
    assert "Traceback" not in text, text


# --------------------------------------------------------------------------- addresses


def test_unknown_index_group_is_0x702(client: zmq.Socket) -> None:
    read_error(client, (GEO, 0x7E0000, 0x1, 4), INVALIDGRP)


def test_unknown_offset_in_known_group_is_0x703(client: zmq.Socket) -> None:
    read_error(client, (GEO, CH1_GEO, 0x7777, 4), INVALIDOFFSET)
    # The same group does serve its known offsets.
    assert u16(read(client, AX1_LINK)) == 1


def test_unknown_port_is_0x6(client: zmq.Socket) -> None:
    read_error(client, (999, CH1_GEO, 0x10018, 4), TARGETPORTNOTFOUND)
    # The address is valid on its own port.
    read(client, AX1_LINK_STATE)


# --------------------------------------------------------------------------- access


def test_write_to_read_only_object_is_0x704(client: zmq.Socket) -> None:
    before = read(client, AX1_LINK_STATE)
    invoke_id = next_id()
    port, group, offset, _ = AX1_LINK_STATE
    reply = request(client, write_frame(invoke_id, port, group, offset, struct.pack("<I", 2)))
    assert_error(reply, invoke_id, WRITE, INVALIDACCESS)
    settle(client)
    assert read(client, AX1_LINK_STATE) == before


def test_a_write_only_command_reads_back_the_value_last_applied(client: zmq.Socket) -> None:
    """As a PLC's command variable; a refused write leaves the value before it."""
    assert write(client, FEED_OVERRIDE_W, struct.pack("<H", 500))[2] == 0
    assert read(client, FEED_OVERRIDE_W) == struct.pack("<H", 500)
    assert write(client, FEED_OVERRIDE_W, struct.pack("<H", 2000))[2] == INVALIDDATA
    assert read(client, FEED_OVERRIDE_W) == struct.pack("<H", 500)
    assert write(client, FEED_OVERRIDE_W, struct.pack("<H", 1000))[2] == 0
    assert read(client, FEED_OVERRIDE_W) == struct.pack("<H", 1000)


# --------------------------------------------------------------------------- sizes


def test_read_with_wrong_length_is_0x705(client: zmq.Socket) -> None:
    port, group, offset, _ = NUMBER_OF_AXES  # UNS32
    read_error(client, (port, group, offset, 2), INVALIDSIZE)
    read_error(client, (port, group, offset, 8), INVALIDSIZE)
    read_error(client, (port, group, offset, 0), INVALIDSIZE)


def test_write_with_wrong_data_length_is_0x705(cnc_service: ServiceProcess) -> None:
    sock = connect(cnc_service.endpoint)
    try:
        before = read(sock, FEED_OVERRIDE_R)
        for data in (b"\x01", struct.pack("<I", 500), b""):
            port, group, offset, _ = FEED_OVERRIDE_W
            invoke_id = next_id()
            reply = request(sock, write_frame(invoke_id, port, group, offset, data))
            assert_error(reply, invoke_id, WRITE, INVALIDSIZE)
        settle(sock)
        assert read(sock, FEED_OVERRIDE_R) == before
    finally:
        sock.close(linger=0)


def test_huge_read_length_at_an_address_is_0x705_by_name_a_buffer_size(client: zmq.Socket) -> None:
    """An object at its address is read with its size; a read by name takes the read
    length as a buffer size (TwinCAT: 0xFFFFFFFF when the client does not know it)."""
    port, group, offset, _ = NUMBER_OF_AXES
    read_error(client, (port, group, offset, 0xFFFFFFFF), INVALIDSIZE)
    invoke_id = next_id()
    reply = request(
        client, read_write_frame(invoke_id, COM, 0xF004, 0, 0xFFFFFFFF, b"cnc_tick_counter_r\0")
    )
    (data,) = assert_ok(reply, invoke_id, READ_WRITE)
    assert len(data) == 4  # UNS32
    assert_serves(client)


def test_data_over_the_data_limit_but_under_the_frame_limit_is_0x705(
    client: zmq.Socket,
) -> None:
    port, group, offset, _ = FEED_OVERRIDE_W
    invoke_id = next_id()
    frame = write_frame(invoke_id, port, group, offset, bytes((1 << 20) + 1000))
    assert len(frame) < MAXMSGSIZE
    assert_error(request(client, frame), invoke_id, WRITE, INVALIDSIZE)
    assert_serves(client)


# --------------------------------------------------------------------------- values


def test_out_of_range_feed_override_is_0x706_and_not_applied(cnc_service: ServiceProcess) -> None:
    sock = connect(cnc_service.endpoint)
    try:
        # A valid value lands (so "unchanged" below is not a value that cannot change).
        assert write(sock, FEED_OVERRIDE_W, struct.pack("<H", 500))[2] == 0
        settle(sock)
        assert u16(read(sock, FEED_OVERRIDE_R)) == 500

        port, group, offset, _ = FEED_OVERRIDE_W
        for value in (2000, 1001, 0xFFFF):
            invoke_id = next_id()
            frame = write_frame(invoke_id, port, group, offset, struct.pack("<H", value))
            reply = request(sock, frame)
            assert_error(reply, invoke_id, WRITE, INVALIDDATA)
        settle(sock)
        assert u16(read(sock, FEED_OVERRIDE_R)) == 500
        assert u16(read(sock, (COM, CH1_COM, 0x0C, 2))) == 500  # active override

        # The documented maximum itself is accepted.
        assert write(sock, FEED_OVERRIDE_W, struct.pack("<H", 1000))[2] == 0
        settle(sock)
        assert u16(read(sock, FEED_OVERRIDE_R)) == 1000
    finally:
        sock.close(linger=0)


@pytest.mark.parametrize(
    "mode",
    [
        pytest.param(0x1, id="block-search-not-implemented"),
        pytest.param(0x18, id="SYNCHK-with-PROD_TIME"),
        pytest.param(0x4000_0000, id="undefined-bit"),
        pytest.param(-1, id="negative"),
    ],
)
def test_invalid_execution_mode_is_0x706_and_not_applied(
    cnc_service: ServiceProcess, mode: int
) -> None:
    sock = connect(cnc_service.endpoint)
    try:
        before = read(sock, EXEC_MODE_R)
        port, group, offset, _ = EXEC_MODE_W
        invoke_id = next_id()
        reply = request(sock, write_frame(invoke_id, port, group, offset, struct.pack("<i", mode)))
        assert_error(reply, invoke_id, WRITE, INVALIDDATA)
        settle(sock)
        assert read(sock, EXEC_MODE_R) == before
        # ISG_STANDARD (0) is a valid mode: the object does take writes.
        assert write(sock, EXEC_MODE_W, struct.pack("<i", 0))[2] == 0
    finally:
        sock.close(linger=0)


# --------------------------------------------------------------------------- commands


def test_delete_unknown_notification_handle_is_0x714(client: zmq.Socket) -> None:
    for handle in (0, 0xDEADBEEF):
        invoke_id = next_id()
        reply = request(client, pack(invoke_id, DELETE_NOTIFICATION, COM, handle))
        assert_error(reply, invoke_id, DELETE_NOTIFICATION, NOTIFYHNDINVALID)


def test_unsupported_command_is_0x701_with_its_invoke_id(client: zmq.Socket) -> None:
    invoke_id = 0xFFFFFFFF  # the largest valid invoke id travels back intact
    reply = request(client, pack(invoke_id, 42, COM, PLATFORM, 0x1002, 2))
    assert_error(reply, invoke_id, 42, SRVNOTSUPP)
    invoke_id = next_id()
    reply = request(client, pack(invoke_id, NOTIFICATION, COM, []))  # server-to-client only
    assert_error(reply, invoke_id, NOTIFICATION, SRVNOTSUPP)


# --------------------------------------------------------------------------- malformed frames

# Frames whose invoke id (12345) is readable: each gets an error reply carrying it.
# (frame, command id expected in the reply or None for any)
READABLE_ID = 12345
MALFORMED_WITH_ID = {
    "group-is-a-string": (pack(READABLE_ID, READ, COM, "0x120100", 0x1002, 2), READ),
    "offset-is-a-float": (pack(READABLE_ID, READ, COM, PLATFORM, 4098.0, 2), READ),
    "length-is-bytes": (pack(READABLE_ID, READ, COM, PLATFORM, 0x1002, b"\x02"), READ),
    "read-with-an-extra-field": (pack(READABLE_ID, READ, COM, PLATFORM, 0x1002, 2, 0), READ),
    "read-missing-length": (pack(READABLE_ID, READ, COM, PLATFORM, 0x1002), READ),
    "read-with-no-fields": (pack(READABLE_ID, READ, COM), READ),
    "negative-group": (pack(READABLE_ID, READ, COM, -1, 0x1002, 2), READ),
    "group-above-u32": (pack(READABLE_ID, READ, COM, 2**32, 0x1002, 2), READ),
    "offset-above-u32": (pack(READABLE_ID, READ, COM, PLATFORM, 2**64 - 1, 2), READ),
    "negative-length": (pack(READABLE_ID, READ, COM, PLATFORM, 0x1002, -2), READ),
    "port-above-u16": (pack(READABLE_ID, READ, 0x10000, PLATFORM, 0x1002, 2), READ),
    "port-is-a-string": (pack(READABLE_ID, READ, "553", PLATFORM, 0x1002, 2), READ),
    "write-data-is-a-string": (pack(READABLE_ID, WRITE, COM, CH1_COM, 0x09, "\x01\x00"), WRITE),
    "write-data-is-a-list": (pack(READABLE_ID, WRITE, COM, CH1_COM, 0x09, [1, 0]), WRITE),
    "browse-pattern-is-bytes": (pack(READABLE_ID, BROWSE, 0, b"*"), BROWSE),
    "command-is-a-string": (pack(READABLE_ID, "READ", COM, PLATFORM, 0x1002, 2), None),
    "command-is-nil": (pack(READABLE_ID, None, COM, PLATFORM, 0x1002, 2), None),
    "unsupported-command-zero": (pack(READABLE_ID, 0, COM), 0),
    "array-of-invoke-id-and-command-only": (pack(READABLE_ID, READ), None),
    "array-of-invoke-id-only": (pack(READABLE_ID), None),
}


@pytest.mark.parametrize("name", list(MALFORMED_WITH_ID))
def test_malformed_frame_with_readable_invoke_id_gets_error_reply(
    client: zmq.Socket, name: str
) -> None:
    frame, command = MALFORMED_WITH_ID[name]
    client.send(frame)
    reply = receive(client)
    assert reply is not None, f"no error reply to {msgpack.unpackb(frame, raw=False)!r}"
    assert_error(reply, READABLE_ID, command, None)
    assert_serves(client)


# Frames with no readable invoke id: no reply at all, and the service keeps serving.
MALFORMED_WITHOUT_ID = {
    "not-msgpack": b"\xc1\xc1\xc1\xc1",
    "truncated-msgpack": b"\x96\x01\x02\xcd\x02",
    "msgpack-with-trailing-bytes": pack(1, READ, COM, PLATFORM, 0x1002, 2) + b"\x00",
    "empty-message": b"",
    "map-instead-of-array": msgpack.packb(
        {"invoke_id": 1, "command": READ, "port": COM, "group": PLATFORM}
    ),
    "bare-integer": msgpack.packb(7),
    "empty-array": pack(),
    "invoke-id-zero": pack(0, READ, COM, PLATFORM, 0x1002, 2),
    "negative-invoke-id": pack(-5, READ, COM, PLATFORM, 0x1002, 2),
    "invoke-id-above-u32": pack(2**32, READ, COM, PLATFORM, 0x1002, 2),
    "invoke-id-is-a-string": pack("7", READ, COM, PLATFORM, 0x1002, 2),
    "invoke-id-is-a-float": pack(7.0, READ, COM, PLATFORM, 0x1002, 2),
    "invoke-id-is-a-bool": pack(True, READ, COM, PLATFORM, 0x1002, 2),
    "invalid-utf8-string": b"\x96\x07\x02\xcd\x02\x29\xa2\xff\xfe\x00\x02",
}


@pytest.mark.parametrize("name", list(MALFORMED_WITHOUT_ID))
def test_malformed_frame_without_invoke_id_is_dropped_and_service_still_serves(
    client: zmq.Socket, endpoint: str, name: str
) -> None:
    client.send(MALFORMED_WITHOUT_ID[name])
    assert_silent_then_serves(client, endpoint)


def test_a_flood_of_frames_without_invoke_id_logs_a_line_not_one_per_frame(
    cnc_service: ServiceProcess,
) -> None:
    """A client causes such frames at will: the first is logged with its detail, the
    rest are counted into a line at most every 10 s (the log held one line per frame)."""
    sock = connect(cnc_service.endpoint)
    try:
        for _ in range(1000):
            sock.send(MALFORMED_WITHOUT_ID["not-msgpack"])
        assert_serves(sock)  # behind the flood: every frame of it was read
    finally:
        sock.close(linger=0)
    lines = [line for line in cnc_service.log if "no readable invoke id" in line]
    assert len(lines) == 1, lines[:5]
    assert "frame is not valid msgpack" in lines[0]


def test_frame_over_maxmsgsize_cuts_off_only_its_sender(endpoint: str) -> None:
    big = connect(endpoint)
    monitor = big.get_monitor_socket(zmq.EVENT_CONNECTED | zmq.EVENT_DISCONNECTED)
    other = connect(endpoint)
    try:
        assert_serves(big)  # connected and served before
        port, group, offset, _ = FEED_OVERRIDE_W
        invoke_id = next_id()
        frame = write_frame(invoke_id, port, group, offset, bytes(MAXMSGSIZE + 4096))
        assert len(frame) > MAXMSGSIZE
        big.send(frame)

        # The service drops the connection: the sender's socket sees it go.
        events = []
        while True:
            assert monitor.poll(REPLY_TIMEOUT_MS), f"no disconnect seen; events {events}"
            event = recv_monitor_message(monitor)["event"]
            events.append(event)
            if event == zmq.EVENT_DISCONNECTED:
                break
        # The oversized request is never answered.
        assert receive(big, SILENCE_MS) is None

        # Everyone else is still served, repeatedly.
        for _ in range(3):
            assert_serves(other)
        assert read(other, CYCLE_TIME) == STATIC_VALUES[CYCLE_TIME]
    finally:
        big.disable_monitor()
        monitor.close(linger=0)
        big.close(linger=0)
        other.close(linger=0)


# --------------------------------------------------------------------------- pipelining


def test_500_pipelined_reads_each_get_exactly_one_correct_reply(client: zmq.Socket) -> None:
    addresses = list(STATIC_VALUES)
    base = 0x7000_0000  # distinct from the ids other tests use
    sent = {}
    for k in range(500):
        address = addresses[k % len(addresses)]
        sent[base + k] = address
        client.send(read_frame(base + k, *address))

    seen: dict[int, int] = {}
    while len(seen) < len(sent):
        reply = receive(client)
        assert reply is not None, f"only {len(seen)} of {len(sent)} replies arrived"
        invoke_id = reply[0]
        assert invoke_id in sent, f"reply to an invoke id never sent: {reply!r}"
        assert invoke_id not in seen, f"invoke id {invoke_id} answered twice"
        seen[invoke_id] = 1
        assert reply[1] == READ and reply[2] == 0, reply
        assert reply[3] == STATIC_VALUES[sent[invoke_id]], (reply, sent[invoke_id])
    assert receive(client, SILENCE_MS) is None, "more replies than requests"


# --------------------------------------------------------------------------- sum commands


def test_sum_read_mixes_good_and_bad_items(client: zmq.Socket) -> None:
    items = [
        (PLATFORM, 0x1002, 2),  # cnc_number_of_channel_r: 2
        (PLATFORM, 0x7777, 4),  # unknown offset: 0x703
        (PLATFORM, 0x1003, 4),  # cnc_number_of_axis_r: 3
        (CH1_COM, 0x3F, 2),  # mc_command_execution_mode_w is SGN32: 0x705
        (PLATFORM, 0x1010, 4),  # cnc_cycle_time_r: 1000 us
        (0x7E0000, 0x1, 2),  # unknown group: 0x702
        (PLATFORM, 0x1003, 2),  # wrong length: 0x705
    ]
    expected = [
        (0, struct.pack("<H", 2)),
        (INVALIDOFFSET, bytes(4)),
        (0, struct.pack("<I", 3)),
        (INVALIDSIZE, bytes(2)),
        (0, struct.pack("<I", 1000)),
        (INVALIDGRP, bytes(2)),
        (INVALIDSIZE, bytes(2)),
    ]
    invoke_id = next_id()
    reply = request(client, sum_read_frame(invoke_id, COM, items))
    fields = assert_ok(reply, invoke_id, READ_WRITE)
    data = fields[0]
    assert type(data) is bytes
    assert len(data) == 4 * len(items) + sum(n for _, _, n in items), len(data)
    codes = list(struct.unpack_from(f"<{len(items)}I", data))
    assert codes == [code for code, _ in expected], [hex(c) for c in codes]
    pos = 4 * len(items)
    for (_, _, length), (_, want) in zip(items, expected):
        assert data[pos : pos + length] == want, (pos, data[pos : pos + length], want)
        pos += length


def test_sum_read_whose_data_does_not_match_its_count_is_0x705(client: zmq.Socket) -> None:
    items = b"".join(struct.pack("<III", PLATFORM, 0x1002, 2) for _ in range(3))
    for count, data in ((4, items), (2, items), (3, items + b"\x00"), (3, items[:-1])):
        invoke_id = next_id()
        reply = request(client, read_write_frame(invoke_id, COM, 0xF080, count, 100, data))
        assert_error(reply, invoke_id, READ_WRITE, INVALIDSIZE)


@pytest.mark.parametrize("count", [0, 501])
def test_sum_read_with_0_or_501_items_is_refused(client: zmq.Socket, count: int) -> None:
    data = struct.pack("<III", PLATFORM, 0x1002, 2) * count
    invoke_id = next_id()
    reply = request(client, read_write_frame(invoke_id, COM, 0xF080, count, 6 * count, data))
    assert_error(reply, invoke_id, READ_WRITE, None)


def test_sum_read_of_500_items_is_served(client: zmq.Socket) -> None:
    invoke_id = next_id()
    items = [(PLATFORM, 0x1002, 2)] * 500
    reply = request(client, sum_read_frame(invoke_id, COM, items))
    fields = assert_ok(reply, invoke_id, READ_WRITE)
    data = fields[0]
    assert data[: 4 * 500] == bytes(4 * 500)
    assert data[4 * 500 :] == struct.pack("<H", 2) * 500


def test_sum_read_with_too_short_read_length_is_0x705(client: zmq.Socket) -> None:
    data = struct.pack("<III", PLATFORM, 0x1003, 4) * 2
    invoke_id = next_id()
    reply = request(client, read_write_frame(invoke_id, COM, 0xF080, 2, 2 * 4 + 8 - 1, data))
    assert_error(reply, invoke_id, READ_WRITE, INVALIDSIZE)


# --------------------------------------------------------------------------- handles


def test_handle_by_name_reads_the_value_and_releases(client: zmq.Socket) -> None:
    invoke_id = next_id()
    reply = request(
        client, read_write_frame(invoke_id, COM, 0xF003, 0, 4, b"cnc_number_of_axis_r\0")
    )
    (data,) = assert_ok(reply, invoke_id, READ_WRITE)
    assert type(data) is bytes and len(data) == 4
    handle = u32(data)

    by_handle = read(client, (COM, 0xF005, handle, 4))
    assert by_handle == read(client, NUMBER_OF_AXES) == struct.pack("<I", 3)

    # The handle names that object, not another one: a different name, a different handle.
    invoke_id = next_id()
    reply = request(
        client, read_write_frame(invoke_id, COM, 0xF003, 0, 4, b"cnc_number_of_channel_r\0")
    )
    (other,) = assert_ok(reply, invoke_id, READ_WRITE)
    assert u32(other) != handle
    assert read(client, (COM, 0xF005, u32(other), 2)) == struct.pack("<H", 2)

    invoke_id = next_id()
    reply = request(client, write_frame(invoke_id, COM, 0xF006, 0, struct.pack("<I", handle)))
    assert_ok(reply, invoke_id, WRITE)


def test_handle_of_unknown_name_is_0x710(client: zmq.Socket) -> None:
    invoke_id = next_id()
    reply = request(client, read_write_frame(invoke_id, COM, 0xF003, 0, 4, b"no_such_object\0"))
    assert_error(reply, invoke_id, READ_WRITE, SYMBOLNOTFOUND)


def test_release_or_read_of_unknown_handle_is_0x710(client: zmq.Socket) -> None:
    invoke_id = next_id()
    reply = request(client, write_frame(invoke_id, COM, 0xF006, 0, struct.pack("<I", 0xDEADBEEF)))
    assert_error(reply, invoke_id, WRITE, SYMBOLNOTFOUND)
    read_error(client, (COM, 0xF005, 0xDEADBEEF, 4), SYMBOLNOTFOUND)


# --------------------------------------------------------------------------- notifications


def test_add_notification_with_client_mode_is_0x713(client: zmq.Socket) -> None:
    port, group, offset, length = NUMBER_OF_AXES
    for mode in (0, 1, 2, 7, 99):
        invoke_id = next_id()
        reply = request(
            client, add_notification_frame(invoke_id, port, group, offset, length, mode, 10)
        )
        assert_error(reply, invoke_id, ADD_NOTIFICATION, TRANSMODENOTSUPP)
    assert receive(client, SILENCE_MS) is None, "a refused subscription sent samples"


def test_add_notification_on_unknown_address_is_0x703(client: zmq.Socket) -> None:
    invoke_id = next_id()
    reply = request(client, add_notification_frame(invoke_id, COM, PLATFORM, 0x7777, 4, 3, 10))
    assert_error(reply, invoke_id, ADD_NOTIFICATION, INVALIDOFFSET)
    assert receive(client, SILENCE_MS) is None, "a refused subscription sent samples"


def test_subscriber_that_vanishes_does_not_hurt_the_service(cnc_service: ServiceProcess) -> None:
    subscriber = connect(cnc_service.endpoint)
    other = connect(cnc_service.endpoint)
    try:
        port, group, offset, length = address_of(subscriber, "cnc_tick_counter_r")
        invoke_id = next_id()
        reply = request(
            subscriber, add_notification_frame(invoke_id, port, group, offset, length, 3, 10)
        )
        (handle,) = assert_ok(reply, invoke_id, ADD_NOTIFICATION)

        # Samples flow: consecutive sequence numbers, the tick counter moving forward.
        samples = []
        while len(samples) < 5:
            frame = receive(subscriber)
            assert frame is not None, f"only {len(samples)} samples arrived"
            assert frame[0] == 0 and frame[1] == NOTIFICATION and frame[2] == port, frame
            samples += [s for s in frame[3] if s[0] == handle]
        sequences = [s[1] for s in samples]
        assert sequences == list(range(1, len(samples) + 1)), sequences
        ticks = [u32(s[3]) for s in samples]
        assert ticks == sorted(ticks) and ticks[-1] > ticks[0], ticks

        subscriber.close(linger=0)  # gone without DeleteDeviceNotification

        # The cnc_service notices and forgets the subscription, and serves others meanwhile.
        cnc_service.wait_for_log(r"client gone: dropped 1 notification")
        for _ in range(3):
            assert_serves(other)
        assert tick(other) > ticks[-1]
        log_barrier(cnc_service)
        assert_no_traceback(cnc_service)
        assert cnc_service.process.poll() is None
    finally:
        subscriber.close(linger=0)
        other.close(linger=0)


# --------------------------------------------------------------------------- survival


def test_service_survives_everything_and_exits_cleanly(cnc_service: ServiceProcess) -> None:
    sock = connect(cnc_service.endpoint)
    try:
        # Every malformed frame, then a valid Read: whatever comes back before the Read's
        # reply is an error reply to a malformed frame (the dedicated tests above check
        # which frames must be answered).
        for frame, _ in MALFORMED_WITH_ID.values():
            sock.send(frame)
        for frame in MALFORMED_WITHOUT_ID.values():
            sock.send(frame)
        invoke_id = next_id()
        sock.send(read_frame(invoke_id, *NUMBER_OF_CHANNELS))
        while True:
            reply = receive_reply(sock)
            if reply[0] == invoke_id:
                break
            assert_error(reply, READABLE_ID, None, None)
        assert assert_ok(reply, invoke_id, READ) == [STATIC_VALUES[NUMBER_OF_CHANNELS]]
        assert_silent_then_serves(sock, cnc_service.endpoint)

        read_error(sock, (GEO, 0x7E0000, 0x1, 4), INVALIDGRP)
        read_error(sock, (GEO, CH1_GEO, 0x7777, 4), INVALIDOFFSET)
        read_error(sock, (999, CH1_GEO, 0x10018, 4), TARGETPORTNOTFOUND)
        read(sock, EXEC_MODE_W)  # a command reads back its last value
        read_error(sock, (COM, PLATFORM, 0x1003, 0xFFFFFFFF), INVALIDSIZE)
        assert write(sock, AX1_LINK_STATE, bytes(4))[2] == INVALIDACCESS
        assert write(sock, FEED_OVERRIDE_W, struct.pack("<H", 2000))[2] == INVALIDDATA
        assert write(sock, EXEC_MODE_W, struct.pack("<i", 0x4000_0000))[2] == INVALIDDATA
        invoke_id = next_id()
        assert_error(
            request(sock, pack(invoke_id, DELETE_NOTIFICATION, COM, 77)),
            invoke_id, DELETE_NOTIFICATION, NOTIFYHNDINVALID,
        )

        # A subscriber that vanishes.
        subscriber = connect(cnc_service.endpoint)
        invoke_id = next_id()
        frame = add_notification_frame(invoke_id, COM, PLATFORM, 0x1011, 4, 3, 10)
        reply = request(subscriber, frame)
        assert_ok(reply, invoke_id, ADD_NOTIFICATION)
        subscriber.close(linger=0)

        # An oversized frame from yet another client.
        big = connect(cnc_service.endpoint)
        big.send(bytes(MAXMSGSIZE + 1))
        assert receive(big, SILENCE_MS) is None
        big.close(linger=0)

        for address, value in STATIC_VALUES.items():
            assert read(sock, address) == value
        log_barrier(cnc_service)
        assert_no_traceback(cnc_service)
    finally:
        sock.close(linger=0)

    assert cnc_service.process.poll() is None, "the service died"
    assert cnc_service.stop() == 0, cnc_service.log_text
