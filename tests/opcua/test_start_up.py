"""The imported address space is kept: a second start loads it, a damaged one is
imported again, and the service serves the same CncInterface either way."""

from __future__ import annotations

import asyncio
import os
import subprocess
import sys
from pathlib import Path

import pytest
from asyncua import Client

from cnc_objects.testing import serving
from tests.opcua.conftest import OPCUA_ANY_PORT, OPCUA_START_S, cnc_node, opcua_url


async def _channels(url: str) -> list[str]:
    async with Client(url, timeout=30) as client:
        node = await cnc_node(client, "CncInterface", "CncChannelList")
        return sorted([(await c.read_browse_name()).Name for c in await node.get_children()])


async def test_a_second_start_loads_the_kept_address_space(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CNC_OPCUA_CACHE_DIR", str(tmp_path))
    seen = []
    for says in ("nodesets imported, keeping them in", "nodesets from",
                 "nodesets imported, keeping them in"):
        with serving(*OPCUA_ANY_PORT, timeout_s=OPCUA_START_S) as service:
            line = service.wait_for_log("OPC UA on")
            assert f"{says} {tmp_path}" in line, line
            seen.append(await _channels(opcua_url(service)))
            if says != "nodesets from":  # a thread keeps the import while it serves
                service.wait_for_log(f"imported address space kept in {tmp_path}")
        if says == "nodesets from":
            [kept] = tmp_path.glob("address-space-*.pickle")
            kept.write_bytes(b"damaged")  # the third start imports again
    assert seen == [["Channel1", "Channel2"]] * 3


def test_the_nodesets_imported_at_installation_make_the_first_start_warm(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setenv("CNC_OPCUA_CACHE_DIR", str(tmp_path))
    prepare = [sys.executable, "-m", "cnc_objects.service.opcua.prepare"]
    first = subprocess.run(prepare, capture_output=True, text=True, timeout=OPCUA_START_S)
    assert first.returncode == 0, first.stderr
    assert first.stdout.startswith(f"OPC UA address space kept in {tmp_path}/address-space-")
    again = subprocess.run(prepare, capture_output=True, text=True, timeout=OPCUA_START_S)
    assert again.stdout.startswith(f"OPC UA address space already kept in {tmp_path}")
    with serving(*OPCUA_ANY_PORT, timeout_s=OPCUA_START_S) as service:
        assert f"nodesets from {tmp_path}" in service.wait_for_log("OPC UA on")
        assert asyncio.run(_namespaces(opcua_url(service)))[:3] == [
            "http://opcfoundation.org/UA/", "urn:cnc-objects:service",
            "http://opcfoundation.org/UA/DI/"]
        assert asyncio.run(_channels(opcua_url(service))) == ["Channel1", "Channel2"]


def test_a_cache_that_cannot_be_written_is_one_line_and_exit_1(tmp_path: Path) -> None:
    blocked = tmp_path / "a-file"
    blocked.write_text("not a directory")
    done = subprocess.run([sys.executable, "-m", "cnc_objects.service.opcua.prepare"],
                          capture_output=True, text=True, timeout=OPCUA_START_S,
                          env={**os.environ, "CNC_OPCUA_CACHE_DIR": str(blocked / "opcua")})
    assert done.returncode == 1
    assert done.stderr.startswith(f"cannot keep the OPC UA address space in {blocked}/opcua/")
    assert len(done.stderr.splitlines()) == 1


async def _namespaces(url: str) -> list[str]:
    async with Client(url, timeout=30) as client:
        names: list[str] = await client.get_namespace_array()
        return names
