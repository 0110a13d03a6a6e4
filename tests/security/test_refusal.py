"""Clients the service does not let in: an unknown key, no key, keys that do not fit.

ZeroMQ tells a client nothing when its CURVE handshake fails; the client library reads
the socket's handshake events and raises ``AuthenticationError`` (ADS 0x723) at once, long
before its timeout. The service logs each refused key with the peer's address. The CLI
exits 3 with one line.
"""

from __future__ import annotations

import asyncio
import itertools
import os
import re
import socket
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest
import zmq.auth

from cnc_objects.clients import AsyncClient, AuthenticationError, Client, ClientValueError
from cnc_objects.testing import ServiceProcess, serving

TIMEOUT_S = 30.0  # the clients' timeout: every refusal must come far sooner
QUICK_S = 5.0  # what "at once" means on a busy 2-core machine
FEED_R = "ch1.mc_command_feed_override_r"


@pytest.fixture
def stranger(tmp_path: Path, keyed: ServiceProcess) -> Path:
    """A key pair the service has never seen, with the service's public key beside it."""
    assert keyed.keys is not None
    _, secret = zmq.auth.create_certificates(tmp_path, "stranger")
    (tmp_path / "server.key").write_bytes(keyed.keys.server_key.read_bytes())
    return Path(secret)


def cnc(endpoint: str, *args: str, env: dict[str, str] | None = None,
        ) -> subprocess.CompletedProcess[str]:
    base = {k: v for k, v in os.environ.items() if k not in ("CNC_KEY", "CNC_SERVER_KEY")}
    return subprocess.run(
        [sys.executable, "-c", "from cnc_objects.clients.cli import main; main()",
         "--endpoint", endpoint, "--timeout", str(TIMEOUT_S), *args],
        capture_output=True, text=True, timeout=120, env={**base, **(env or {})})


def test_an_unknown_key_is_refused_at_once_and_logged_with_the_address(
    keyed: ServiceProcess, stranger: Path,
) -> None:
    start = time.monotonic()
    with pytest.raises(AuthenticationError) as refused:
        with Client(keyed.endpoint, timeout_s=TIMEOUT_S, key_file=stranger) as c:
            c.read(FEED_R)
    assert time.monotonic() - start < QUICK_S
    assert refused.value.code == 0x723
    assert "refused this client's key (CURVE)" in str(refused.value)
    assert str(stranger) in str(refused.value)
    public = zmq.auth.load_certificate(stranger)[0].decode()
    keyed.wait_for_log(r"ZeroMQ client at 127\.0\.0\.1 refused: its CURVE public key "
                       + re.escape(public) + " is not in the allow-list")


def test_an_unknown_key_is_refused_for_the_async_client_too(
    keyed: ServiceProcess, stranger: Path,
) -> None:
    async def main() -> float:
        start = time.monotonic()
        async with AsyncClient(keyed.endpoint, timeout_s=TIMEOUT_S, key_file=stranger) as c:
            with pytest.raises(AuthenticationError, match="refused this client's key"):
                await c.read(FEED_R)
            with pytest.raises(AuthenticationError):  # later requests say why, too
                await c.info()
        return time.monotonic() - start

    assert asyncio.run(main()) < QUICK_S


def test_the_cli_exits_3_for_an_unknown_key(keyed: ServiceProcess, stranger: Path) -> None:
    start = time.monotonic()
    result = cnc(keyed.endpoint, "--key", str(stranger), "read", FEED_R)
    assert result.returncode == 3, result.stderr
    assert time.monotonic() - start < TIMEOUT_S
    assert result.stderr.startswith("error: ADS 0x723 ACCESSDENIED: the service at ")
    assert "refused this client's key (CURVE)" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    by_env = cnc(keyed.endpoint, "info", env={"CNC_KEY": str(stranger)})
    assert by_env.returncode == 3 and "refused this client's key" in by_env.stderr


