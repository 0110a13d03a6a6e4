"""The dead-man of jogging (issue 36, point 2): a jog key is held only while the
connection that pressed it lives and renews it.

A child process (``jog_child.py``: our ``Client`` over ZeroMQ, pyads over ADS) presses
``ch1.ax1.manual_jog_plus_w`` in continuous jog and is killed with SIGKILL; the axis
must stop soon after, in wall time (the service runs on the real-time clock). Before,
X ran on at 16.7 mm/s until another client released the key. A client that stays
connected but stops renewing is stopped by ``[limits] jog_hold_timeout_s``; one that
renews keeps jogging.
"""

from __future__ import annotations

import asyncio
import signal
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest

from cnc_objects.clients import AsyncClient, Client
from cnc_objects.clients.jog_hold import HeldJog
from cnc_objects.testing import ServiceProcess, serving
from tests.limits.wire import limits_toml
from tests.reliability import figures
from tests.support.child_output import read_line

NODE = "tests/reliability/test_jog_dead_man.py"
CHILD = Path(__file__).with_name("jog_child.py")
ROOT = Path(__file__).resolve().parents[2]
KEY = "ch1.ax1.manual_jog_plus_w"
MOVING = "ch1.ax1.manual_moving_r"
LOCAL_NET_ID = "127.0.0.1.1.36"  # the pyads child, as its own AMS router
PRESS_TIMEOUT_S = 30.0  # a child started, connected and pressed, on a loaded machine
#: A generous bound on the stop after a kill (the target is 0.5 s; the figure is
#: recorded): a loaded 2-core machine delays the child's end and our polls.
STOP_BOUND_S = 2.0
POLL_S = 0.002
HOLD_TIMEOUT_S = 0.5  # jog_hold_timeout_s of the renewal tests


@pytest.fixture
def no_renewal_timeout(tmp_path: Path) -> Iterator[ServiceProcess]:
    """A real-time service whose jog keys are released only when their connection
    ends (no renewal timeout), with ADS on."""
    config = limits_toml(tmp_path / "c.toml", jog_hold_timeout_s=0.0)
    with serving("--config", str(config), "--clock", "realtime", ads=True) as service:
        yield service


def _manual_continuous(client: Client) -> None:
    client.write("ch1.mc_command_reset_w", True)
    client.write("ch1.mc_command_mode_w", 4)  # MANUAL
    client.write("ch1.ax1.manual_operation_mode_w", 2)  # continuous jog


def _wait(client: Client, moving: bool, timeout_s: float) -> float:
    """Poll until the axis's ``manual_moving_r`` is ``moving``; the wall time it took."""
    start = time.monotonic()
    while client.read(MOVING) is not moving:
        assert time.monotonic() - start < timeout_s, f"{MOVING} not {moving} in {timeout_s} s"
        time.sleep(POLL_S)
    return time.monotonic() - start


def _killed_stops(service: ServiceProcess, child_args: list[str], wire: str) -> None:
    with Client(service.endpoint, timeout_s=20) as client:
        _manual_continuous(client)
        child = subprocess.Popen([sys.executable, str(CHILD), *child_args],
                                 stdout=subprocess.PIPE, text=True, cwd=ROOT)
        try:
            assert read_line(child, PRESS_TIMEOUT_S) == "pressed"
            _wait(client, True, PRESS_TIMEOUT_S)
        finally:
            killed_at = time.monotonic()
            child.send_signal(signal.SIGKILL)
            child.wait()
        _wait(client, False, 30.0)
        stopped_s = time.monotonic() - killed_at  # braking included
        assert client.read(KEY) is False  # released, not merely braked
    service.wait_for_log("jog key ch1.ax1.manual_jog_plus_w released: its connection")
    figures.record(f"jog stop after SIGKILL of its client ({wire})", f"{stopped_s:.3f} s",
                   NODE)
    assert stopped_s < STOP_BOUND_S, f"the axis stopped {stopped_s:.3f} s after the kill"


def test_a_killed_zeromq_client_s_jog_stops(no_renewal_timeout: ServiceProcess) -> None:
    service = no_renewal_timeout
    _killed_stops(service, ["zmq", service.endpoint, KEY], "ZeroMQ")


def test_a_killed_pyads_client_s_jog_stops(no_renewal_timeout: ServiceProcess) -> None:
    service = no_renewal_timeout
    assert service.ams_net_id is not None and service.ads_address is not None
    _killed_stops(service, ["ads", service.ams_net_id, service.ads_address[0], LOCAL_NET_ID,
                            KEY], "ADS, pyads")


