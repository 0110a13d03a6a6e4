"""ADS over AMS/TCP, byte by byte: what pyads cannot send, from a client written here.

The client builds every frame by hand with ``struct`` from Beckhoff's specification and
reads replies the same way (no project code on this side of the socket)::

    AMS/TCP header  reserved u16, length u32
    AMS header      target net id 6, target port u16, source net id 6, source port u16,
                    command u16, state flags u16, data length u32, error code u32,
                    invoke id u32
    data            the command's payload

Each test waits for replies with a socket timeout, never for a fixed time: that no reply
came for a frame is shown by the reply to the next request arriving first.
"""

from __future__ import annotations

import struct
import threading
import time
from pathlib import Path

import pytest

from cnc_objects.clients import Client
from cnc_objects.service.ads.routes import Route, RouteTable
from cnc_objects.testing import ServiceProcess, start_service
from tests.support.ads_raw import (
    ADD_NOTIFICATION,
    CH1_COM,
    CH1_GEO,
    CLIENT_NET_ID,
    CLIENT_PORT,
    COM,
    DELETE_NOTIFICATION,
    GEO,
    PLC,
    READ,
    READ_DEVICE_INFO,
    READ_STATE,
    READ_WRITE,
    REQUEST,
    RESPONSE,
    SYSTEM,
    TIMEOUT_S,
    WRITE,
    WRITE_CONTROL,
    RawAds,
    Reply,
    _invoke_ids,
    add_notification,
    frame,
    read,
    read_write,
    write,
)

FILETIME_UNIX_EPOCH = 116444736000000000

















# --------------------------------------------------------------------------- framing


def test_the_service_logs_its_ads_address_and_net_id(ads_service: ServiceProcess) -> None:
    host, port = ads_service.ads_address  # type: ignore[misc]
    assert host == "127.0.0.1" and port > 0
    assert ads_service.ams_net_id == "127.0.0.1.1.1"  # the bound address + .1.1


def test_a_reply_follows_the_specification(ads: RawAds) -> None:
    invoke_id = ads.send(READ, read(CH1_GEO, 0x10017, 2), port=GEO)  # ch1.ax1 link_to
    got = ads.reply(invoke_id)
    assert (got.target_net_id, got.target_port) == (CLIENT_NET_ID, CLIENT_PORT)
    assert (got.source_net_id, got.source_port) == (ads.net_id, GEO)
    assert (got.command, got.flags, got.error) == (READ, RESPONSE, 0)
    assert got.data == struct.pack("<II", 0, 2) + struct.pack("<H", 1)


def test_a_request_split_byte_by_byte(ads: RawAds) -> None:
    raw = frame(READ, read(CH1_GEO, 0x10017, 2), port=GEO, target=ads.net_id, invoke_id=901)
    for k in range(len(raw)):
        ads.sock.sendall(raw[k:k + 1])
    assert ads.reply(901).data[8:] == struct.pack("<H", 1)


def test_requests_coalesced_in_one_segment_are_answered_in_order(ads: RawAds) -> None:
    raws = [frame(READ_STATE, port=PLC, target=ads.net_id, invoke_id=910 + k) for k in range(5)]
    ads.sock.sendall(b"".join(raws))
    for k in range(5):
        got = ads.reply(910 + k)
        assert got.data == struct.pack("<IHH", 0, 5, 0)  # RUN


def test_a_data_length_that_does_not_match_gets_ams_error_0xe(ads: RawAds) -> None:
    got = ads.call(READ, read(CH1_GEO, 0x10017, 2), port=GEO, length=11)
    assert got.error == 0xE and got.data == b"" and got.flags == RESPONSE
    assert ads.call(READ_STATE).result == 0  # the connection goes on


