"""Sum write, value by name and write by handle on the wire (raw frames, real service)."""

from __future__ import annotations

import itertools
import struct

import pytest
import zmq

from cnc_objects.protocol import sum as sums
from cnc_objects.protocol.constants import ReservedIndexGroup as RIG
from cnc_objects.protocol.frames import ReadRequest, ReadWriteRequest, Response, WriteRequest, decode_incoming
from cnc_objects.testing import ServiceProcess

COM, GEO = 553, 551
CH1_COM, CH2_COM = 0x120101, 0x120102
_ids = itertools.count(1)


@pytest.fixture
def sock(cnc_service: ServiceProcess):
    s = zmq.Context.instance().socket(zmq.DEALER)
    s.setsockopt(zmq.LINGER, 0)
    s.connect(cnc_service.endpoint)
    yield s
    s.close()


def call(sock: zmq.Socket, request) -> Response:
    sock.send(request.encode())
    assert sock.poll(5000), f"no reply to {request}"
    reply = decode_incoming(sock.recv())
    assert isinstance(reply, Response) and reply.invoke_id == request.invoke_id
    return reply


def read_u16(sock: zmq.Socket, group: int, offset: int) -> int:
    reply = call(sock, ReadRequest(next(_ids), COM, group, offset, 2))
    assert reply.result == 0, reply
    return struct.unpack("<H", reply.fields[0])[0]


def test_sum_write_applies_good_items_and_codes_bad_ones(sock: zmq.Socket) -> None:
    items = [
        sums.SumItem(CH1_COM, 0x09, data=struct.pack("<H", 321)),  # feed override ch1
        sums.SumItem(CH2_COM, 0x09, data=struct.pack("<H", 654)),  # feed override ch2
        sums.SumItem(CH1_COM, 0x0A, data=struct.pack("<H", 1)),  # read-only: 0x704
        sums.SumItem(CH1_COM, 0x09, data=struct.pack("<H", 5000)),  # out of range: 0x706
        sums.SumItem(CH1_COM, 0x09, data=b"\x01"),  # wrong size: 0x705
        sums.SumItem(CH1_COM, 0x7777, data=b"\x00\x00"),  # unknown offset: 0x703
    ]
    data, read_length = sums.encode_sum_write(items)
    reply = call(sock, ReadWriteRequest(next(_ids), COM, RIG.SUM_WRITE, len(items), read_length, data))
    assert reply.result == 0
    assert sums.decode_codes(len(items), reply.fields[0]) == [0, 0, 0x704, 0x706, 0x705, 0x703]
    # The reply came after the kernel applied the good items: read them back at once.
    assert read_u16(sock, CH1_COM, 0x0C) == 321
    assert read_u16(sock, CH2_COM, 0x0C) == 654


def test_sum_write_with_inconsistent_lengths_is_refused(sock: zmq.Socket) -> None:
    data, read_length = sums.encode_sum_write([sums.SumItem(CH1_COM, 0x09, data=b"\x01\x00")])
    reply = call(sock, ReadWriteRequest(next(_ids), COM, RIG.SUM_WRITE, 1, read_length, data + b"x"))
    assert reply.result == 0x705 and reply.message
    assert read_u16(sock, CH1_COM, 0x0A) == 1000  # nothing was written


def test_value_by_name(sock: zmq.Socket) -> None:
    name = b"ch1.ax2.actual_link_to_physical_axis\x00"
    reply = call(sock, ReadWriteRequest(next(_ids), GEO, RIG.SYM_VALUE_BY_NAME, 0, 2, name))
    assert reply.result == 0 and reply.fields[0] == struct.pack("<H", 2)
    # The read length is a buffer size (TwinCAT): a larger one gets the value's 2 bytes.
    reply = call(sock, ReadWriteRequest(next(_ids), GEO, RIG.SYM_VALUE_BY_NAME, 0, 4, name))
    assert reply.result == 0 and reply.fields[0] == struct.pack("<H", 2)
    reply = call(sock, ReadWriteRequest(next(_ids), GEO, RIG.SYM_VALUE_BY_NAME, 0, 1, name))
    assert reply.result == 0x705


def test_write_and_read_by_handle(sock: zmq.Socket) -> None:
    name = b"ch1.mc_command_feed_override_w\x00"
    reply = call(sock, ReadWriteRequest(next(_ids), COM, RIG.SYM_HANDLE_BY_NAME, 0, 4, name))
    assert reply.result == 0
    handle = struct.unpack("<I", reply.fields[0])[0]
    reply = call(sock, WriteRequest(next(_ids), COM, RIG.SYM_VALUE_BY_HANDLE, handle, b"\x2c\x01"))
    assert reply.result == 0
    assert read_u16(sock, CH1_COM, 0x0C) == 300
    # The handle names a write-only command: it reads back the value last written.
    reply = call(sock, ReadRequest(next(_ids), COM, RIG.SYM_VALUE_BY_HANDLE, handle, 2))
    assert reply.result == 0 and reply.fields[0] == b"\x2c\x01"


def test_readwrite_on_an_ordinary_object_reads_without_data_and_refuses_data(
    sock: zmq.Socket,
) -> None:
    reply = call(sock, ReadWriteRequest(next(_ids), COM, CH1_COM, 0x0A, 2, b""))
    assert reply.result == 0 and reply.fields[0] == struct.pack("<H", 1000)
    reply = call(sock, ReadWriteRequest(next(_ids), COM, CH1_COM, 0x0A, 2, b"\x01\x00"))
    assert reply.result == 0x701 and "ReadWrite" in reply.message
