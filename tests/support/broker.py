"""A real MQTT broker for tests, on a free port of 127.0.0.1.

Mosquitto when the ``mosquitto`` binary is installed (a subprocess with a generated
configuration: one listener, anonymous access or a password file, optionally TLS, no
persistence), else the amqtt broker in the test's event loop (``$CNC_TEST_BROKER=amqtt``
forces it). Both wait until the broker accepts connections (Mosquitto's "running" log
line, then a TCP connect), never for a fixed time. ``restart()`` stops the
broker and starts a fresh one on the same port: retained messages are gone, as after a
broker restart without persistence.
"""

from __future__ import annotations

import asyncio
import base64
import contextlib
import hashlib
import json
import logging
import os
import queue
import shutil
import signal
import socket
import subprocess
import tempfile
import threading
from collections.abc import AsyncIterator, Callable
from pathlib import Path
from typing import Any, Protocol

import aiomqtt

HOST = "127.0.0.1"
# predicates on a status payload, for Watcher.wait_for
ONLINE = lambda payload: payload == b"online"
OFFLINE = lambda payload: payload == b"offline"
# A self-signed certificate for 127.0.0.1 and localhost (EC P-256, valid until 2126) and
# its key, for the brokers' TLS listeners. Test data only: the key is public.
TEST_CERT_PEM = """\
-----BEGIN CERTIFICATE-----
MIIBtjCCAV2gAwIBAgIUbQOnBkzMDcT4k991nx4llRkxg8QwCgYIKoZIzj0EAwIw
IjEgMB4GA1UEAwwXY25jLW9iamVjdHMgdGVzdCBicm9rZXIwIBcNMjYxMTIxMjEx
MDM0WhgPMjEyNjEwMjgyMTEwMzRaMCIxIDAeBgNVBAMMF2NuYy1vYmplY3RzIHRl
c3QgYnJva2VyMFkwEwYHKoZIzj0CAQYIKoZIzj0DAQcDQgAE25cWJ6Ggm2g1B4EY
aRjoVEh4W+SWfHkHsle6Xni86WECrKCF7Ye4IdAkA5g8NfmWCL5WKBN8M9jgl+cG
qCeMq6NvMG0wHQYDVR0OBBYEFL+UL4rKju8LUvxy/r5oG52YMm0MMB8GA1UdIwQY
MBaAFL+UL4rKju8LUvxy/r5oG52YMm0MMA8GA1UdEwEB/wQFMAMBAf8wGgYDVR0R
BBMwEYcEfwAAAYIJbG9jYWxob3N0MAoGCCqGSM49BAMCA0cAMEQCIBeIXDzDWY2O
Fo/tv4oyjZLzsc/Gm6sdPthG8t6YKsdHAiA+ZVcNbGRYmFY2z/qfO/ayYfaUhH6+
4ePLb0S+x0TvsQ==
-----END CERTIFICATE-----
"""
TEST_KEY_PEM = """\
-----BEGIN PRIVATE KEY-----
MIGHAgEAMBMGByqGSM49AgEGCCqGSM49AwEHBG0wawIBAQQgzyUKQaRISKaQrhu2
6duWysdPkA0SqtD29kmSupsnfTihRANCAATblxYnoaCbaDUHgRhpGOhUSHhb5JZ8
eQeyV7peeLzpYQKsoIXth7gh0CQDmDw1+ZYIvlYoE3wz2OCX5waoJ4yr
-----END PRIVATE KEY-----
"""
_MOSQUITTO_PATHS = ("/usr/sbin/mosquitto", "/usr/local/sbin/mosquitto")
_START_TIMEOUT_S = 10.0


def mosquitto_binary() -> str | None:
    """The mosquitto executable, or None when it is not installed."""
    found = shutil.which("mosquitto")
    if found:
        return found
    return next((p for p in _MOSQUITTO_PATHS if os.access(p, os.X_OK)), None)


def free_port() -> int:
    """A TCP port of 127.0.0.1 that nothing listens on right now."""
    with socket.socket() as sock:
        sock.bind((HOST, 0))
        return sock.getsockname()[1]


def _accepts(port: int) -> bool:
    """True when a TCP connect to the broker succeeds."""
    try:
        with socket.create_connection((HOST, port), timeout=1.0):
            return True
    except OSError:
        return False


class Broker(Protocol):
    """What tests use of a broker."""

    kind: str  # "mosquitto" or "amqtt"
    host: str
    port: int
    cert_file: Path | None  # the certificate to trust when the listener speaks TLS

    async def start(self) -> None: ...
    async def stop(self) -> None: ...
    async def restart(self) -> None: ...


def _write_certificate(directory: Path) -> Path:
    """``cert.pem`` and ``key.pem`` of the test certificate in ``directory``; the cert."""
    (directory / "key.pem").write_text(TEST_KEY_PEM)
    cert = directory / "cert.pem"
    cert.write_text(TEST_CERT_PEM)
    return cert