def test_a_client_without_key_is_told_the_service_needs_one(keyed: ServiceProcess) -> None:
    start = time.monotonic()
    # ZeroMQ says "mechanism mismatch", or (a race) just closes: both name the key
    with pytest.raises(AuthenticationError, match="requires a CURVE key .*--keys.*give --key"):
        with Client(keyed.endpoint, timeout_s=TIMEOUT_S) as c:
            c.info()
    assert time.monotonic() - start < QUICK_S
    result = cnc(keyed.endpoint, "info")
    assert result.returncode == 3 and "give --key FILE" in result.stderr


def test_a_wrong_server_key_is_named(keyed: ServiceProcess, tmp_path: Path) -> None:
    assert keyed.keys is not None
    impostor, _ = zmq.auth.create_certificates(tmp_path, "impostor")
    with pytest.raises(AuthenticationError, match=f"is {impostor} the public key of this"):
        with Client(keyed.endpoint, timeout_s=TIMEOUT_S,
                    key_file=keyed.keys.client("operator"), server_key=impostor) as c:
            c.info()


def test_a_key_given_to_a_service_without_keys_is_named(tmp_path: Path) -> None:
    _, secret = zmq.auth.create_certificates(tmp_path, "alice")
    server, _ = zmq.auth.create_certificates(tmp_path, "server")
    with serving() as plain:
        start = time.monotonic()
        with pytest.raises(AuthenticationError, match="does it run with --keys|does not use"):
            with Client(plain.endpoint, timeout_s=TIMEOUT_S, key_file=secret,
                        server_key=server) as c:
                c.info()
        assert time.monotonic() - start < QUICK_S


def test_unusable_key_files_are_refused_before_anything_is_sent(tmp_path: Path) -> None:
    public, _ = zmq.auth.create_certificates(tmp_path, "alice")
    with pytest.raises(ClientValueError, match="does not exist"):
        Client(key_file=tmp_path / "nobody.key_secret")
    with pytest.raises(ClientValueError, match="server.key does not exist"):
        Client(key_file=public)  # the secret beside it is found; no server key beside it
    (tmp_path / "garbage.key_secret").write_text("not a certificate\n")
    with pytest.raises(ClientValueError, match="garbage.key_secret"):
        Client(key_file=tmp_path / "garbage.key_secret", server_key=public)
    with pytest.raises(ClientValueError, match="needs this client's key file"):
        Client(server_key=public)
    result = cnc("tcp://127.0.0.1:9", "--key", str(tmp_path / "nobody.key_secret"), "info")
    assert result.returncode == 2 and "does not exist" in result.stderr


def _closing_listener(connections: int | None) -> tuple[socket.socket, threading.Thread]:
    """A TCP port that closes each connection at once (a handshake that ends without a
    word), ``connections`` times (None: until the listener is closed)."""
    listener = socket.create_server(("127.0.0.1", 0))

    def close_them() -> None:
        for _ in itertools.count() if connections is None else range(connections):
            try:
                peer, _ = listener.accept()
            except OSError:  # the listener was closed
                return
            peer.close()

    thread = threading.Thread(target=close_them, daemon=True)
    thread.start()
    return listener, thread


def test_a_port_that_ends_every_handshake_is_named_soon() -> None:
    listener, _ = _closing_listener(None)
    try:
        port = listener.getsockname()[1]
        start = time.monotonic()
        with pytest.raises(AuthenticationError, match="closes every connection in its "
                                                      "handshake"):
            with Client(f"tcp://127.0.0.1:{port}", timeout_s=TIMEOUT_S) as c:
                c.info()
        assert time.monotonic() - start < QUICK_S
    finally:
        listener.close()


def test_one_handshake_cut_short_is_not_a_refusal(tmp_path: Path) -> None:
    """A service that stops in the middle of a handshake (a restart) ends it without a
    word once; the client waits for the next one instead of giving up."""
    listener, closer = _closing_listener(1)
    port = listener.getsockname()[1]
    with Client(f"tcp://127.0.0.1:{port}", timeout_s=TIMEOUT_S) as c:
        closer.join(TIMEOUT_S)  # the client's first handshake was cut short
        assert not closer.is_alive()
        listener.close()
        with serving("--endpoint", f"tcp://127.0.0.1:{port}") as service:
            assert service.endpoint == f"tcp://127.0.0.1:{port}"
            assert c.info().name == "cnc-objects"