def test_a_truncated_header_is_skipped_and_the_connection_goes_on(ads: RawAds) -> None:
    ads.sock.sendall(struct.pack("<HI", 0, 20) + bytes(20))  # no room for an AMS header
    ads.sock.sendall(struct.pack("<HI", 0x2345, 2) + b"\x01\x02")  # an unknown router command
    assert ads.call(READ_STATE).result == 0  # the next reply is this one's


def test_a_frame_over_the_maximum_closes_that_connection_only(
    ads_service: ServiceProcess,
) -> None:
    bystander = RawAds(ads_service)
    offender = RawAds(ads_service)
    try:
        assert bystander.call(READ_STATE).result == 0
        offender.sock.sendall(struct.pack("<HI", 0, (1 << 20) + 1))  # the header says enough
        assert offender.closed_by_peer()
        ads_service.wait_for_log(r"ADS connection from 127\.0\.0\.1:\d+ closed: .*exceeds")
        assert bystander.call(READ_STATE).result == 0
        with Client(ads_service.endpoint, timeout_s=TIMEOUT_S) as zmq_client:  # alive
            assert zmq_client.read("ch1.ax1.link_state") == 0
    finally:
        bystander.close()
        offender.close()


# --------------------------------------------------------------------------- routing


@pytest.mark.parametrize("port", [0, 800, 852, 10001, 0xFFFF])
def test_an_unknown_port_gets_ams_error_0x6(ads: RawAds, port: int) -> None:
    got = ads.call(READ_STATE, port=port)
    assert got.error == 0x6 and got.data == b""
    assert (got.source_port, got.target_port) == (port, CLIENT_PORT)


def test_another_net_id_gets_ams_error_0x7(ads: RawAds) -> None:
    got = ads.call(READ_STATE, target=bytes([10, 0, 0, 9, 1, 1]))
    assert got.error == 0x7 and got.data == b""
    assert ads.call(READ_STATE).result == 0


def test_the_system_service_answers_on_port_10000(ads: RawAds) -> None:
    assert ads.call(READ_STATE, port=SYSTEM).data == struct.pack("<IHH", 0, 5, 0)
    info = ads.call(READ_DEVICE_INFO, port=SYSTEM)
    assert len(info.data) == 24 and info.result == 0
    assert info.data[8:].rstrip(b"\x00") == b"cnc-objects"
    # A port without objects has no index groups: ADS 0x702, not a router error.
    assert ads.call(READ, read(0x4020, 0, 4), port=SYSTEM).data == struct.pack("<II", 0x702, 0)


def test_the_route_decision() -> None:
    routes = RouteTable([Route.parse("hmi", "192.0.2.7.1.1", "192.0.2.7")])
    refused = routes.admit("192.0.2.8")
    assert not refused.allowed and not refused.accepts(bytes([192, 0, 2, 8, 1, 1]))
    routed = routes.admit("192.0.2.7")
    assert routed.accepts(bytes([192, 0, 2, 7, 1, 1]))
    assert not routed.accepts(bytes([192, 0, 2, 9, 1, 1]))  # its route's Net ID only
    assert not RouteTable().admit("192.0.2.7").allowed
    for loopback in ("127.0.0.1", "127.0.0.42", "::1", "::ffff:127.0.0.1"):
        assert routes.admit(loopback).accepts(bytes(6)), loopback  # any Net ID
    assert routes.admit("::ffff:192.0.2.7").allowed  # IPv4-mapped is the IPv4 peer
    assert not routes.admit("not an address").allowed