def _mosquitto_hash(password: str) -> str:
    """Mosquitto's ``$6$`` password hash: salted SHA-512, salt and digest in base64."""
    salt = os.urandom(12)
    digest = hashlib.sha512(password.encode() + salt).digest()
    return f"$6${base64.b64encode(salt).decode()}${base64.b64encode(digest).decode()}"


class MosquittoBroker:
    """Mosquitto in a subprocess; its log is in ``log``."""

    kind = "mosquitto"

    def __init__(self, binary: str, users: dict[str, str] | None = None, tls: bool = False) -> None:
        self.host = HOST
        self.port = free_port()
        self.binary = binary
        self.users = users
        self.log: list[str] = []
        self._process: subprocess.Popen[str] | None = None
        self._dir = Path(tempfile.mkdtemp(prefix="mosquitto-"))
        self.cert_file = _write_certificate(self._dir) if tls else None

    def _config(self) -> Path:
        path = self._dir / "mosquitto.conf"
        lines = [
            f"listener {self.port} {HOST}",
            f"allow_anonymous {'false' if self.users else 'true'}",
            "persistence false",
            "log_dest stderr",
            *(f"log_type {t}" for t in ("error", "warning", "notice", "information")),
        ]
        if os.geteuid() == 0:
            lines.append("user root")  # stay root: files made by the test stay readable
        if self.users:
            passwords = self._dir / "passwords"
            passwords.write_text("".join(
                f"{user}:{_mosquitto_hash(password)}\n" for user, password in self.users.items()
            ))
            lines.append(f"password_file {passwords}")
        if self.cert_file:
            lines += [f"certfile {self.cert_file}", f"keyfile {self._dir / 'key.pem'}"]
        path.write_text("\n".join(lines) + "\n")
        return path

    def start_blocking(self) -> None:
        """Start and wait until it listens (its "running" line, then a connect)."""
        process = subprocess.Popen(
            [self.binary, "-c", str(self._config())],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
        )
        lines: queue.Queue[str | None] = queue.Queue()

        def pump() -> None:  # keep reading, so that a chatty broker never blocks on the pipe
            for line in process.stderr:  # type: ignore[union-attr]
                self.log.append(line.rstrip("\n"))
                lines.put(line)
            lines.put(None)

        threading.Thread(target=pump, name="mosquitto-log", daemon=True).start()
        self._process = process
        while True:
            try:
                line = lines.get(timeout=_START_TIMEOUT_S)
            except queue.Empty:
                self.stop_blocking()
                raise AssertionError("mosquitto did not start:\n" + "\n".join(self.log)) from None
            if line is None:
                raise AssertionError(
                    f"mosquitto exited with {process.wait()}:\n" + "\n".join(self.log)
                )
            if " running" in line:
                break
        log = "\n".join(self.log)
        assert _accepts(self.port), f"mosquitto runs but refuses connections:\n{log}"

    def stop_blocking(self) -> None:
        """SIGTERM and wait (SIGKILL after 5 s)."""
        process, self._process = self._process, None
        if process is None or process.poll() is not None:
            return
        process.send_signal(signal.SIGTERM)
        try:
            process.wait(5.0)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()

    async def start(self) -> None:
        """``start_blocking`` off the event loop (a bridge on the loop keeps running)."""
        await asyncio.to_thread(self.start_blocking)

    async def stop(self) -> None:
        """``stop_blocking`` off the event loop."""
        await asyncio.to_thread(self.stop_blocking)

    async def restart(self) -> None:
        """Stop, then start again on the same port."""
        await self.stop()
        await self.start()


class AmqttBroker:
    """The amqtt broker in this event loop (the fallback when Mosquitto is missing)."""

    kind = "amqtt"

    def __init__(self, users: dict[str, str] | None = None, tls: bool = False) -> None:
        self.host = HOST
        self.port = free_port()
        self.users = users
        self._broker = None
        self._dir = Path(tempfile.mkdtemp(prefix="amqtt-"))
        self.cert_file = _write_certificate(self._dir) if tls else None

    async def start(self) -> None:
        """Start and wait until it accepts connections."""
        from amqtt.broker import Broker as _Amqtt  # test extra: import only when used

        # amqtt logs every connection, and each dropped client with a traceback.
        logging.getLogger("amqtt").setLevel(logging.CRITICAL)
        logging.getLogger("transitions").setLevel(logging.WARNING)

        plugins: dict[str, dict[str, object]] = {
            "amqtt.plugins.authentication.AnonymousAuthPlugin": {"allow_anonymous": not self.users},
        }
        if self.users:
            from pwdlib.hashers.argon2 import Argon2Hasher  # amqtt's own dependency

            passwords = self._dir / "passwords"
            passwords.write_text("".join(
                f"{user}:{Argon2Hasher().hash(password)}\n" for user, password in self.users.items()
            ))
            plugins = {
                "amqtt.plugins.authentication.FileAuthPlugin": {"password_file": str(passwords)}
            }
        listener: dict[str, object] = {"type": "tcp", "bind": f"{HOST}:{self.port}"}
        if self.cert_file:
            listener |= {"ssl": True, "certfile": str(self.cert_file),
                         "keyfile": str(self._dir / "key.pem")}
        config = {"listeners": {"default": listener}, "plugins": plugins}
        self._broker = _Amqtt(config)
        await self._broker.start()
        assert await asyncio.to_thread(_accepts, self.port), "amqtt refuses connections"

    async def stop(self) -> None:
        """Shut the broker down (its clients are disconnected)."""
        broker, self._broker = self._broker, None
        if broker is not None:
            await broker.shutdown()

    async def restart(self) -> None:
        """Stop, then start a fresh broker on the same port."""
        await self.stop()
        await self.start()


