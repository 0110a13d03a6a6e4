"""cnc-mqtt killed, and the last will its broker publishes."""

from __future__ import annotations

import asyncio
import os
import signal
import subprocess
import sys
import tempfile

from tests.support.broker import OFFLINE, ONLINE, Broker, Watcher
from tests.support.service import ROOT


def start_bridge(endpoint: str, broker: Broker, machine: str, *args: str) -> subprocess.Popen:
    """``cnc-mqtt`` in a subprocess (its log goes to a temporary file). It trusts the
    broker's test certificate, if any, through ``$SSL_CERT_FILE``."""
    log = tempfile.TemporaryFile(mode="w+")
    env = dict(os.environ)
    if broker.cert_file is not None:
        env["SSL_CERT_FILE"] = str(broker.cert_file)
    return subprocess.Popen(
        [sys.executable, "-m", "cnc_objects.clients.mqtt.cli", "--endpoint", endpoint,
         "--broker", f"{broker.host}:{broker.port}", "--machine", machine, *args],
        cwd=ROOT, stdout=subprocess.DEVNULL, stderr=log, env=env,
    )


async def exit_code(process: subprocess.Popen, timeout_s: float = 10.0) -> int:
    """Wait for the process without blocking the event loop (the broker may live in it)."""
    return await asyncio.to_thread(process.wait, timeout_s)


async def kill_and_see_the_last_will(endpoint: str, broker: Broker, machine: str) -> None:
    """Start a bridge of ``machine``, wait for ``online``, SIGKILL it and wait for the
    broker's last will (``offline``)."""
    status = f"cnc/{machine}/status"
    async with Watcher(broker, status) as watcher:
        process = start_bridge(endpoint, broker, machine, "--objects", "ch1.mc_active_state_r")
        try:
            await watcher.wait_for(status, ONLINE, timeout_s=30)
            mark = watcher.mark()
        finally:
            process.kill()  # SIGKILL: no DISCONNECT, no "offline" of its own
            assert await exit_code(process) == -signal.SIGKILL
        await watcher.wait_for(status, OFFLINE, since=mark)
