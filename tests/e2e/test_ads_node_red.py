"""Node-RED with an untouched ADS connection node reads, writes and subscribes (issue 41).

Node-RED 4 and node-red-contrib-ads-client (the ADS nodes Node-RED users install; it runs
ads-client 1.x) run headless against a real service, pinned in ``tests/ads_clients/
node_red`` (package.json, package-lock.json; ``npm ci`` installs them when missing, and
``.ci/run`` beforehand; without Node.js and npm the test is skipped, saying so).

The flow (``flows.json``) has one connection node whose only settings changed from the
editor's defaults are the router's address and TCP port: no local AMS Net ID, no local
ADS port, target ``localhost`` port 851. So ads-client first asks the router for an AMS
port (AMS/TCP port connect, 0x1000), as on a PC with TwinCAT; the service answers it
(``service/ads/connection.py``). HTTP endpoints of the flow (on Node-RED's own port, on
loopback) run a read node by name, a write node by name, and list what a subscribe node
delivered; the test checks them there and on the service with our own client.
"""

from __future__ import annotations

import json
import os
import subprocess
import time
import urllib.error
import urllib.parse
import urllib.request
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from cnc_objects.clients import Client
from cnc_objects.testing import ServiceProcess, start_service
from cnc_objects.testing.web import free_port
from tests.support.node_packages import node_with

NODE_RED_DIR = Path(__file__).resolve().parents[1] / "ads_clients" / "node_red"
START_TIMEOUT_S = 30.0  # Node-RED up and its ADS connection made
HTTP_TIMEOUT_S = 10.0
LENGTH = "gpCh[0].contour_lookahead.request.length"  # the write node's symbol (LREAL)
START = "gpCh[0].contour_lookahead.request.start_position"  # the subscribe node's (LREAL)


@pytest.fixture(scope="module")
def service(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServiceProcess]:
    """ADS on 127.0.0.1 (a free port): the AMS Net ID 127.0.0.1.1.1 that ads-client's
    default target ``localhost`` means, as a service started with its defaults has."""
    running = start_service(program_dir=tmp_path_factory.mktemp("node-red"), ads="127.0.0.1:0")
    yield running
    assert running.stop() == 0, running.log_text


class NodeRed:
    """A headless Node-RED on a free loopback port, userDir in a temporary directory."""

    def __init__(self, node: str, service: ServiceProcess, user_dir: Path) -> None:
        host, port = service.ads_address  # type: ignore[misc]
        flows = (NODE_RED_DIR / "flows.json").read_text()
        flows = flows.replace('"@ADS_HOST@"', json.dumps(host))
        flows = flows.replace('"@ADS_PORT@"', json.dumps(str(port)))
        (user_dir / "flows.json").write_text(flows)
        self.port = free_port()
        self.log = user_dir / "node-red.log"
        with self.log.open("w") as out:
            self.process = subprocess.Popen(
                [node, str(NODE_RED_DIR / "node_modules" / "node-red" / "red.js"),
                 "--settings", str(NODE_RED_DIR / "settings.js"), "--userDir", str(user_dir),
                 "--port", str(self.port), "flows.json"],
                cwd=user_dir, stdout=out, stderr=subprocess.STDOUT,
                env={**os.environ, "NODE_RED_ENABLE_PROJECTS": "false"})

    def get(self, path: str, body: Any = None) -> Any:
        """GET (POST with ``body``) an endpoint of the flow; its JSON answer."""
        data = None if body is None else json.dumps(body).encode()
        request = urllib.request.Request(
            f"http://127.0.0.1:{self.port}{path}", data=data,
            headers={"Content-Type": "application/json"})
        try:
            with urllib.request.urlopen(request, timeout=HTTP_TIMEOUT_S) as reply:
                return json.loads(reply.read())
        except urllib.error.HTTPError as exc:  # the flow answers a failed node with 500
            return {"http": exc.code, **json.loads(exc.read() or b"{}")}

    def wait_connected(self) -> None:
        """Poll the flow's status endpoint until the connection node is connected."""
        deadline = time.monotonic() + START_TIMEOUT_S
        last: Any = "Node-RED not answering"
        while time.monotonic() < deadline:
            assert self.process.poll() is None, f"Node-RED ended:\n{self.log.read_text()}"
            try:
                last = self.get("/cnc/status")
            except (OSError, ValueError) as exc:  # not listening yet
                last = exc
            else:
                if last["connected"]:
                    return
            time.sleep(0.1)  # a poll interval, not a wait for an event we could see
        raise AssertionError(f"not connected within {START_TIMEOUT_S:g} s: {last}\n"
                             f"{self.log.read_text()[-3000:]}")

    def wait_seen(self, value: float) -> list[Any]:
        """Poll what the subscription delivered until ``value`` is among it."""
        deadline = time.monotonic() + HTTP_TIMEOUT_S
        while True:
            seen: list[Any] = self.get("/cnc/seen")["seen"]
            if value in seen or time.monotonic() > deadline:
                return seen
            time.sleep(0.05)

    def stop(self) -> None:
        self.process.terminate()
        try:
            self.process.wait(timeout=HTTP_TIMEOUT_S)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()


@pytest.fixture
def node_red(service: ServiceProcess, tmp_path: Path) -> Iterator[NodeRed]:
    node = node_with(NODE_RED_DIR, "node-red-contrib-ads-client", "the Node-RED test")
    running = NodeRed(node, service, tmp_path)
    try:
        yield running
    finally:
        running.stop()


def test_an_untouched_connection_node_reads_writes_and_subscribes(
    node_red: NodeRed, service: ServiceProcess,
) -> None:
    node_red.wait_connected()  # ads-client registered an AMS port, then connected
    with Client(service.endpoint) as cnc:
        cnc.write(START, 1.5)
        cnc.write(LENGTH, 2.0)
        # read by name
        assert node_red.get("/cnc/read?name=ch1.mc_command_feed_override_r") == {
            "value": 1000, "type": "UINT"}
        assert node_red.get("/cnc/read?name=" + urllib.parse.quote(LENGTH))["value"] == 2.0
        # write by name: the value is in the kernel
        assert node_red.get("/cnc/write", {"value": 42.5}) == {"written": 42.5}
        assert cnc.read(LENGTH) == 42.5
        # subscribe by name: a change made by another client arrives
        assert 1.5 in node_red.wait_seen(1.5)
        cnc.write(START, 7.25)
        assert 7.25 in node_red.wait_seen(7.25)
    status = node_red.get("/cnc/status")
    assert status == {"connected": True, "errors": []}
    unknown = node_red.get("/cnc/read?name=no.such.symbol")
    assert unknown["http"] == 500 and "no.such.symbol" in unknown["error"]
