"""CURVE keys, the ZAP allow-list with roles, and the loopback rule of the ZeroMQ front end.

``cnc-service --keys DIR`` (or ``[security] keys_dir``) turns CURVE on: every ZeroMQ
connection is encrypted, and only clients whose public key is in the allow-list get in.
The key files are ZeroMQ certificates as ``zmq.auth.create_certificates`` (and ``cnc keys
new``) writes them::

    DIR/server.key_secret            the service's key pair (the secret never leaves DIR)
    DIR/server.key                   the service's public key: give it to every client
    DIR/clients/monitor/NAME.key     public keys of the clients, one directory per role
    DIR/clients/operator/NAME.key
    DIR/clients/admin/NAME.key

``[[security.clients]]`` entries of the configuration (name, public_key, role) add to
the directory's keys. The allow-list is read at start; restart the service to apply a
change.

The ZAP handler is pyzmq's ``ThreadAuthenticator`` (its own thread, so handshakes do not
wait for a busy event loop) with a credentials callback: a known key is admitted with the
User-Id ``<role>/<name>``, which ZeroMQ attaches to every message of that connection
(``zmq.Frame.get("User-Id")``); the server maps it to the role and the dispatcher decides.
An unknown key is refused and logged with the peer's address. ``ZAP_ENFORCE_DOMAIN``
makes libzmq refuse every client should the handler ever be missing. The same handler
(with or without CURVE) refuses a handshake when the connection table is full, with a
status of its own (``zmq_connections``), so that the client is told so and not that its
key was refused.
"""

from __future__ import annotations

import ipaddress
import logging
import stat
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from pathlib import Path

import zmq
import zmq.auth
from zmq.auth.thread import ThreadAuthenticator
from zmq.utils import z85

from cnc_objects.protocol.constants import ZAP_STATUS_TABLE_FULL
from cnc_objects.protocol.roles import ROLE_NAMES, Role

log = logging.getLogger(__name__)

SERVER_KEY_NAME = "server"  # DIR/server.key and DIR/server.key_secret
PUBLIC_SUFFIX = ".key"
SECRET_SUFFIX = ".key_secret"
CLIENTS_DIR = "clients"  # DIR/clients/<role>/<name>.key
ZAP_DOMAIN = "cnc-objects"
Z85_KEY_CHARS = 40  # a CURVE key (32 bytes) in Z85 text


class SecurityError(ValueError):
    """The keys or the allow-list cannot be used; the message says which file and why."""


@dataclass(frozen=True, slots=True)
class ClientKey:
    """One entry of the allow-list: a client's public key, its name and role."""

    name: str
    role: Role
    public_key: bytes  # Z85 text, as zmq.auth hands it to the credentials callback
    source: str  # the key file, or "configuration"

    @property
    def user_id(self) -> str:
        """The ZAP User-Id of this client's connections: ``<role>/<name>``."""
        return f"{self.role.label}/{self.name}"


class AllowList:
    """The client keys the service admits, by public key, and the role of each User-Id."""

    def __init__(self, clients: Iterable[ClientKey], origin: str) -> None:
        self.by_key: dict[bytes, ClientKey] = {}
        for client in clients:
            known = self.by_key.get(client.public_key)
            if known is not None and known.role is not client.role:
                raise SecurityError(
                    f"the key of {client.name} ({client.source}) is also {known.name}'s "
                    f"({known.source}) with role {known.role.label}: one role per key")
            self.by_key.setdefault(client.public_key, client)
        self.roles_by_user: dict[str, Role] = {c.user_id: c.role for c in self.by_key.values()}
        self.origin = origin

    def __len__(self) -> int:
        return len(self.by_key)

    def census(self) -> str:
        """``monitor 1, operator 2, admin 0``: how many keys each role has."""
        roles = [c.role for c in self.by_key.values()]
        return ", ".join(f"{r.label} {roles.count(r)}" for r in Role)


@dataclass(frozen=True)
class ServerCurve:
    """What CURVE needs on the service's side: its key pair and the allow-list."""

    public_key: bytes  # Z85
    secret_key: bytes  # Z85
    allow_list: AllowList

    def authenticator(self, context: zmq.Context[zmq.Socket[bytes]]) -> ZapAuthenticator:
        """The ZAP handler for ``context``'s sockets (not started)."""
        return ZapAuthenticator(context, self.allow_list)

    def secure(self, sock: zmq.Socket[bytes]) -> None:
        """Make ``sock`` a CURVE server of this key pair, authenticated by ZAP (call before
        bind)."""
        sock.curve_secretkey = self.secret_key
        sock.curve_publickey = self.public_key
        sock.curve_server = True
        sock.zap_domain = ZAP_DOMAIN.encode()
        sock.setsockopt(zmq.ZAP_ENFORCE_DOMAIN, 1)  # no handler answering: nobody gets in


