"""The imported address space is kept: a second start loads it, a damaged one is
imported again, and the service serves the same CncInterface either way."""

from __future__ import annotations

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
    for says in ("nodesets imported, kept in", "nodesets from", "nodesets imported, kept in"):
        with serving(*OPCUA_ANY_PORT, timeout_s=OPCUA_START_S) as service:
            line = service.wait_for_log("OPC UA on")
            assert f"{says} {tmp_path}" in line, line
            seen.append(await _channels(opcua_url(service)))
        if says == "nodesets from":
            [kept] = tmp_path.glob("address-space-*.pickle")
            kept.write_bytes(b"damaged")  # the third start imports again
    assert seen == [["Channel1", "Channel2"]] * 3
