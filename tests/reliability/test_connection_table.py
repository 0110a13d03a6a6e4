"""A full connection table (issue 35, hole 11): idle keyless connections cannot lock a
keyed client out, idle ones give their seats to newcomers, and a refused ZeroMQ client
is told that the table is full, not that its key was refused.

Before: 64 idle loopback ADS connections (``connections_per_front_end``) closed every
new ADS client at once, a route's too, for as long as they stayed; a ZeroMQ client
refused for a full table timed out (no keys) or was told its CURVE handshake failed.
The idle connections are raw TCP sockets (``floods``) that send nothing, as an attacker
holds them.
"""

from __future__ import annotations

import socket
import time
from contextlib import ExitStack
from pathlib import Path

import pytest

from cnc_objects.clients import AuthenticationError, Client, ServiceFullError
from cnc_objects.protocol.ams import AMS_HEADER_BYTES, FRAME_HEADER, REQUEST_FLAGS
from cnc_objects.protocol.constants import AdsCommand
from cnc_objects.protocol.frames import ReadRequest
from cnc_objects.service.limits import LimitsConfig
from cnc_objects.testing import serving
from tests.limits.wire import limits_toml
from tests.reliability.floods import CONNECT_TIMEOUT_S, Flood, zmtp_greeting
from tests.reliability.health import TICK_ADDRESS, RawConnection

IDLE = 70  # idle connections: more than the table holds
CAP = LimitsConfig().connections_per_front_end
SERVED_TIMEOUT_S = 30.0  # a newcomer served, on a loaded 2-core machine
SMALL_CAP = 4


def _ads_device_info(address: tuple[str, int], target: str, source: str,
                     source_address: str = "") -> int:
    """The ADS result of a ReadDeviceInfo over a new connection from ``source_address``,
    sent from AMS Net ID ``source``; ``ConnectionError`` when the service closes it."""
    with socket.create_connection(address, CONNECT_TIMEOUT_S,
                                  (source_address, 0) if source_address else None) as sock:
        sock.sendall(FRAME_HEADER.pack(
            0, AMS_HEADER_BYTES, _net_id(target), 851, _net_id(source), 30000,
            AdsCommand.READ_DEVICE_INFO, REQUEST_FLAGS, 0, 0, 7))
        reply = b""
        while len(reply) < FRAME_HEADER.size + 4:
            chunk = sock.recv(4096)
            if not chunk:
                raise ConnectionError("the service closed the connection")
            reply += chunk
        return int.from_bytes(reply[FRAME_HEADER.size:FRAME_HEADER.size + 4], "little")


def _net_id(text: str) -> bytes:
    return bytes(int(p) for p in text.split("."))


def _zmq_address(endpoint: str) -> tuple[str, int]:
    host, port = endpoint.removeprefix("tcp://").rsplit(":", 1)
    return host.strip("[]"), int(port)


def test_idle_keyless_ads_connections_do_not_lock_out_a_route(
        tmp_path: Path, non_loopback_ipv4: str) -> None:
    """70 idle loopback (keyless) ADS connections fill the table; a peer with a route
    still gets in at once (the keyless one idle longest gives up its seat), however
    long ``idle_connection_s`` is."""
    address = non_loopback_ipv4
    config = limits_toml(tmp_path / "c.toml", idle_connection_s=3600.0)
    config.write_text(config.read_text() + f'[[ads.routes]]\nname = "panel"\n'
                      f'net_id = "{address}.1.1"\naddress = "{address}"\n')
    with serving("--config", str(config), ads="0.0.0.0:0") as service:
        assert service.ads_address is not None and service.ams_net_id is not None
        port = service.ads_address[1]
        with Flood(("127.0.0.1", port), IDLE, b"") as idle:
            assert idle.wait_closed(IDLE - CAP, SERVED_TIMEOUT_S) == IDLE - CAP  # table full
            result = _ads_device_info((address, port), service.ams_net_id,
                                      f"{address}.1.1", address)
            assert result == 0
            assert idle.closed_by_service() == IDLE - CAP + 1  # one idle keyless gave way
        service.wait_for_log("idle keyless connection closed to make room")