class ZapAuthenticator(ThreadAuthenticator):
    """pyzmq's ZAP thread with our allow-list as the CURVE credentials callback, and the
    connection table's ``door``: a handshake it turns away is refused with ZAP status
    ``ZAP_STATUS_TABLE_FULL`` (500), which the client's monitor reports as such. Without
    an allow-list (a service without keys) NULL handshakes pass ZAP only for the door."""

    def __init__(self, context: zmq.Context[zmq.Socket[bytes]],
                 allow_list: AllowList | None = None) -> None:
        super().__init__(context, log=logging.getLogger(f"{__name__}.zap"))
        self._allow = allow_list if allow_list is not None else AllowList((), "none")
        self._curve = allow_list is not None
        self._peer = "?"  # the address of the ZAP request being handled
        # the connection table's question for a handshake from an address (ZAP thread)
        self.door: Callable[[str, bool], bool] | None = None

    def start(self) -> None:
        """Start the thread and answer CURVE requests of our domain from the allow-list."""
        super().start()
        if self._curve:
            self.configure_curve_callback(ZAP_DOMAIN, self)

    async def handle_zap_message(self, msg: list[bytes]) -> None:
        """Note the peer's address (ZAP frame 4) for the callback's log; refuse the
        handshake when the table is full, else authenticate."""
        self._peer = msg[3].decode("utf-8", "replace") if len(msg) > 3 else "?"
        door = self.door
        if door is not None and len(msg) > 1 and not door(self._peer, self._keyed(msg)):
            self._send_zap_reply(msg[1], str(ZAP_STATUS_TABLE_FULL).encode(),
                                 b"connection table full")
            return
        await super().handle_zap_message(msg)

    def _keyed(self, msg: list[bytes]) -> bool:
        """Does the ZAP request ``msg`` bring a CURVE key of the allow-list?"""
        if not self._curve or len(msg) != 7 or msg[5] != b"CURVE" or len(msg[6]) != 32:
            return False
        return z85.encode(msg[6]) in self._allow.by_key

    def callback(self, domain: str, key: bytes) -> bool:
        """The credentials callback: is the Z85 public ``key`` in the allow-list?"""
        client = self._allow.by_key.get(key)
        if client is None:
            log.warning("ZeroMQ client at %s refused: its CURVE public key %s is not in the "
                        "allow-list (%s)", self._peer, key.decode("ascii", "replace"),
                        self._allow.origin)
            return False
        log.info("ZeroMQ client %s (role %s) at %s admitted", client.name, client.role.label,
                 self._peer)
        return True

    def curve_user_id(self, client_public_key: bytes) -> str:
        """The User-Id of an admitted client: ``<role>/<name>``."""
        return self._allow.by_key[z85.encode(client_public_key)].user_id


# --------------------------------------------------------------------------- loading


def load_server_curve(
    keys_dir: Path | None,
    secret_file: Path | None = None,
    clients_dir: Path | None = None,
    inline: Iterable[tuple[str, str, str]] = (),
) -> ServerCurve:
    """The key pair (``secret_file``, default ``keys_dir/server.key_secret``) and the
    allow-list (``clients_dir``, default ``keys_dir/clients``, plus ``inline`` (name,
    Z85 public key, role) entries). ``SecurityError`` names the file and the problem."""
    if secret_file is None:
        if keys_dir is None:
            raise SecurityError("no server key: give a keys directory or a server secret key file")
        secret_file = keys_dir / f"{SERVER_KEY_NAME}{SECRET_SUFFIX}"
    public, secret = _load_key_file(secret_file, secret=True)
    _warn_if_readable(secret_file)
    clients: list[ClientKey] = []
    origins: list[str] = []
    if clients_dir is None and keys_dir is not None:
        clients_dir = keys_dir / CLIENTS_DIR
        if not clients_dir.is_dir():
            clients_dir = None  # the configuration may list every client instead
    if clients_dir is not None:
        clients += _directory_clients(clients_dir)
        origins.append(str(clients_dir))
    for name, key, role in inline:
        clients.append(_inline_client(name, key, role))
    if inline:
        origins.append("[[security.clients]] of the configuration")
    allow_list = AllowList(clients, " and ".join(origins) or "empty")
    if not allow_list:
        log.warning("CURVE is on but the allow-list is empty: every client is refused "
                    "(put public keys into %s/<role>/, see docs/security.md)",
                    clients_dir or (keys_dir / CLIENTS_DIR if keys_dir else "clients"))
    assert secret is not None  # _load_key_file(secret=True) refuses a file without one
    return ServerCurve(public, secret, allow_list)


