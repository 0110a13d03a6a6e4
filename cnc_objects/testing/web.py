"""Start ``cnc-web`` for tests, the screenshot script and the benchmark.

    with serving_web(service.endpoint) as web:      # a free loopback port
        urllib.request.urlopen(web.url + "/api/session")

``users_file``: the web users file (sign-in); ``key``/``server_key``: the web server's
CURVE keys for a service with keys. The process is stopped with SIGINT on leaving.
"""

from __future__ import annotations

import contextlib
import os
import socket
import subprocess
import sys
import time
import urllib.error
import urllib.request
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

START_TIMEOUT_S = 20.0
STOP_TIMEOUT_S = 10.0


@dataclass
class WebProcess:
    """A running cnc-web: its process and base URL (``http://127.0.0.1:PORT``)."""

    process: subprocess.Popen[bytes]
    url: str

    def stop(self) -> int:
        """End it (SIGINT, then kill) and return its exit code."""
        if self.process.poll() is None:
            self.process.send_signal(2)
            try:
                return self.process.wait(STOP_TIMEOUT_S)
            except subprocess.TimeoutExpired:
                self.process.kill()
        return self.process.wait()


def free_port() -> int:
    """A TCP port free on loopback now."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


def start_web(endpoint: str, *, users_file: str | os.PathLike[str] | None = None,
              key: str | os.PathLike[str] | None = None,
              server_key: str | os.PathLike[str] | None = None,
              cwd: str | os.PathLike[str] | None = None, port: int | None = None,
              args: tuple[str, ...] = ()) -> WebProcess:
    """Start cnc-web for the service at ``endpoint`` on ``port`` (default: a free loopback
    port), with further options ``args`` (``("--watch-per-page", "5")``); returns once it
    answers HTTP (``RuntimeError`` with its output when it exits first)."""
    port = port if port is not None else free_port()
    argv = [sys.executable, "-m", "cnc_objects.clients.web.cli", "--endpoint", endpoint,
            "--port", str(port), "--log-level", "WARNING"]
    if users_file is not None:
        argv += ["--users", os.fspath(users_file)]
    if key is not None:
        argv += ["--key", os.fspath(key)]
    if server_key is not None:
        argv += ["--server-key", os.fspath(server_key)]
    argv += args
    log = open(Path(os.environ.get("TMPDIR", "/tmp")) / f"cnc-web-{port}.log", "w+b")
    process = subprocess.Popen(argv, cwd=cwd, stdin=subprocess.DEVNULL, stdout=log,
                               stderr=subprocess.STDOUT)
    web = WebProcess(process, f"http://127.0.0.1:{port}")
    deadline = time.monotonic() + START_TIMEOUT_S
    while time.monotonic() < deadline:
        if process.poll() is not None:
            log.seek(0)
            raise RuntimeError(f"cnc-web exited with {process.returncode}:\n"
                               f"{log.read().decode(errors='replace')}")
        try:
            with urllib.request.urlopen(web.url + "/api/session", timeout=2):
                return web
        except (urllib.error.URLError, ConnectionError, TimeoutError):
            time.sleep(0.1)  # polling a process that is starting: nothing to wait on
    web.stop()
    raise TimeoutError(f"cnc-web did not answer within {START_TIMEOUT_S:g} s")


@contextlib.contextmanager
def serving_web(endpoint: str, **options: Any) -> Iterator[WebProcess]:
    """``start_web`` for a ``with`` block; stopped on leaving."""
    web = start_web(endpoint, **options)
    try:
        yield web
    finally:
        web.stop()
