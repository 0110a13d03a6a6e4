"""Without keys only loopback is served: a non-loopback ZeroMQ address is refused (one
line, exit 2) unless ``--insecure``, and so is a non-loopback ADS address without routes.
With keys (ZeroMQ) or routes (ADS) the network is fine."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from cnc_objects.clients import Client
from cnc_objects.service.security import endpoint_is_local, host_is_loopback
from cnc_objects.testing import serving
from cnc_objects.testing.process import make_keys


def service_exit(*args: str, tmp_path: Path) -> subprocess.CompletedProcess[str]:
    """cnc-service with ``args`` that must end by itself (a refused start)."""
    return subprocess.run(
        [sys.executable, "-m", "cnc_objects.service.main", "--clock", "virtual",
         "--program-dir", str(tmp_path), *args],
        capture_output=True, text=True, timeout=60)


@pytest.mark.parametrize("endpoint, local", [
    ("tcp://127.0.0.1:5555", True), ("tcp://127.0.0.1:*", True), ("tcp://127.9.8.7:1", True),
    ("tcp://[::1]:5555", True), ("tcp://localhost:5555", True), ("tcp://lo:5555", True),
    ("ipc:///tmp/cnc.sock", True), ("inproc://cnc", True),
    ("tcp://*:5555", False), ("tcp://0.0.0.0:5555", False), ("tcp://192.0.2.2:5555", False),
    ("tcp://[::]:5555", False), ("tcp://eth0:5555", False), ("tcp://cnc.example:5555", False),
    ("pgm://eth0;239.192.1.1:5555", False), ("127.0.0.1:5555", False),
])
def test_which_endpoints_are_loopback(endpoint: str, local: bool) -> None:
    assert endpoint_is_local(endpoint) is local


def test_which_ads_hosts_are_loopback() -> None:
    assert all(host_is_loopback(h) for h in ("127.0.0.1", "127.1.2.3", "::1", "localhost"))
    assert not any(host_is_loopback(h) for h in ("0.0.0.0", "::", "192.0.2.2", "example"))


@pytest.mark.parametrize("endpoint", ["tcp://0.0.0.0:*", "tcp://*:*"])
def test_a_network_endpoint_without_keys_is_refused(endpoint: str, tmp_path: Path) -> None:
    refused = service_exit("--endpoint", endpoint, "--ads", "off", tmp_path=tmp_path)
    assert refused.returncode == 2
    assert refused.stderr.splitlines() == [
        f"cnc-service: {endpoint} is not a loopback address and no keys are given: anyone "
        "who reaches it could write every object; give --keys DIR (docs/security.md), bind "
        "127.0.0.1, or --insecure"]


def test_insecure_serves_a_network_endpoint_without_keys() -> None:
    with serving("--endpoint", "tcp://0.0.0.0:*", "--insecure") as service:
        port = service.endpoint.rsplit(":", 1)[1]
        with Client(f"tcp://127.0.0.1:{port}") as c:
            c.write("ch1.mc_command_feed_override_w", 500)  # no keys: may everything


def test_keys_serve_a_network_endpoint(tmp_path: Path) -> None:
    keys = make_keys(tmp_path)
    with serving("--endpoint", "tcp://0.0.0.0:*", "--keys", str(keys.directory)) as service:
        port = service.endpoint.rsplit(":", 1)[1]
        with Client(f"tcp://127.0.0.1:{port}", key_file=keys.client("operator")) as c:
            c.write("ch1.mc_command_feed_override_w", 500)


def test_a_network_ads_address_without_routes_is_refused(tmp_path: Path) -> None:
    refused = service_exit("--ads", "0.0.0.0:0", tmp_path=tmp_path)
    assert refused.returncode == 2
    assert refused.stderr.splitlines() == [
        "cnc-service: ADS address 0.0.0.0:0 is not a loopback address and [ads] has no "
        "routes: only loopback peers could be served; add [[ads.routes]] "
        "(docs/security.md), bind 127.0.0.1 (--ads 127.0.0.1), or --insecure"]
    config = tmp_path / "ads.toml"
    config.write_text('[ads]\nendpoint = "0.0.0.0:0"\n')
    from_config = service_exit("--config", str(config), tmp_path=tmp_path)
    assert from_config.returncode == 2 and "[ads] has no routes" in from_config.stderr


def test_a_network_ads_address_with_routes_or_insecure_is_served(tmp_path: Path) -> None:
    config = tmp_path / "routes.toml"
    config.write_text('[[ads.routes]]\nname = "hmi"\nnet_id = "198.51.100.7.1.1"\n'
                      'address = "198.51.100.7"\n')
    with serving("--config", str(config), ads="0.0.0.0:0") as routed:
        routed.wait_for_log(r"ADS on 0\.0\.0\.0:\d+, .*1 routes besides loopback, loopback "
                            r"role admin\)")
    with serving("--insecure", ads="0.0.0.0:0") as open_:
        open_.wait_for_log(r"ADS on 0\.0\.0\.0:\d+, .*every peer's role admin\)")
