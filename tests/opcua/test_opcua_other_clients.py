"""An OPC UA client no one here wrote, used unmodified against the real service: node-opcua
(npm, Node.js), the stack under Node-RED's OPC UA nodes and many plant gateways.

``tests/opcua_clients/node`` pins it (package.json, package-lock.json; node-opcua-client
2.180.0, the last release that runs on Debian's Node.js 20); ``check.js`` runs one check
per process and prints what the client saw as JSON. ``npm ci`` installs it when missing
(``.ci/run`` does it beforehand); without Node.js and npm the check is skipped, saying so
(``.ci/run`` installs Debian's nodejs and npm).
"""

from __future__ import annotations

import json
import subprocess
from pathlib import Path
from typing import Any

import pytest

from cnc_objects.testing import ServiceProcess
from tests.support.node_packages import node_with

from .conftest import opcua_url

NODE_DIR = Path(__file__).resolve().parents[1] / "opcua_clients" / "node"
CHECK_TIMEOUT_S = 180.0


@pytest.fixture(scope="session")
def node() -> str:
    """Node.js with node-opcua-client installed from the lock file (``npm ci`` when
    missing)."""
    return node_with(NODE_DIR, "node-opcua-client", "node-opcua")


def node_opcua(node: str, service: ServiceProcess, check: str) -> Any:
    """Run ``check.js CHECK URL`` (a fresh connection) and return what it saw."""
    ran = subprocess.run(
        [node, "check.js", check, opcua_url(service)], cwd=NODE_DIR, capture_output=True,
        text=True, timeout=CHECK_TIMEOUT_S, check=False)
    assert ran.returncode == 0, ran.stderr[-3000:]
    out = json.loads(ran.stdout.strip().splitlines()[-1])
    assert out["ok"], out.get("error")
    return out["result"]


def test_node_opcua_browses_everything_and_reads_every_variable(
        node: str, opcua_service: ServiceProcess) -> None:
    """The whole tree below Objects, every variable's Value read: all Good; the two
    models' entry points at the top, the nodeset's example instance gone; the channels
    READY (ActStatus 2 of CncChannelStatus), overrides 100 %, positions 0."""
    seen = node_opcua(node, opcua_service, "browse_read")
    assert seen["bad"] == []
    assert {"CncInterface", "Machines", "Server"} <= set(seen["top"])
    assert "test" not in seen["top"]
    assert seen["variables"] > 1000 and seen["nodes"] > seen["variables"]
    samples = seen["samples"]
    channels = {k: v for k, v in samples.items()
                if "/CncChannelList/" in k and not k.endswith("/ActPos")}
    assert channels == {
        "Objects/CncInterface/CncChannelList/Channel1/ActOverride": 100,
        "Objects/CncInterface/CncChannelList/Channel1/ActStatus": 2,
        "Objects/CncInterface/CncChannelList/Channel2/ActOverride": 100,
        "Objects/CncInterface/CncChannelList/Channel2/ActStatus": 2,
    }
    axes = [v for k, v in samples.items() if "/CncAxisList/" in k and k.endswith("/ActPos")]
    assert len(axes) == 12 and set(axes) == {0}  # 2 channels x 3 axes, direct and indirect