def make_broker(
    kind: str = "auto", users: dict[str, str] | None = None, tls: bool = False
) -> Broker:
    """A broker object, not started: ``mosquitto`` when installed (or asked for),
    ``amqtt`` when asked for or Mosquitto is missing. ``$CNC_TEST_BROKER`` (``amqtt`` or
    ``mosquitto``) overrides ``auto``, to run the tests on the fallback broker. With
    ``users`` (name: password) only they may connect; with ``tls`` the listener speaks
    TLS with the test certificate (``cert_file``, to trust)."""
    if kind == "auto":
        kind = os.environ.get("CNC_TEST_BROKER", "auto")
    binary = mosquitto_binary()
    if kind == "amqtt" or (kind == "auto" and binary is None):
        return AmqttBroker(users, tls)
    if binary is None:
        raise AssertionError("mosquitto is not installed")
    return MosquittoBroker(binary, users, tls)


@contextlib.asynccontextmanager
async def running_broker(
    kind: str = "auto", users: dict[str, str] | None = None, tls: bool = False
) -> AsyncIterator[Broker]:
    """A started broker for an ``async with`` block; stopped on the way out."""
    broker = make_broker(kind, users, tls)
    await broker.start()
    try:
        yield broker
    finally:
        await broker.stop()



class Watcher:
    """An MQTT client that records every message under ``topic_filter``; tests wait for
    the message they expect with a timeout (``wait_for``), never for a fixed time.

        async with Watcher(broker, "cnc/m1/#") as w:
            message = await w.wait_for("cnc/m1/status", lambda p: p == b"online")
    """

    def __init__(self, broker: Broker, topic_filter: str, **client_options: object) -> None:
        self.broker = broker
        self.topic_filter = topic_filter
        self.messages: list[aiomqtt.Message] = []
        self._options = client_options
        self._arrived = asyncio.Event()
        self._stack = contextlib.AsyncExitStack()

    async def __aenter__(self) -> Watcher:
        client = aiomqtt.Client(
            self.broker.host, self.broker.port, **self._options  # type: ignore[arg-type]
        )
        self.client = await self._stack.enter_async_context(client)
        await self.client.subscribe(self.topic_filter, qos=1)
        task = asyncio.create_task(self._receive(), name=f"watch {self.topic_filter}")
        self._stack.push_async_callback(_cancel, task)
        return self

    async def __aexit__(self, *exc: object) -> None:
        await self._stack.aclose()

    async def _receive(self) -> None:
        with contextlib.suppress(aiomqtt.MqttError):  # the broker went away: the test decides
            async for message in self.client.messages:
                self.messages.append(message)
                self._arrived.set()

    def mark(self) -> int:
        """A position in ``messages``: ``wait_for(..., since=mark)`` looks only after it."""
        return len(self.messages)

    async def wait_for(
        self,
        topic: str,
        match: Callable[[bytes], bool] = lambda payload: True,
        *,
        since: int = 0,
        timeout_s: float = 10.0,
    ) -> aiomqtt.Message:
        """The first message on ``topic`` (from index ``since``) whose payload matches."""
        index = since
        try:
            async with asyncio.timeout(timeout_s):
                while True:
                    while index < len(self.messages):
                        message = self.messages[index]
                        index += 1
                        payload: bytes = message.payload  # type: ignore[assignment]
                        if message.topic.value == topic and match(payload):
                            return message
                    self._arrived.clear()
                    await self._arrived.wait()
        except TimeoutError:
            seen = [f"{m.topic.value} {m.payload!r}" for m in self.messages[since:]][-20:]
            raise AssertionError(
                f"no matching message on {topic} within {timeout_s} s; last seen:\n"
                + "\n".join(seen)
            ) from None

    async def wait_value(self, topic: str, match: Callable[[Any], bool], **kw: Any) -> dict:
        """The first JSON value message on ``topic`` whose ``value`` matches; its payload."""
        message = await self.wait_for(
            topic, lambda payload: match(json.loads(payload)["value"]), **kw
        )
        return json.loads(message.payload)  # type: ignore[arg-type]


async def _cancel(task: asyncio.Task[None]) -> None:
    task.cancel()
    with contextlib.suppress(asyncio.CancelledError):
        await task
