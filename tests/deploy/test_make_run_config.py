"""``make run CONFIG=file``: the Makefile hands the file to cnc-service, and the README
says so. The test runs ``make run`` as a user would (WEB=0, a free endpoint, no ADS) and
reads the configuration back as objects over the wire."""

from __future__ import annotations

import os
import shutil
import signal
import socket
import subprocess
import time
from pathlib import Path

import pytest

from cnc_objects.clients import Client
from tests.support.service import ROOT

START_TIMEOUT_S = 120.0  # make checks the venv first; the service then starts


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port: int = s.getsockname()[1]
        return port


def _read_when_up(endpoint: str, name: str, proc: subprocess.Popen[str]) -> object:
    """``name`` read from the service as soon as it answers (it may still be starting)."""
    deadline = time.monotonic() + START_TIMEOUT_S
    while time.monotonic() < deadline:
        assert proc.poll() is None, proc.communicate()[1]
        try:
            with Client(endpoint, timeout_s=2) as c:
                return c.read(name)
        except (TimeoutError, OSError):
            continue  # not listening yet: the request timed out
    raise AssertionError(f"make run did not answer within {START_TIMEOUT_S} s")


@pytest.mark.skipif(shutil.which("make") is None, reason="make is not installed")
def test_make_run_config_starts_the_service_on_that_file(tmp_path: Path) -> None:
    config = tmp_path / "plc.toml"
    config.write_text('[plc]\nacknowledges = ["M6", "M8", "M9"]\n')
    endpoint = f"tcp://127.0.0.1:{_free_port()}"
    proc = subprocess.Popen(
        ["make", "run", "WEB=0", f"CONFIG={config}", f"ENDPOINT={endpoint}", "ADS=off", "OPCUA=off",
         f"DATA_DIR={tmp_path / 'data'}"],
        cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
        start_new_session=True)
    try:
        assert _read_when_up(endpoint, "cnc_plc_acknowledges_r", proc) == "M6 M8 M9"
    finally:
        os.killpg(proc.pid, signal.SIGINT)  # make and the service it started
        proc.communicate(timeout=60)
    readme = (ROOT / "README.md").read_text()
    assert "make run CONFIG=" in readme
    assert "CONFIG" in (ROOT / "Makefile").read_text()