def _load_key_file(path: Path, secret: bool) -> tuple[bytes, bytes | None]:
    """(public, secret) of a certificate file; ``secret``: the secret key must be there."""
    if not path.is_file():
        make = f" (make it: cnc keys new {SERVER_KEY_NAME} --dir {path.parent})" if secret else ""
        raise SecurityError(f"the key file {path} does not exist{make}")
    try:
        public, secret_key = zmq.auth.load_certificate(path)
    except OSError as exc:
        raise SecurityError(f"cannot read the key file {path}: {exc.strerror or exc}") from None
    except (ValueError, UnicodeDecodeError) as exc:
        raise SecurityError(f"{path} is not a ZeroMQ key file: {exc}") from None
    if public is None or len(public) != Z85_KEY_CHARS:
        raise SecurityError(f"{path} holds no CURVE public key (public-key = \"...\")")
    if secret and (secret_key is None or len(secret_key) != Z85_KEY_CHARS):
        raise SecurityError(f"{path} holds no CURVE secret key: the service needs its "
                            f"{SECRET_SUFFIX} file (cnc keys new {SERVER_KEY_NAME} --dir DIR)")
    return public, secret_key


def _warn_if_readable(path: Path) -> None:
    try:
        mode = path.stat().st_mode
    except OSError:
        return
    if mode & (stat.S_IRGRP | stat.S_IROTH):
        log.warning("%s can be read by other users; chmod 600 it", path)


def _directory_clients(clients_dir: Path) -> list[ClientKey]:
    """The public keys in ``clients_dir/<role>/*.key``; any other entry is refused, so
    that a misspelt role directory cannot leave a client out unnoticed."""
    if not clients_dir.is_dir():
        raise SecurityError(f"the allow-list directory {clients_dir} does not exist")
    found: list[ClientKey] = []
    for role_dir in sorted(clients_dir.iterdir()):
        try:
            role = Role.parse(role_dir.name)
        except ValueError:
            raise SecurityError(f"{role_dir}: the allow-list has one directory per role "
                                f"({ROLE_NAMES}), not {role_dir.name!r}") from None
        if not role_dir.is_dir():
            raise SecurityError(f"{role_dir} must be a directory of public key files")
        for path in sorted(role_dir.iterdir()):
            if path.name.endswith(SECRET_SUFFIX):
                log.warning("%s is a client's SECRET key: it belongs to the client only; "
                            "remove it from the service's allow-list", path)
            elif path.name.endswith(PUBLIC_SUFFIX):
                public, _ = _load_key_file(path, secret=False)
                found.append(ClientKey(path.name[:-len(PUBLIC_SUFFIX)], role, public, str(path)))
    return found


def _inline_client(name: str, key: str, role: str) -> ClientKey:
    data = key.strip().encode("ascii", "replace")
    try:
        valid = len(data) == Z85_KEY_CHARS and len(z85.decode(data)) == 32
    except (ValueError, KeyError):
        valid = False
    if not valid:
        raise SecurityError(f"[[security.clients]] {name}: public_key must be the "
                            f"{Z85_KEY_CHARS} Z85 characters of a CURVE public key")
    return ClientKey(name, Role.parse(role), data, "configuration")


# --------------------------------------------------------------------------- loopback


def host_is_loopback(host: str) -> bool:
    """True when ``host`` (an address, a name or a ZeroMQ interface) only ever reaches
    this machine: a loopback IP address, ``localhost``, the ``lo`` interface. Anything
    else (``*``, 0.0.0.0, a LAN address, another name) counts as the network."""
    host = host.strip().strip("[]").split("%", 1)[0]
    if host.lower() in ("localhost", "lo", "lo0"):
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def endpoint_is_local(endpoint: str) -> bool:
    """True when a ZeroMQ bind ``endpoint`` serves this machine only: ``tcp://`` on a
    loopback host, ``ipc://`` (file permissions decide) or ``inproc://``."""
    transport, sep, address = endpoint.partition("://")
    if not sep:
        return False
    transport = transport.lower()
    if transport in ("ipc", "inproc"):
        return True
    if transport not in ("tcp", "ws", "wss"):
        return False
    address = address.split("/", 1)[0]  # ws://host:port/path
    host, _, _ = address.rpartition(":")  # the port is always given when binding
    return host_is_loopback(host)
