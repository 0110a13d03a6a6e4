"""``cnc-service --opcua``: where it listens, off, an address in use, a bad URL."""

from __future__ import annotations

import socket
from pathlib import Path

from asyncua import Client

from cnc_objects.testing import ServiceProcess, serving
from tests.opcua.conftest import opcua_url
from tests.support.entry_point import run_service


async def test_the_service_serves_opc_ua_and_says_where(opcua_service: ServiceProcess) -> None:
    url = opcua_url(opcua_service)
    async with Client(url, timeout=30) as client:
        names = await client.get_namespace_array()
    assert "http://opcfoundation.org/UA/CNC" in names
    assert "http://opcfoundation.org/UA/MachineTool/" in names
    # the OPC UA line comes before the ZeroMQ one, the last start-up line
    lines = opcua_service.log
    opcua = next(k for k, line in enumerate(lines) if "OPC UA on" in line)
    assert opcua < next(k for k, line in enumerate(lines) if "listening on tcp://" in line)


def test_opcua_off_serves_none() -> None:
    with serving("--opcua", "off") as service:
        assert not any("OPC UA on" in line for line in service.log)


def test_an_opcua_port_in_use_is_refused(tmp_path: Path) -> None:
    with socket.socket() as taken:
        taken.bind(("127.0.0.1", 0))
        taken.listen()
        port = taken.getsockname()[1]
        done = run_service("--clock", "virtual", "--ads", "off", "--endpoint",
                           "tcp://127.0.0.1:*", "--program-dir", str(tmp_path / "p"),
                           "--opcua", f"opc.tcp://127.0.0.1:{port}")
    assert done.returncode == 2, done.stderr
    assert f"cannot listen for OPC UA on 127.0.0.1:{port}" in done.stderr


def test_a_bad_opcua_url_is_refused(tmp_path: Path) -> None:
    for url, says in (("tcp://127.0.0.1:4840", "must begin with opc.tcp://"),
                      ("opc.tcp://127.0.0.1:99999", "out of range"),
                      ("opc.tcp://0.0.0.0:4840", "not a loopback address")):
        done = run_service("--clock", "virtual", "--ads", "off", "--program-dir",
                           str(tmp_path / "p"), "--opcua", url)
        assert done.returncode == 2, (url, done.stderr)
        assert says in done.stderr, (url, done.stderr)