def test_idle_keyless_ads_connections_give_way_to_a_keyless_newcomer(tmp_path: Path) -> None:
    """A new loopback client, too, is served once the idle connections have been idle
    for ``idle_connection_s``: the one idle longest is closed for it."""
    with serving("--config", str(limits_toml(tmp_path / "c.toml", idle_connection_s=0.5)),
                 ads=True) as service:
        assert service.ads_address is not None and service.ams_net_id is not None
        with Flood(service.ads_address, IDLE, b"") as idle:
            assert idle.wait_closed(IDLE - CAP, SERVED_TIMEOUT_S) == IDLE - CAP
            deadline = time.monotonic() + SERVED_TIMEOUT_S
            while True:  # refused until the idle ones have been idle 0.5 s
                try:
                    result = _ads_device_info(service.ads_address, service.ams_net_id,
                                              "127.0.0.1.1.1")
                    break
                except ConnectionError:
                    assert time.monotonic() < deadline, "no idle connection gave way"
                    time.sleep(0.1)
            assert result == 0
            assert idle.closed_by_service() > IDLE - CAP


def test_a_zeromq_client_refused_for_a_full_table_is_told_so(tmp_path: Path) -> None:
    """Without keys: a table full of busy connections refuses a newcomer in its
    handshake, and the client says the table is full (``ServiceFullError``), at once."""
    config = limits_toml(tmp_path / "c.toml", connections_per_front_end=SMALL_CAP,
                         idle_connection_s=3600.0)
    with serving("--config", str(config)) as service:
        seated = [RawConnection(service.endpoint) for _ in range(SMALL_CAP)]
        try:
            for raw in seated:
                assert raw.call(ReadRequest, *TICK_ADDRESS, 4)[2] == 0
            with Client(service.endpoint, timeout_s=SERVED_TIMEOUT_S) as cnc:
                with pytest.raises(ServiceFullError, match="connection table is full"):
                    cnc.read("cnc_tick_counter_r")
        finally:
            for raw in seated:
                raw.close()
        service.wait_for_log("connection table is full")


def test_a_keyed_zeromq_client_refused_for_a_full_table_is_not_told_of_its_key(
        tmp_path: Path) -> None:
    """With keys: a table full of keyed connections refuses a keyed newcomer; it is
    told the table is full, not an ``AuthenticationError`` about its key."""
    config = limits_toml(tmp_path / "c.toml", connections_per_front_end=SMALL_CAP)
    with serving("--config", str(config), keys=True) as service:
        assert service.keys is not None
        key = service.keys.client("monitor")
        with ExitStack() as stack:
            for _ in range(SMALL_CAP):
                stack.enter_context(Client(service.endpoint, key_file=key)).read(
                    "cnc_tick_counter_r")
            with Client(service.endpoint, key_file=key, timeout_s=SERVED_TIMEOUT_S) as cnc:
                with pytest.raises(ServiceFullError) as refused:
                    cnc.read("cnc_tick_counter_r")
        assert not isinstance(refused.value, AuthenticationError)
        assert "refused this client's key" not in str(refused.value)
        assert "connection table is full" in str(refused.value)


def test_idle_keyless_zeromq_connections_do_not_lock_out_a_key() -> None:
    """With keys: 70 TCP connections that never handshake fill the table; a client with
    a key of the allow-list is served at once (one of them gives way)."""
    with serving(keys=True) as service:
        assert service.keys is not None
        with Flood(_zmq_address(service.endpoint), IDLE, b""), \
                Client(service.endpoint, key_file=service.keys.client("monitor"),
                       timeout_s=SERVED_TIMEOUT_S) as cnc:
            assert cnc.read("cnc_tick_counter_r") >= 0


def test_idle_keyless_zeromq_connections_give_way_after_the_idle_time(tmp_path: Path) -> None:
    """Without keys: a table full of connections that completed their greeting and sent
    nothing gives a seat to a newcomer once they have been idle ``idle_connection_s``."""
    config = limits_toml(tmp_path / "c.toml", connections_per_front_end=SMALL_CAP,
                         idle_connection_s=0.5)
    with serving("--config", str(config)) as service:
        with Flood(_zmq_address(service.endpoint), SMALL_CAP, zmtp_greeting()) as idle:
            deadline = time.monotonic() + SERVED_TIMEOUT_S
            while True:  # refused (and told so) until the idle ones have been idle 0.5 s
                try:
                    with Client(service.endpoint, timeout_s=SERVED_TIMEOUT_S) as cnc:
                        assert cnc.read("cnc_tick_counter_r") >= 0
                    break
                except ServiceFullError:
                    assert time.monotonic() < deadline, "no idle connection gave way"
                    time.sleep(0.1)
            assert idle.closed_by_service() >= 1, service.log_text