def test_a_peer_without_a_route_is_refused_and_a_routed_one_served(
    tmp_path: Path, non_loopback_ipv4: str
) -> None:
    """A real non-loopback peer: this machine's own network address, bound on both ends."""
    address = non_loopback_ipv4
    routed_net_id = f"{address}.1.1"
    config = tmp_path / "routes.toml"
    config.write_text(f'[[ads.routes]]\nname = "hmi"\nnet_id = "{routed_net_id}"\n'
                      f'address = "{address}"\n')
    # A route for another peer only: a non-loopback address needs routes to be served.
    elsewhere = tmp_path / "elsewhere.toml"
    elsewhere.write_text('[[ads.routes]]\nname = "other"\nnet_id = "198.51.100.7.1.1"\n'
                         'address = "198.51.100.7"\n')
    plain = start_service("--config", str(elsewhere), program_dir=tmp_path / "a",
                          ads=f"{address}:0")
    try:
        refused = RawAds(plain)
        assert refused.closed_by_peer()
        plain.wait_for_log(rf"ADS connection from {address}:\d+ refused: no route")
        refused.close()
    finally:
        assert plain.stop() == 0
    routed = start_service("--config", str(config), program_dir=tmp_path / "b",
                           ads=f"{address}:0")
    try:
        ok = RawAds(routed)
        invoke_id = next(_invoke_ids)
        ok.sock.sendall(struct.pack("<HI", 0, 32) + struct.pack(
            "<6sH6sHHHIII", ok.net_id, PLC, bytes(int(p) for p in routed_net_id.split(".")),
            CLIENT_PORT, READ_STATE, REQUEST, 0, 0, invoke_id))
        assert ok.reply(invoke_id).result == 0
        ok.close()
        stranger = RawAds(routed)  # the routed address, but not the route's Net ID
        stranger.send(READ_STATE)
        assert stranger.closed_by_peer()
        routed.wait_for_log(rf"ADS connection from {address}:\d+ \(AMS Net ID "
                            r"10\.11\.12\.13\.1\.1\) closed: no route")
        stranger.close()
    finally:
        assert routed.stop() == 0


# --------------------------------------------------------------------------- commands


@pytest.mark.parametrize("command", [0, 8, 10, 0x55, 0x100])
def test_an_unknown_command_gets_0x701(ads: RawAds, command: int) -> None:
    got = ads.call(command)
    assert got.error == 0 and got.data == struct.pack("<I", 0x701)
    assert ads.call(READ_STATE).result == 0


#: (command, data, ADS code, reply data length): one error of each command.
ERRORS = [
    (READ_DEVICE_INFO, b"\x00", 0x705, 24),  # carries no data
    (READ, read(0x777777, 0, 4), 0x702, 8),  # unknown group
    (READ, read(CH1_COM, 0xA, 4), 0x705, 8),  # UNS16 read with 4 bytes
    (WRITE, write(CH1_COM, 0xA, b"\x01\x00"), 0x704, 4),  # read-only
    (READ_STATE, b"\x00", 0x705, 8),
    (WRITE_CONTROL, struct.pack("<HHI", 11, 0, 0), 0x706, 4),  # ERROR cannot be commanded
    (ADD_NOTIFICATION, add_notification(CH1_COM, 0xA, 2, 1, 0), 0x713, 8),  # client mode
    (DELETE_NOTIFICATION, struct.pack("<I", 999_999), 0x714, 4),
    (READ_WRITE, read_write(0xF003, 0, 4, b"no.such.symbol\x00"), 0x710, 8),
]


@pytest.mark.parametrize(("command", "data", "code", "length"), ERRORS)
def test_error_replies_have_the_length_of_the_command(
    ads: RawAds, command: int, data: bytes, code: int, length: int,
) -> None:
    port = COM if command in (READ, WRITE, ADD_NOTIFICATION) else PLC
    got = ads.call(command, data, port=port)
    assert got.error == 0 and got.result == code
    assert len(got.data) == length and got.data[4:] == bytes(length - 4)


def test_a_string_is_read_with_any_length(ads: RawAds) -> None:
    """ch1.mc_active_program_name_r, STRING(84): cut to a shorter read, whole for a
    longer one; every other type must be read with its size."""
    whole = ads.call(READ, read(CH1_COM, 0x3005, 84), port=COM)
    assert whole.data[:8] == struct.pack("<II", 0, 84)
    short = ads.call(READ, read(CH1_COM, 0x3005, 10), port=COM)
    assert short.data == struct.pack("<II", 0, 10) + whole.data[8:18]
    long = ads.call(READ, read(CH1_COM, 0x3005, 1024), port=COM)
    assert long.data == whole.data
    assert ads.call(READ, read(CH1_COM, 0xA, 3), port=COM).result == 0x705  # a UINT


