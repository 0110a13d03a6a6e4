"""Port registration, byte by byte: the AMS/TCP commands a client without an AMS Net ID
sends to a TwinCAT router (ads-client and so Node-RED's ADS nodes, ads-rs' ``Source::
Request``), answered by the service as that router answers them (issue 41, item 1)::

    port connect   0x1000  length 2  wanted port u16   reply 0x1000, length 8: Net ID, port
    port close     0x0001  length 2  the port u16      no reply: the router ends the connection
    get Net ID     0x1002  length 4  (ignored)         reply 0x1002, length 6: the Net ID

The frames are built here with ``struct`` (no project code on this side of the socket).
Every wait is a socket read with a timeout; a release the service makes when a
connection ends is waited for by asking for the port again until it is granted.
"""

from __future__ import annotations

import struct
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from cnc_objects.testing import ServiceProcess, start_service
from tests.support.ads_raw import PLC, READ_STATE, REQUEST, RESPONSE, TIMEOUT_S, RawAds, _invoke_ids

PORT_CLOSE, PORT_CONNECT, ROUTER_NOTE, GET_LOCAL_NET_ID = 0x0001, 0x1000, 0x1001, 0x1002
FIRST_CLIENT_PORT = 32768
PORTS_PER_CONNECTION = 64


@pytest.fixture(scope="module")
def ads_service(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServiceProcess]:
    """A service of this module's own: which ports are free depends on its tests only."""
    running = start_service(program_dir=tmp_path_factory.mktemp("ports"), ads="127.0.0.1:0")
    yield running
    assert running.stop() == 0, running.log_text


def router_command(command: int, data: bytes) -> bytes:
    return struct.pack("<HI", command, len(data)) + data


def register(ads: RawAds, wanted: int = 0) -> tuple[bytes, int]:
    """Send a port connect; the AMS address the service's reply gives."""
    ads.sock.sendall(router_command(PORT_CONNECT, struct.pack("<H", wanted)))
    command, length = struct.unpack("<HI", ads._read(6))
    assert (command, length) == (PORT_CONNECT, 8)
    body = ads._read(8)
    return body[:6], struct.unpack_from("<H", body, 6)[0]


def read_state_from(ads: RawAds, net_id: bytes, port: int) -> tuple[bytes, int, int]:
    """A ReadState sent from ``net_id:port``: the reply's target address and ADS result."""
    invoke_id = next(_invoke_ids)
    ads.sock.sendall(struct.pack("<HI", 0, 32) + struct.pack(
        "<6sH6sHHHIII", ads.net_id, PLC, net_id, port, READ_STATE, REQUEST, 0, 0, invoke_id))
    got = ads.reply(invoke_id)
    assert got.flags == RESPONSE and got.source_net_id == ads.net_id
    return got.target_net_id, got.target_port, got.result


def close_port(ads: RawAds, port: int) -> None:
    """Port close; the service ends the connection with its last port."""
    ads.sock.sendall(router_command(PORT_CLOSE, struct.pack("<H", port)))
    assert ads.closed_by_peer()
    ads.close()


def granted_again(service: ServiceProcess, port: int) -> RawAds:
    """A connection that got ``port`` by asking for it, once the service has released it
    (a refused wish closes the asking connection: ask again on a new one)."""
    deadline = time.monotonic() + TIMEOUT_S
    while True:
        ads = RawAds(service)
        try:
            if register(ads, port)[1] == port:
                return ads
        except (ConnectionError, OSError):
            pass
        ads.close()
        assert time.monotonic() < deadline, f"port {port} was never released"


def test_a_client_gets_the_service_net_id_and_a_port_and_is_answered_there(
    ads_service: ServiceProcess,
) -> None:
    ads = RawAds(ads_service)
    try:
        net_id, port = register(ads)
        assert net_id == ads.net_id  # a local client of a TwinCAT router gets its Net ID
        assert FIRST_CLIENT_PORT <= port <= 0xFFFF
        assert read_state_from(ads, net_id, port) == (net_id, port, 0)
        close_port(ads, port)
    finally:
        ads.close()


