"""OPC UA is served from a process of its own (issue 40, docs/opcua.md "One process of its
own"): a child of cnc-service that listens on the OPC UA port, ends with the service, and
is started again, where it listened, when it dies."""

from __future__ import annotations

import os
import re
import select
import signal
from pathlib import Path

from asyncua import Client

from cnc_objects.testing import ServiceProcess, serving
from cnc_objects.testing.process import start_service
from tests.opcua.conftest import OPCUA_ANY_PORT, OPCUA_START_S, cnc_node

_PROCESS = re.compile(r"OPC UA on (opc\.tcp://\S+).*process (\d+)\)")


def _served_by(line: str) -> tuple[str, int]:
    """The URL and the process a start-up line of OPC UA names."""
    found = _PROCESS.search(line)
    assert found is not None, line
    return found.group(1), int(found.group(2))


def _parent_of(pid: int) -> int:
    """The parent process id of ``pid`` (/proc/PID/stat, the field after the state)."""
    stat = Path(f"/proc/{pid}/stat").read_text()
    return int(stat[stat.rindex(")") + 2:].split()[1])


def _listening_sockets(pid: int) -> set[str]:
    """The socket inodes ``pid`` holds open."""
    inodes = set()
    for fd in Path(f"/proc/{pid}/fd").iterdir():
        target = os.readlink(fd)
        if target.startswith("socket:["):
            inodes.add(target[len("socket:["):-1])
    return inodes


def _listener_inode(port: int) -> str:
    """The inode of the loopback TCP socket listening on ``port`` (/proc/net/tcp)."""
    for line in Path("/proc/net/tcp").read_text().splitlines()[1:]:
        fields = line.split()
        if int(fields[1].rsplit(":", 1)[1], 16) == port and fields[3] == "0A":  # LISTEN
            return fields[9]
    raise AssertionError(f"nothing listens on port {port}")


async def _channel_ids(url: str) -> list[int]:
    async with Client(url, timeout=30) as client:
        channels = await cnc_node(client, "CncInterface", "CncChannelList")
        ids = []
        for channel in await channels.get_children():
            ns = channel.nodeid.NamespaceIndex
            ids.append(await (await channel.get_child(f"{ns}:Id")).read_value())
        return sorted(ids)


def _serves_in_child(service: ServiceProcess, line: str) -> tuple[str, int]:
    url, pid = _served_by(line)
    assert pid != service.process.pid
    assert _parent_of(pid) == service.process.pid
    port = int(url.rsplit(":", 1)[1])
    inode = _listener_inode(port)
    assert inode in _listening_sockets(pid)  # the child listens, not the service
    assert inode not in _listening_sockets(service.process.pid)
    return url, pid


async def test_opcua_is_served_by_a_child_that_ends_with_the_service() -> None:
    with serving(*OPCUA_ANY_PORT, timeout_s=OPCUA_START_S) as service:
        url, pid = _serves_in_child(service, service.wait_for_log("OPC UA on"))
        assert await _channel_ids(url) == [1, 2]  # the objects, through the service
        assert service.stop() == 0
    assert not Path(f"/proc/{pid}").exists()  # stopped and reaped by the service


async def test_a_child_that_dies_is_started_again_where_it_listened() -> None:
    with serving(*OPCUA_ANY_PORT, timeout_s=OPCUA_START_S) as service:
        url, first = _served_by(service.wait_for_log("OPC UA on"))
        os.kill(first, signal.SIGKILL)
        line = service.wait_for_log(r"OPC UA on \S+ again", timeout_s=OPCUA_START_S)
        again, second = _serves_in_child(service, line)
        assert second != first
        assert again == url  # clients reconnect where they were
        assert "the OPC UA process ended (exit code -9): starting it again" in service.log_text
        assert await _channel_ids(again) == [1, 2]
        assert service.process.poll() is None


def test_a_child_whose_service_is_killed_ends() -> None:
    service = start_service(*OPCUA_ANY_PORT, timeout_s=OPCUA_START_S)
    try:
        _, pid = _served_by(service.wait_for_log("OPC UA on"))
        ended = os.pidfd_open(pid)  # readable once the process has ended
        try:
            service.process.kill()  # no chance to stop its child
            assert select.select([ended], [], [], 30.0)[0] == [ended], "the child goes on"
        finally:
            os.close(ended)
    finally:
        assert service.stop() == -signal.SIGKILL