def test_a_jog_not_renewed_stops_after_the_hold_timeout(tmp_path: Path) -> None:
    """A client that stays connected but silent: its jog stops ``jog_hold_timeout_s``
    after its last TRUE; a client that renews (writes TRUE again) jogs on meanwhile."""
    config = limits_toml(tmp_path / "c.toml", jog_hold_timeout_s=HOLD_TIMEOUT_S)
    with serving("--config", str(config), "--clock", "realtime") as service, \
            Client(service.endpoint, timeout_s=20) as client:
        _manual_continuous(client)
        client.write(KEY, True)
        renewed_until = time.monotonic() + 3 * HOLD_TIMEOUT_S
        while time.monotonic() < renewed_until:  # renewed: it keeps moving
            time.sleep(HOLD_TIMEOUT_S / 5)
            assert client.read(MOVING) is True
            client.write(KEY, True)
        last_write = time.monotonic()
        _wait(client, False, 30.0)  # silent from here on
        stopped_s = time.monotonic() - last_write
        assert client.read(KEY) is False
        service.wait_for_log(f"not renewed for {HOLD_TIMEOUT_S:g} s")
    figures.record(f"jog stop of a silent client (jog_hold_timeout_s {HOLD_TIMEOUT_S:g})",
                   f"{stopped_s:.3f} s after its last TRUE", NODE)
    assert HOLD_TIMEOUT_S * 0.9 <= stopped_s < HOLD_TIMEOUT_S + STOP_BOUND_S


async def test_held_jog_renews_until_the_block_ends(tmp_path: Path) -> None:
    """``HeldJog`` (the client library's held key): the axis jogs on for several hold
    timeouts while the block runs, and stops when it ends."""
    config = limits_toml(tmp_path / "c.toml", jog_hold_timeout_s=HOLD_TIMEOUT_S)
    with serving("--config", str(config), "--clock", "realtime") as service:
        async with AsyncClient(service.endpoint, timeout_s=20) as client:
            await client.write("ch1.mc_command_reset_w", True)
            await client.write("ch1.mc_command_mode_w", 4)
            await client.write("ch1.ax1.manual_operation_mode_w", 2)
            async with HeldJog(client, KEY, renew_s=HOLD_TIMEOUT_S / 5):
                until = time.monotonic() + 4 * HOLD_TIMEOUT_S
                while time.monotonic() < until:
                    assert await client.read(MOVING) is True
                    await asyncio.sleep(HOLD_TIMEOUT_S / 10)
            assert await client.read(KEY) is False
        assert "not renewed" not in service.log_text


async def test_the_async_client_s_continuous_jog_is_renewed_until_jog_stop(
        tmp_path: Path) -> None:
    """``AsyncClient.jog(..., continuous=True)`` holds the key past several hold timeouts
    (renewed in the background); ``jog_stop`` releases it and the axis stands."""
    config = limits_toml(tmp_path / "c.toml", jog_hold_timeout_s=HOLD_TIMEOUT_S)
    with serving("--config", str(config), "--clock", "realtime") as service:
        async with AsyncClient(service.endpoint, timeout_s=20) as client:
            state = await client.jog("X", "+", continuous=True)
            assert state.moving
            until = time.monotonic() + 4 * HOLD_TIMEOUT_S
            while time.monotonic() < until:
                assert await client.read(MOVING) is True
                await asyncio.sleep(HOLD_TIMEOUT_S / 10)
            stopped = await client.jog_stop("X", timeout_s=PRESS_TIMEOUT_S)
            assert (stopped.moving, await client.read(KEY)) == (False, False)
        assert "not renewed" not in service.log_text


def test_the_blocking_client_renews_a_continuous_jog_with_renew_jog(tmp_path: Path) -> None:
    """The blocking ``Client`` has no background: ``renew_jog`` keeps the key held past
    the hold timeout; without it the service releases the key."""
    config = limits_toml(tmp_path / "c.toml", jog_hold_timeout_s=HOLD_TIMEOUT_S)
    with serving("--config", str(config), "--clock", "realtime") as service, \
            Client(service.endpoint, timeout_s=20) as client:
        assert client.jog("X", "+", continuous=True).moving
        until = time.monotonic() + 4 * HOLD_TIMEOUT_S
        while time.monotonic() < until:
            assert client.read(MOVING) is True
            client.renew_jog("X", "+")
            time.sleep(HOLD_TIMEOUT_S / 5)
        stopped_s = _wait(client, moving=False, timeout_s=HOLD_TIMEOUT_S + STOP_BOUND_S)
        assert stopped_s >= HOLD_TIMEOUT_S * 0.5  # released by the dead-man, not at once