def test_two_clients_get_different_ports_and_a_freed_port_is_handed_out_again(
    ads_service: ServiceProcess,
) -> None:
    first, second = RawAds(ads_service), RawAds(ads_service)
    _, port_1 = register(first)
    _, port_2 = register(second)
    assert port_1 != port_2
    close_port(first, port_1)
    third = RawAds(ads_service)
    _, port_3 = register(third)  # the lowest free port: the one given back
    assert port_3 == port_1
    assert read_state_from(second, second.net_id, port_2)[2] == 0  # untouched
    close_port(second, port_2)
    close_port(third, port_3)


def test_a_port_in_use_is_refused_and_freed_when_its_connection_ends(
    ads_service: ServiceProcess,
) -> None:
    holder = RawAds(ads_service)
    _, port = register(holder)
    rival = RawAds(ads_service)
    rival.sock.sendall(router_command(PORT_CONNECT, struct.pack("<H", port)))
    assert rival.closed_by_peer()  # as TwinCAT's router: the connection ends
    ads_service.wait_for_log(rf"port registration refused: port {port} is in use")
    rival.close()
    holder.close()  # no port close: the registration ends with the connection
    again = granted_again(ads_service, port)
    close_port(again, port)


def test_the_ports_of_one_connection_are_bounded(ads_service: ServiceProcess) -> None:
    ads = RawAds(ads_service)
    ports = {register(ads)[1] for _ in range(PORTS_PER_CONNECTION)}
    assert len(ports) == PORTS_PER_CONNECTION
    ads.sock.sendall(router_command(PORT_CONNECT, b"\x00\x00"))
    assert ads.closed_by_peer()
    ads_service.wait_for_log(r"port registration refused: this connection holds 64 ports")
    ads.close()


def test_a_served_port_cannot_be_registered(ads_service: ServiceProcess) -> None:
    ads = RawAds(ads_service)
    ads.sock.sendall(router_command(PORT_CONNECT, struct.pack("<H", PLC)))
    assert ads.closed_by_peer()
    ads_service.wait_for_log(r"port registration refused: port 851 is one the service serves")
    ads.close()


def test_get_local_net_id_and_unknown_router_commands(ads_service: ServiceProcess) -> None:
    ads = RawAds(ads_service)
    try:
        ads.sock.sendall(router_command(GET_LOCAL_NET_ID, bytes(4)))
        assert struct.unpack("<HI", ads._read(6)) == (GET_LOCAL_NET_ID, 6)
        assert ads._read(6) == ads.net_id
        ads.sock.sendall(router_command(ROUTER_NOTE, bytes(4)))  # router to client only
        ads.sock.sendall(router_command(0x2345, b"xy"))
        ads.sock.sendall(router_command(PORT_CLOSE, struct.pack("<H", 40000)))  # not ours
        assert ads.call(READ_STATE).result == 0  # skipped, and the connection goes on
        ads_service.wait_for_log(r"AMS/TCP command 0x1001 \(router note\) \(4 bytes\) is "
                                 r"not answered")
    finally:
        ads.close()


def test_a_routed_peer_may_not_register_a_port(tmp_path: Path, non_loopback_ipv4: str) -> None:
    """TwinCAT's router takes port registration on 127.0.0.1 only: a peer by route is
    another station, which sends from its route's AMS Net ID."""
    address = non_loopback_ipv4
    config = tmp_path / "routes.toml"
    config.write_text(f'[[ads.routes]]\nname = "hmi"\nnet_id = "{address}.1.1"\n'
                      f'address = "{address}"\n')
    routed = start_service("--config", str(config), program_dir=tmp_path / "store",
                           ads=f"{address}:0")
    try:
        ads = RawAds(routed)
        ads.sock.sendall(router_command(PORT_CONNECT, b"\x00\x00"))
        assert ads.closed_by_peer()
        routed.wait_for_log(rf"ADS connection from {address}:\d+ closed: AMS/TCP command "
                            r"0x1000 \(port connect\) is answered to clients on this machine")
        ads.close()
    finally:
        assert routed.stop() == 0, routed.log_text
