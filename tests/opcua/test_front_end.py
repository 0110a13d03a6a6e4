"""``cnc-service --opcua``: where it listens, off, an address in use, a bad URL, malformed
chunks."""

from __future__ import annotations

import asyncio
import socket
from pathlib import Path

import pytest
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


@pytest.mark.parametrize("garbage", [
    b"\x00" * 64,  # no message type at all
    b"HELF\xff\xff\xff\xff",  # a Hello that claims 4 GB
    b"HELF\x20\x00\x00\x00" + b"\x01" * 24,  # a Hello whose fields are nonsense
    b"MSGF\x10\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00",  # a message on no channel
    b"OPNF\x08\x00\x00\x00",  # an OpenSecureChannel cut short
])
async def test_malformed_chunks_leave_the_service_serving(
        opcua_service: ServiceProcess, garbage: bytes) -> None:
    host, port = opcua_url(opcua_service).removeprefix("opc.tcp://").rsplit(":", 1)
    reader, writer = await asyncio.open_connection(host, int(port))
    writer.write(garbage)
    await writer.drain()
    writer.write_eof()
    await asyncio.wait_for(reader.read(), 30)  # the server answers or closes; it goes on
    writer.close()
    async with Client(opcua_url(opcua_service), timeout=30) as client:
        assert "http://opcfoundation.org/UA/CNC" in await client.get_namespace_array()
    assert opcua_service.process.poll() is None
