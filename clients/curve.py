"""A client's CURVE keys, and a watch on its handshakes so that a refusal is an error.

A service started with ``--keys`` admits only clients whose public key is in its
allow-list (docs/security.md). A client then needs:

- its key pair: the secret key file ``NAME.key_secret`` (``cnc keys new NAME``); naming
  the public ``NAME.key`` finds the secret file beside it;
- the service's public key, ``server.key``: given, or found in the key file's directory.

ZeroMQ says nothing to a socket whose handshake fails (it retries, or gives up, in
silence), so a refused client would only ever time out. ``HandshakeWatch`` reads the
socket's monitor events (``EVENT_HANDSHAKE_*``) and turns a failure into an
``AuthenticationError`` naming the cause: the key refused (not in the allow-list), a
server key that is not the service's, a key given to a service without CURVE or none
given to one with it; or into a ``ServiceFullError`` when the service had no room for
the connection (its ZAP status 500, with or without keys).
"""

from __future__ import annotations

import os
import struct
import time
from dataclasses import dataclass
from pathlib import Path

import zmq

from cnc_objects.protocol.constants import ZAP_STATUS_TABLE_FULL

from .errors import AdsConnectionError, AuthenticationError, ClientValueError, ServiceFullError
from .key_files import PUBLIC_SUFFIX, SECRET_SUFFIX, SERVER_KEY_FILE

_KEY_CHARS = 40  # a CURVE key in Z85 text

_EVENTS = (zmq.EVENT_HANDSHAKE_SUCCEEDED | zmq.EVENT_HANDSHAKE_FAILED_AUTH
           | zmq.EVENT_HANDSHAKE_FAILED_PROTOCOL | zmq.EVENT_HANDSHAKE_FAILED_NO_DETAIL)
_MECHANISM_MISMATCH = zmq.PROTOCOL_ERROR_ZMTP_MECHANISM_MISMATCH
# A handshake that ends without detail (the peer closed) is a refusal only when it keeps
# ending so: once may be a service stopping mid-handshake. ZeroMQ retries every 100 ms.
VAGUE_FAILURES = 3
# A monitor event's first frame: 16-bit event id, 32-bit value, native order, no padding
# (zmq_socket_monitor). Parsed here: pyzmq's parse_monitor_message lives in a module that
# imports zmq.asyncio and asyncio, which a blocking client (``cnc read``) never needs.
_EVENT_FRAME = struct.Struct("=HI")


@dataclass(frozen=True)
class ClientCurve:
    """A client's key pair and the service's public key (Z85), with the files they
    came from (for messages)."""

    public_key: bytes
    secret_key: bytes
    server_key: bytes
    key_file: Path
    server_key_file: Path

    def secure(self, sock: zmq.Socket[bytes]) -> None:
        """Make ``sock`` a CURVE client of the service (call before connect)."""
        sock.curve_publickey = self.public_key
        sock.curve_secretkey = self.secret_key
        sock.curve_serverkey = self.server_key


def client_curve(
    key_file: str | os.PathLike[str] | None, server_key: str | os.PathLike[str] | None = None
) -> ClientCurve | None:
    """``load_client_curve`` when a key file is given, else None (no CURVE); a server
    key without a key file is a mistake (``ClientValueError``)."""
    if key_file is None:
        if server_key is not None:
            raise ClientValueError("a server key needs this client's key file too (--key FILE)")
        return None
    return load_client_curve(key_file, server_key)


def load_client_curve(
    key_file: str | os.PathLike[str], server_key: str | os.PathLike[str] | None = None
) -> ClientCurve:
    """The keys of ``key_file`` (``NAME.key_secret``, or ``NAME.key`` with the secret file
    beside it) and of the service (``server_key``, default ``server.key`` in the key
    file's directory). ``ClientValueError`` names the file and what is wrong."""
    path = Path(key_file).expanduser()
    if path.name.endswith(PUBLIC_SUFFIX) and not path.name.endswith(SECRET_SUFFIX):
        path = path.with_name(path.name[:-len(PUBLIC_SUFFIX)] + SECRET_SUFFIX)
    public, secret = _read(path, "key file")
    if secret is None:
        raise ClientValueError(f"key file {path} holds no secret key: give the "
                               f"{SECRET_SUFFIX} file that `cnc keys new` wrote")
    server_path = (Path(server_key).expanduser() if server_key is not None
                   else path.parent / SERVER_KEY_FILE)
    if server_key is None and not server_path.exists():
        raise ClientValueError(
            f"no server key: {server_path} does not exist; give the service's public key "
            "with --server-key FILE (or CNC_SERVER_KEY), or copy it there")
    server_public, _ = _read(server_path, "server key file")
    return ClientCurve(public, secret, server_public, path, server_path)


