"""A service with OPC UA and the asyncua client helpers the OPC UA tests of the machine
node share (MachineTool, alarm events, channel methods)."""

from __future__ import annotations

import asyncio
import contextlib
import re
from collections.abc import AsyncIterator, Callable, Iterator
from pathlib import Path
from typing import Any

from asyncua import Client, Node, ua

from cnc_objects.testing import ServiceProcess, serving

MACHINERY_URI = "http://opcfoundation.org/UA/Machinery/"
START_TIMEOUT_S = 90.0  # the nodesets and instances take seconds on a busy machine
WAIT_S = 30.0
Running = tuple[ServiceProcess, str]  # a service with OPC UA and its opc.tcp URL


@contextlib.contextmanager
def serving_opcua(work: Path, toml: str = "") -> Iterator[tuple[ServiceProcess, str]]:
    """A service with OPC UA on a free loopback port (``toml``: its configuration)."""
    args = ["--opcua", "opc.tcp://127.0.0.1:0"]
    if toml:
        (work / "machine.toml").write_text(toml)
        args += ["--config", str(work / "machine.toml")]
    with serving(*args, program_dir=work / "programs", timeout_s=START_TIMEOUT_S) as service:
        line = service.wait_for_log(r"OPC UA on opc\.tcp://")
        found = re.search(r"OPC UA on (opc\.tcp://\S+) ", line)
        assert found is not None, line
        yield service, found.group(1)


@contextlib.asynccontextmanager
async def connected(url: str) -> AsyncIterator[Client]:
    client = Client(url, timeout=WAIT_S)
    async with client:
        yield client


async def machine_node(client: Client) -> Node:
    """Objects/Machines/<the one machine>."""
    machinery = await client.get_namespace_index(MACHINERY_URI)
    machines = await client.nodes.objects.get_child(f"{machinery}:Machines")
    [node] = await machines.get_children()
    return node


async def child(node: Node, *names: str) -> Node:
    """The descendant of ``node`` browsed as ``names`` (any namespace)."""
    for name in names:
        found = {(await c.read_browse_name()).Name: c for c in await node.get_children()}
        assert name in found, f"{name} not under {node}: {sorted(found)}"
        node = found[name]
    return node


class Changes:
    """Data changes of subscribed variables, by node."""

    def __init__(self) -> None:
        self.values: dict[ua.NodeId, list[Any]] = {}
        self.changed = asyncio.Condition()

    async def datachange_notification(self, node: Node, value: Any, data: Any) -> None:
        async with self.changed:
            self.values.setdefault(node.nodeid, []).append(value)
            self.changed.notify_all()

    async def wait(self, node: Node, test: Callable[[Any], bool]) -> Any:
        """The first value of ``node`` (seen or to come) that passes ``test``."""
        async with asyncio.timeout(WAIT_S), self.changed:
            while True:
                for value in self.values.get(node.nodeid, []):
                    if test(value):
                        return value
                await self.changed.wait()