def test_by_name_access_resolves_every_object_on_every_port(ads: RawAds) -> None:
    name = b"ch1.ax1.requested_link_to_physical_axis\x00"  # a GEO object, UNS16
    for port in (GEO, COM, PLC, SYSTEM):
        got = ads.call(READ_WRITE, read_write(0xF004, 0, 2, name), port=port)
        assert got.data == struct.pack("<II", 0, 2) + struct.pack("<H", 1), port


def test_a_sum_read_serves_the_good_items_and_fails_the_bad_one_in_its_slot(ads: RawAds) -> None:
    items = [(CH1_GEO, 0x10017, 2), (0x777777, 0, 4), (CH1_GEO, 0x10018, 4)]
    request = b"".join(struct.pack("<III", *item) for item in items)
    got = ads.call(READ_WRITE, read_write(0xF080, 3, 12 + 10, request), port=GEO)
    assert got.result == 0
    length = struct.unpack_from("<I", got.data, 4)[0]
    body = got.data[8:]
    assert length == len(body) == 22
    assert struct.unpack_from("<III", body) == (0, 0x702, 0)
    assert body[12:] == struct.pack("<H", 1) + bytes(4) + struct.pack("<I", 0)


def test_a_sum_read_write_answers_each_sub_request_in_its_slot(ads: RawAds) -> None:
    """0xF082 of three handle-by-name requests, the middle one for an unknown name."""
    names = [b"ch1.ax1.link_state\x00", b"no.such.symbol\x00", b"cnc_cycle_time_r\x00"]
    head = b"".join(struct.pack("<IIII", 0xF003, 0, 4, len(n)) for n in names)
    got = ads.call(READ_WRITE, read_write(0xF082, 3, 3 * 8 + 3 * 4, head + b"".join(names)))
    body = got.data[8:]
    (first, first_length, second, second_length, third, third_length) = struct.unpack_from(
        "<IIIIII", body)
    assert (first, second, third) == (0, 0x710, 0)
    assert (first_length, second_length, third_length) == (4, 0, 4)
    handles = struct.unpack_from("<II", body, 24)
    assert len(body) == 24 + 8
    for handle, expected in zip(handles, (b"\x00" * 4, struct.pack("<I", 1000))):
        assert ads.call(READ, read(0xF005, handle, 4)).data[8:] == expected


def test_device_data_gives_the_plc_state_and_notifies_its_change(ads: RawAds) -> None:
    assert ads.call(READ, read(0xF100, 0, 2)).data == struct.pack("<II", 0, 2) + b"\x05\x00"
    assert ads.call(READ, read(0xF100, 2, 2)).data == struct.pack("<II", 0, 2) + b"\x00\x00"
    assert ads.call(READ, read(0xF100, 0, 4)).data[8:] == b"\x05\x00\x00\x00"
    assert ads.call(READ, read(0xF100, 4, 2)).result == 0x703
    assert ads.call(WRITE, write(0xF100, 0, b"\x06\x00")).result == 0x704
    subscribed = ads.call(ADD_NOTIFICATION, add_notification(0xF100, 0, 2, 4, 10_000))
    assert subscribed.result == 0
    handle = struct.unpack_from("<I", subscribed.data, 4)[0]
    try:
        assert _next_sample(ads, handle) == b"\x05\x00"  # RUN, at once
        assert ads.call(WRITE_CONTROL, struct.pack("<HHI", 6, 0, 0)).result == 0  # STOP
        assert _next_sample(ads, handle) == b"\x06\x00"
        assert ads.call(READ_STATE).data == struct.pack("<IHH", 0, 6, 0)
        assert ads.call(READ_STATE, port=SYSTEM).data == struct.pack("<IHH", 0, 5, 0)
    finally:
        assert ads.call(WRITE_CONTROL, struct.pack("<HHI", 5, 0, 0)).result == 0  # RUN
    assert ads.call(DELETE_NOTIFICATION, struct.pack("<I", handle)).result == 0


