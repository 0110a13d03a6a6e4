"""``cnc-mqtt`` as a process: the broker's last will when it dies, a clean stop on
SIGTERM, and exit code 2 with one line for bad usage."""

from __future__ import annotations

import signal
import ssl
import subprocess
import sys
from pathlib import Path

import aiomqtt
import pytest
from typer.testing import CliRunner

from cnc_objects.clients.mqtt.cli import app
from tests.support.broker import OFFLINE, ONLINE, Broker, Watcher, running_broker
from tests.support.mqtt_cli import exit_code, kill_and_see_the_last_will, start_bridge
from tests.support.service import ROOT


async def test_the_last_will_says_offline_when_the_bridge_is_killed(
    endpoint: str, broker: Broker
) -> None:
    await kill_and_see_the_last_will(endpoint, broker, "p1")
    async with Watcher(broker, "cnc/p1/status") as late:  # retained
        assert (await late.wait_for("cnc/p1/status")).payload == b"offline"


async def test_sigterm_stops_cleanly_with_offline(endpoint: str, broker: Broker) -> None:
    async with Watcher(broker, "cnc/p2/#") as watcher:
        process = start_bridge(endpoint, broker, "p2", "--objects", "ch1.mc_active_state_r",
                               "--objects", "ax1.actual_position_acs")
        try:
            await watcher.wait_for("cnc/p2/status", ONLINE, timeout_s=30)
            await watcher.wait_for("cnc/p2/ax1.actual_position_acs")
            mark = watcher.mark()
        finally:
            process.send_signal(signal.SIGTERM)
            assert await exit_code(process) == 0
        await watcher.wait_for("cnc/p2/status", OFFLINE, since=mark)


@pytest.mark.parametrize("kind", ["auto", "amqtt"])
async def test_username_and_password_file(endpoint: str, kind: str, tmp_path: Path) -> None:
    users = {"bridge": "s3cret", "viewer": "look"}
    async with running_broker(kind, users=users) as broker:
        with pytest.raises(aiomqtt.MqttError):  # the broker refuses anonymous clients
            async with aiomqtt.Client(broker.host, broker.port):
                pass
        secret = tmp_path / "secret"
        secret.write_text("s3cret\n")  # the first line, without its newline
        async with Watcher(broker, "cnc/p3/status", username="viewer", password="look") as watcher:
            process = start_bridge(endpoint, broker, "p3", "--objects", "ch1.mc_active_state_r",
                                   "--username", "bridge", "--password-file", str(secret))
            try:
                await watcher.wait_for("cnc/p3/status", ONLINE, timeout_s=30)
            finally:
                process.send_signal(signal.SIGINT)
                assert await exit_code(process) == 0


@pytest.mark.parametrize("kind", ["auto", "amqtt"])
async def test_tls(endpoint: str, kind: str) -> None:
    async with running_broker(kind, tls=True) as broker:
        trust = ssl.create_default_context(cafile=str(broker.cert_file))
        async with Watcher(broker, "cnc/p4/status", tls_context=trust) as watcher:
            process = start_bridge(endpoint, broker, "p4", "--objects", "ch1.mc_active_state_r",
                                   "--tls")
            try:
                await watcher.wait_for("cnc/p4/status", ONLINE, timeout_s=30)
            finally:
                process.send_signal(signal.SIGTERM)
                assert await exit_code(process) == 0


USAGE_ERRORS = [
    (["--broker", "localhost:99999"], "port must be a number"),
    (["--broker", ":1883"], "expected HOST[:PORT]"),
    (["--broker", "::1"], "IPv6"),
    (["--machine", "mill/1"], "machine name"),
    (["--machine", "mill#"], "machine name"),
    (["--username", "u", "--password-file", "/nonexistent/secret"], "cannot read the password file"),
    (["--password-file", "/etc/hostname"], "--password-file needs --username"),
    (["--endpoint", "no-such-transport://x"], "endpoint"),
    (["--reconnect-initial-s", "5", "--reconnect-max-s", "1"], "reconnect"),
    (["--log-level", "LOUD"], "log level"),
]


@pytest.mark.parametrize(("args", "says"), USAGE_ERRORS, ids=[a[0][-1] for a in USAGE_ERRORS])
def test_bad_usage_exits_2_with_one_line(args: list[str], says: str) -> None:
    base = {"--broker": "localhost", "--machine": "m1"}
    for flag, value in base.items():
        if flag not in args:
            args = [*args, flag, value]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 2, result.output
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and says in lines[0], result.stderr


def test_empty_password_file_and_missing_options(tmp_path: Path) -> None:
    empty = tmp_path / "password"
    empty.write_text("\n")
    result = CliRunner().invoke(app, ["--broker", "h", "--machine", "m", "--username", "u",
                                      "--password-file", str(empty)])
    assert result.exit_code == 2 and "is empty" in result.stderr
    missing = CliRunner().invoke(app, ["--machine", "m"])  # no --broker
    assert missing.exit_code == 2 and "--broker" in missing.stderr


def test_entry_point_exit_code_as_a_process() -> None:
    result = subprocess.run(
        [sys.executable, "-m", "cnc_objects.clients.mqtt.cli", "--broker", "h:x", "--machine", "m"],
        cwd=ROOT, capture_output=True, text=True, timeout=60,
    )
    assert result.returncode == 2
    assert result.stderr.strip() == "cnc-mqtt: broker 'h:x': the port must be a number 1..65535"
