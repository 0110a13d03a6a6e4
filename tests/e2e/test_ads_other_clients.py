"""ADS clients no one here wrote, used unmodified against the real service (issue 26).

Besides pyads (test_ads_pyads.py, test_ads_symbols_raw.py), two more implementations of
ADS talk to a service as they would to a TwinCAT 3 runtime, each check on a fresh
connection:

* jisotalo's ``ads-client`` (npm, Node.js), the library under Node-RED's ADS nodes: it
  follows TwinCAT 3's conventions (read lengths of 0xFFFFFFFF, extended handles,
  symbol version notifications, data types by name). ``tests/ads_clients/node`` pins it
  (package.json, package-lock.json); ``check.js`` runs one check per process and prints
  what the client saw as JSON. ``npm ci`` installs it when missing; without Node.js and
  npm the checks are skipped, saying so (``.ci/run`` installs Debian's nodejs and npm).
* ``py-ads-client`` (PyPI), a pure-Python client of its own (handles, typed symbols and
  structs, notifications); it has no symbol upload and no sum commands.
"""

from __future__ import annotations

import json
import subprocess
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from cnc_objects.testing import ServiceProcess, start_service
from tests.support.node_packages import node_with

NODE_DIR = Path(__file__).resolve().parents[1] / "ads_clients" / "node"
CHECK_TIMEOUT_S = 120.0
SYMBOLNOTFOUND, INVALIDACCESS = 0x710, 0x704


@pytest.fixture(scope="module")
def service(tmp_path_factory: pytest.TempPathFactory) -> Iterator[ServiceProcess]:
    """ADS on 127.0.0.<n>:48898: py-ads-client always dials port 48898."""
    running = start_service(program_dir=tmp_path_factory.mktemp("ads-clients"), ads=True)
    yield running
    assert running.stop() == 0, running.log_text


@pytest.fixture(scope="session")
def node() -> str:
    """Node.js with ads-client installed from the lock file (``npm ci`` when missing)."""
    return node_with(NODE_DIR, "ads-client", "ads-client")


def ads_client(node: str, service: ServiceProcess, check: str) -> Any:
    """Run ``check.js CHECK`` (a fresh connection) and return what it saw."""
    host, port = service.ads_address  # type: ignore[misc]
    ran = subprocess.run(
        [node, "check.js", check, host, str(port), service.ams_net_id], cwd=NODE_DIR,
        capture_output=True, text=True, timeout=CHECK_TIMEOUT_S, check=False)
    assert ran.returncode == 0, ran.stderr
    out = json.loads(ran.stdout.strip().splitlines()[-1])
    assert out["ok"], out.get("error")
    return out["result"]


# --------------------------------------------------------------------------- ads-client


def test_ads_client_reads_and_writes_by_name(node: str, service: ServiceProcess) -> None:
    seen = ads_client(node, service, "by_name")
    assert seen == {"override": 1000, "length": 12.5, "text": "cnc-objects 0.1.0"}


def test_ads_client_handles(node: str, service: ServiceProcess) -> None:
    seen = ads_client(node, service, "handles")
    assert seen["handle"] == {"size": 8, "dataType": "LREAL"}  # the TwinCAT 3 extended reply
    assert seen["value"] == 4.25
    assert seen["multi"] == [
        {"success": True, "code": 0, "dataType": "UINT"},
        {"success": False, "code": SYMBOLNOTFOUND},
    ]


def test_ads_client_whole_structs_and_arrays(node: str, service: ServiceProcess) -> None:
    seen = ads_client(node, service, "structs")
    assert seen["request"] == {"start_position": 3, "length": 7}
    assert set(seen["suspend"]) == {"command_w", "enable_w", "request_r", "state_r"}
    assert seen["axisNumbers"] == [1, 2, 3, 11, 12, 13]  # gpAx[i].head.log_ax_n_r
    assert seen["blocks"] == 32 and seen["blockKeys"][:3] == [
        "block_type", "_pad_0x0002", "block_number"]  # the padding the type lists (issue 41)
    assert seen["readOnly"]["code"] == INVALIDACCESS
    assert seen["spindleWrite"] == {"code": 0}  # Node-RED's {"override_w": 500} (issue 41)
    assert seen["spindle"] == {"mode_r": 1, "override_w": 500}


def test_ads_client_notifications_of_a_member_and_its_struct(
    node: str, service: ServiceProcess,
) -> None:
    seen = ads_client(node, service, "notifications")
    assert seen["leaf"] == 99.5 and seen["struct"]["length"] == 99.5


def test_ads_client_sum_commands(node: str, service: ServiceProcess) -> None:
    seen = ads_client(node, service, "sum")
    assert seen["reads"] == [{"success": True, "size": 2}, {"success": True, "size": 16}]
    assert seen["writes"] == [0, INVALIDACCESS]
    assert seen["startPosition"] == 8.5
    assert seen["byName"] == [{"code": 0, "data": [0xE8, 0x03]}, {"code": SYMBOLNOTFOUND, "data": None}]