def _next_sample(ads: RawAds, handle: int) -> bytes:
    """The data of the next notification sample for ``handle``."""
    while True:
        got = ads.notification()
        for sample_handle, data in _samples(got):
            if sample_handle == handle:
                return data


def _samples(got: Reply) -> list[tuple[int, bytes]]:
    """(handle, data) of every sample of a DeviceNotification, checking its layout."""
    length, stamps = struct.unpack_from("<II", got.data)
    assert length == len(got.data) - 4
    pos, out = 8, []
    for _ in range(stamps):
        timestamp, count = struct.unpack_from("<QI", got.data, pos)
        now = FILETIME_UNIX_EPOCH + time.time_ns() // 100
        assert now - 600 * 10**7 < timestamp <= now  # a FILETIME of the last minute
        pos += 12
        for _ in range(count):
            sample_handle, size = struct.unpack_from("<II", got.data, pos)
            out.append((sample_handle, got.data[pos + 8:pos + 8 + size]))
            pos += 8 + size
    assert pos == len(got.data)
    return out


def test_notifications_go_to_the_subscribers_address(ads: RawAds) -> None:
    subscribed = ads.call(ADD_NOTIFICATION, add_notification(CH1_GEO, 0x10017, 2, 3, 100_000),
                          port=GEO)
    handle = struct.unpack_from("<I", subscribed.data, 4)[0]
    got = ads.notification()
    assert got.error == 0
    assert (got.target_net_id, got.target_port) == (CLIENT_NET_ID, CLIENT_PORT)
    assert (got.source_net_id, got.source_port) == (ads.net_id, GEO)
    assert _samples(got) == [(handle, b"\x01\x00")]
    assert _next_sample(ads, handle) == b"\x01\x00"  # cyclic: again after 10 ms


def test_a_closed_connection_loses_its_notifications(ads_service: ServiceProcess) -> None:
    ads = RawAds(ads_service)
    subscribed = ads.call(ADD_NOTIFICATION, add_notification(0xF100, 0, 2, 3, 10_000))
    assert subscribed.result == 0
    ads.close()
    ads_service.wait_for_log(r"client gone: dropped 1 notifications")


def test_a_client_that_does_not_read_is_paused_not_dropped(tmp_path: Path) -> None:
    """Replies pile up beyond the transport's high-water mark: the service stops reading
    that client (others are served meanwhile) and goes on, losing nothing, once it
    reads again."""
    service = start_service("--log-level", "DEBUG", program_dir=tmp_path, ads="127.0.0.1:0")
    try:
        slow = RawAds(service, receive_buffer_bytes=4096)  # a small window: replies wait
        bystander = RawAds(service)
        count = 100_000  # 5 MB of requests, 5 MB of replies: far over any socket buffer
        flood = b"".join(frame(READ, read(CH1_GEO, 0x10017, 2), port=GEO, target=slow.net_id,
                               invoke_id=100_000 + k) for k in range(count))
        sender = threading.Thread(target=slow.sock.sendall, args=(flood,), daemon=True)
        sender.start()  # blocks once the service stops reading: hence a thread
        service.wait_for_log(r"does not read its replies: not reading it until it does")
        assert bystander.call(READ_STATE).result == 0
        for k in range(count):
            assert slow.reply(100_000 + k).data[8:] == b"\x01\x00"
        sender.join(TIMEOUT_S)
        assert not sender.is_alive()
        assert slow.call(READ_STATE).result == 0
        slow.close()
        bystander.close()
    finally:
        assert service.stop() == 0