def _read(path: Path, what: str) -> tuple[bytes, bytes | None]:
    if not path.is_file():
        raise ClientValueError(f"the {what} {path} does not exist")
    import zmq.auth  # here: only a client given keys needs it (it loads asyncio)

    try:
        public, secret = zmq.auth.load_certificate(path)
    except OSError as exc:
        raise ClientValueError(f"cannot read the {what} {path}: {exc.strerror or exc}") from None
    except (ValueError, UnicodeDecodeError) as exc:
        raise ClientValueError(f"{path} is not a ZeroMQ key file: {exc}") from None
    if public is None or len(public) != _KEY_CHARS:
        raise ClientValueError(f"{path} holds no CURVE public key")
    return public, secret


class HandshakeWatch:
    """The handshake events of one socket (its ZeroMQ monitor). Create it before the
    socket connects; ``check`` reads what happened without blocking, ``wait`` blocks."""

    def __init__(self, sock: zmq.Socket[bytes], endpoint: str, curve: ClientCurve | None) -> None:
        self._sock = sock
        self._monitor = sock.get_monitor_socket(_EVENTS)
        self._endpoint = endpoint
        self._curve = curve
        self.succeeded = False  # a handshake succeeded (the last one seen)
        self.failure: AdsConnectionError | None = None  # why the last one failed
        self._vague = 0  # handshakes in a row that ended without detail

    @property
    def fd(self) -> int:
        """The monitor's file descriptor (edge-triggered, as every ZeroMQ socket's)."""
        return self._monitor.FD

    def check(self) -> AdsConnectionError | None:
        """Read every event that waits; the failure of the last handshake, if it failed."""
        while True:
            try:
                frames = self._monitor.recv_multipart(zmq.NOBLOCK)
            except zmq.Again:
                return self.failure
            event, value = _EVENT_FRAME.unpack(frames[0])
            if event == zmq.EVENT_HANDSHAKE_SUCCEEDED:
                self.succeeded, self.failure, self._vague = True, None, 0
                continue
            self.succeeded = False
            if event == zmq.EVENT_HANDSHAKE_FAILED_NO_DETAIL:
                self._vague += 1
                if self._vague < VAGUE_FAILURES:
                    continue
            self.failure = self._explain(event, value)

    def wait(self, timeout_s: float) -> bool:
        """Block until a handshake succeeded or failed for good (True), or ``timeout_s``
        passed (False)."""
        deadline = time.monotonic() + timeout_s
        while self.check() is None and not self.succeeded:
            left_ms = int((deadline - time.monotonic()) * 1000)
            if left_ms <= 0 or not self._monitor.poll(left_ms):
                return False
        return True

    def close(self) -> None:
        """Stop monitoring (before the socket closes)."""
        try:
            self._sock.disable_monitor()
        except zmq.ZMQError:
            pass  # the socket is closed already
        self._monitor.close(linger=0)

    def _explain(self, event: int, value: int) -> AdsConnectionError:
        where, curve = self._endpoint, self._curve
        if event == zmq.EVENT_HANDSHAKE_FAILED_AUTH and value == ZAP_STATUS_TABLE_FULL:
            return ServiceFullError(
                f"the service at {where} refused this connection: its connection table is "
                "full ([limits] connections_per_front_end, all seats keyed or busy); not a "
                "key problem: try again later (docs/security.md)")
        if event == zmq.EVENT_HANDSHAKE_FAILED_AUTH:
            key = f"the public key of {curve.key_file}" if curve is not None else "it"
            text = (f"the service at {where} refused this client's key (CURVE): {key} is "
                    "not in the service's allow-list")
        elif curve is None and value == _MECHANISM_MISMATCH:
            text = (f"the service at {where} requires a CURVE key (it runs with --keys): "
                    "give --key FILE and --server-key FILE (or CNC_KEY, CNC_SERVER_KEY); "
                    "see docs/security.md")
        elif curve is None and event == zmq.EVENT_HANDSHAKE_FAILED_NO_DETAIL:
            text = (f"the service at {where} closes every connection in its handshake: it "
                    "likely requires a CURVE key (it runs with --keys: give --key FILE and "
                    "--server-key FILE, see docs/security.md), or it is no cnc-service")
        elif curve is None:
            text = (f"the handshake with {where} failed (ZeroMQ protocol error 0x{value:x}): "
                    "is it a cnc-service?")
        elif value == _MECHANISM_MISMATCH:
            text = (f"the service at {where} does not use CURVE keys, but this client has "
                    "one: leave out --key (CNC_KEY)")
        else:  # the connection just ends: a wrong server key, or a service without CURVE
            text = (f"the CURVE handshake with {where} failed: is {curve.server_key_file} "
                    "the public key of this service, and does it run with --keys?")
        return AuthenticationError(text)
