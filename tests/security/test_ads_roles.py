"""Roles over ADS (AMS/TCP): a route's role, the loopback role, and ``--insecure``.

ADS peers are told apart by route (``[[ads.routes]] role = ...``, operator by default);
loopback peers get ``[ads] loopback_role``: admin by default, monitor when the service
runs with keys. The same dispatcher decides as for ZeroMQ: a request beyond the role is
answered ADS 0x704 and the connection stays. Frames are built by hand from Beckhoff's
layout (AMS/TCP header, 32-byte AMS header, the command's data) by the raw client of
tests/e2e/test_ads_raw.py.
"""

from __future__ import annotations

import struct
from pathlib import Path

from cnc_objects.testing import ServiceProcess, serving
from tests.support.ads_raw import COM, READ, READ_WRITE, WRITE, RawAds, read, read_write, write

CH1_COM = 0x120101
FEED_W, FEED_R = 0x09, 0x0C  # ch1 feed override, commanded and active (UNS16)
PROGRAM_STORE, UPLOAD = 0x150000, 2
SUM_WRITE = 0xF081
INVALIDACCESS = 0x704


def net_id(text: str) -> bytes:
    return bytes(int(p) for p in text.split("."))


class Ams(RawAds):
    """One TCP connection to the service's ADS port (from the local address ``source``),
    sending to the COM port from any Net ID."""

    def __init__(self, service: ServiceProcess, source: str = "127.0.0.1") -> None:
        super().__init__(service, source_address=source)

    def call_from(self, source: bytes, command: int, data: bytes) -> tuple[int, bytes]:
        """(ADS result, the reply's data after the result) of a request from ``source``."""
        got = self.call(command, data, COM, source=source)
        assert got.error == 0
        return got.result, got.data[4:]

    def read_feed(self, source: bytes) -> int:
        result, data = self.call_from(source, READ, read(CH1_COM, FEED_R, 2))
        assert result == 0
        return struct.unpack("<IH", data)[1]

    def write_feed(self, source: bytes, value: int) -> int:
        return self.call_from(source, WRITE, write(CH1_COM, FEED_W, struct.pack("<H", value)))[0]

    def upload(self, source: bytes, name: bytes) -> int:
        return self.call_from(source, WRITE,
                              write(PROGRAM_STORE, UPLOAD, name + b"\x00" + b"N10 M30\n"))[0]

    def sum_write_feeds(self, source: bytes, values: list[int]) -> list[int]:
        head = b"".join(struct.pack("<III", CH1_COM, FEED_W, 2) for _ in values)
        data = head + b"".join(struct.pack("<H", v) for v in values)
        result, reply = self.call_from(
            source, READ_WRITE, read_write(SUM_WRITE, len(values), 4 * len(values), data))
        assert result == 0
        return list(struct.unpack_from(f"<{len(values)}I", reply, 4))


def test_each_route_has_its_role(tmp_path: Path, non_loopback_ipv4: str) -> None:
    address = non_loopback_ipv4
    config = tmp_path / "routes.toml"
    config.write_text(
        f'[[ads.routes]]\nname = "panel"\nnet_id = "{address}.1.1"\naddress = "{address}"\n'
        'role = "monitor"\n'
        f'[[ads.routes]]\nname = "plc"\nnet_id = "{address}.1.2"\naddress = "{address}"\n')
    panel, plc = net_id(f"{address}.1.1"), net_id(f"{address}.1.2")
    with serving("--config", str(config), ads=f"{address}:0") as service:
        ams = Ams(service, source=address)
        try:
            before = ams.read_feed(panel)
            assert ams.write_feed(panel, 123) == INVALIDACCESS
            assert ams.sum_write_feeds(panel, [124, 125]) == [INVALIDACCESS, INVALIDACCESS]
            assert ams.read_feed(panel) == before  # refused, and the connection stays
            assert ams.write_feed(plc, 321) == 0  # the default role of a route: operator
            assert ams.read_feed(panel) == 321
            assert ams.sum_write_feeds(plc, [322]) == [0]
            assert ams.upload(plc, b"route.nc") == INVALIDACCESS  # the store: admin only
        finally:
            ams.close()


def test_loopback_is_admin_without_keys_and_monitor_with_keys(tmp_path: Path) -> None:
    with serving(ads=True) as plain:
        ams = Ams(plain)
        try:
            assert ams.write_feed(bytes(6), 500) == 0
            assert ams.upload(bytes(6), b"loopback.nc") == 0
        finally:
            ams.close()
    with serving(ads=True, keys=True) as keyed:
        keyed.wait_for_log(r"loopback role monitor\)")
        ams = Ams(keyed)
        try:
            assert ams.read_feed(bytes(6)) == 1000
            assert ams.write_feed(bytes(6), 500) == INVALIDACCESS
            assert ams.read_feed(bytes(6)) == 1000
        finally:
            ams.close()


def test_the_loopback_role_is_configurable(tmp_path: Path) -> None:
    config = tmp_path / "loopback.toml"
    config.write_text('[ads]\nloopback_role = "operator"\n')
    with serving("--config", str(config), ads=True, keys=True) as service:
        ams = Ams(service)
        try:
            assert ams.write_feed(bytes(6), 600) == 0
            assert ams.upload(bytes(6), b"operator.nc") == INVALIDACCESS
        finally:
            ams.close()


def test_insecure_serves_every_peer_as_loopback(non_loopback_ipv4: str) -> None:
    address = non_loopback_ipv4
    with serving("--insecure", ads=f"{address}:0") as service:
        ams = Ams(service, source=address)
        try:
            assert ams.write_feed(net_id("10.1.2.3.1.1"), 700) == 0  # any Net ID, no route
        finally:
            ams.close()