def test_ads_client_uploads_then_reads_every_symbol(node: str, service: ServiceProcess) -> None:
    seen = ads_client(node, service, "upload_read_all")
    assert seen["failed"] == []
    assert seen["read"] == seen["count"] > 1004  # the objects and the HLI's structs


def test_ads_client_unknown_names_are_0x710(node: str, service: ServiceProcess) -> None:
    seen = ads_client(node, service, "unknown_name")
    assert {what: got["code"] for what, got in seen.items()} == {
        "read": SYMBOLNOTFOUND, "handle": SYMBOLNOTFOUND, "symbol": SYMBOLNOTFOUND}


def test_ads_client_writes_to_read_only_are_0x704(node: str, service: ServiceProcess) -> None:
    seen = ads_client(node, service, "read_only_write")
    assert seen["leaf"]["code"] == INVALIDACCESS and seen["stillThere"] == 1000


def test_ads_client_without_a_local_address_registers_a_port(
    node: str, service: ServiceProcess,
) -> None:
    """ads-client 2 with no local AMS Net ID asks the router for a port (issue 41)."""
    seen = ads_client(node, service, "registered")
    assert seen["localAmsNetId"] == service.ams_net_id  # the router's own, as TwinCAT's
    assert 32768 <= seen["localAdsPort"] <= 65535
    assert seen["override"] == 1000
    assert seen["disconnectMs"] < 5000  # the port close ends the connection, no timeout


# --------------------------------------------------------------------------- py-ads-client


@pytest.fixture
def py_ads(service: ServiceProcess) -> Iterator[Any]:
    """A fresh py-ads-client connection to port 851."""
    py_ads_client = pytest.importorskip("py_ads_client")
    host, _ = service.ads_address  # type: ignore[misc]
    client = py_ads_client.ADSClient(local_ams_net_id="127.0.0.1.1.41")
    client.open(target_ip=host, target_ams_net_id=service.ams_net_id)
    yield client
    client.close()


def test_py_ads_client_by_name_and_handles(py_ads: Any) -> None:
    from py_ads_client import LREAL, UINT, ADSSymbol

    assert py_ads.read_symbol(ADSSymbol("ch1.mc_command_feed_override_r", UINT)) == 1000
    length = ADSSymbol("gpCh[0]^.contour_lookahead.request.length", LREAL)
    py_ads.write_symbol(length, 6.5)
    assert py_ads.read_symbol(length) == 6.5
    handle = py_ads.get_handle_by_name("gpCh[0].contour_lookahead.request.length")
    assert py_ads.read_value_by_handle(handle, 8) == b"\x00\x00\x00\x00\x00\x00\x1a@"
    py_ads.release_handle(handle)


def test_py_ads_client_whole_structs(py_ads: Any) -> None:
    from py_ads_client import BOOL, LREAL, STRUCT, ADSSymbol

    request = ADSSymbol("gpCh[0].contour_lookahead.request",
                        STRUCT([("start_position", LREAL), ("length", LREAL)]))
    py_ads.write_symbol(request, {"start_position": 1.5, "length": 2.5})
    assert py_ads.read_symbol(request) == {"start_position": 1.5, "length": 2.5}
    unit = ADSSymbol("gpCh[1].bahn_mc_control.suspend_axis_output", STRUCT(
        [("command_w", BOOL), ("enable_w", BOOL), ("request_r", BOOL), ("state_r", BOOL)]))
    assert set(py_ads.read_symbol(unit)) == {"command_w", "enable_w", "request_r", "state_r"}


def test_py_ads_client_notifications(py_ads: Any) -> None:
    from py_ads_client import LREAL, ADSSymbol

    length = ADSSymbol("gpCh[1].contour_lookahead.request.length", LREAL)
    py_ads.add_device_notification(length, cycle_time_ms=10)
    first = py_ads.device_notification_queue.get(timeout=10)[2]
    py_ads.write_symbol(length, first + 1.0)
    assert py_ads.device_notification_queue.get(timeout=10)[2] == first + 1.0
    py_ads.del_device_notification(length)


def test_py_ads_client_unknown_names_and_read_only_writes(py_ads: Any) -> None:
    from py_ads_client import UINT, ADSSymbol

    with pytest.raises(RuntimeError, match="SYMBOLNOTFOUND"):
        py_ads.read_symbol(ADSSymbol("gpCh[0].no_such_member", UINT))
    with pytest.raises(RuntimeError, match="INVALIDACCESS"):
        py_ads.write_symbol(ADSSymbol("ch1.mc_command_feed_override_r", UINT), 5)
    assert py_ads.read_symbol(ADSSymbol("ch1.mc_command_feed_override_r", UINT)) == 1000
