"""A real ``cnc-service`` in a subprocess on a free port, for integration tests.

    with serving("--config", "machine.toml") as service:   # virtual clock, own program store
        with Client(service.endpoint) as cnc:
            ...

The service binds ``tcp://127.0.0.1:*`` (ZeroMQ picks a free port: no race between
choosing a port and binding it) and logs the endpoint it got; the start waits for that
log line, never for a fixed time. Standard library only: the pytest plugin imports this
at every pytest start.

ADS (AMS/TCP) is off unless asked for, so that services started side by side never
compete for 127.0.0.1:48898: ``start_service(ads=True)`` gives the service a loopback
address of its own, ``127.0.0.<n>:48898`` (ADS clients such as pyads always dial port
48898 and tell servers apart by IP address), and ``ads="127.0.0.1:0"`` any free port;
``ServiceProcess.ads_address`` and ``.ams_net_id`` say what it got.

CURVE (docs/security.md): ``start_service(keys=True)`` makes a key directory of this
service's own (removed by ``stop``) with one client key per role and starts the service
with ``--keys``; ``service.keys.client("operator")`` is the operator's key file (the
service's ``server.key`` lies beside it), for ``Client(..., key_file=...)`` or ``cnc
--key``. ``keys=DIR`` starts it with ``--keys DIR``.
"""

from __future__ import annotations

import contextlib
import os
import random
import re
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

_LISTENING = re.compile(r"listening on (tcp://\S+)")
_ADS_LISTENING = re.compile(r"ADS on \[?([^\s\]]+?)\]?:(\d+), AMS Net ID (\S+)")
_OUTPUT_AREA = re.compile(r"output area: (.+) \(")
_ADS_BUSY = "cannot listen for ADS"
START_TIMEOUT_S = 20.0  # a cold start imports numpy and pydantic: seconds on a busy CI
STOP_TIMEOUT_S = 10.0
AMS_TCP_PORT = 48898  # ADS clients dial this port; a service of its own needs its own IP
ADS_START_ATTEMPTS = 20  # loopback addresses tried before giving up (another took it)
KEY_ROLES = ("monitor", "operator", "admin")  # a client key of each is made by keys=True


@dataclass(frozen=True)
class ServiceKeys:
    """The CURVE keys of a service started with ``keys=True``."""

    directory: Path  # the service's --keys DIR: server.key_secret, clients/<role>/*.key
    clients: dict[str, Path]  # role -> that client's secret key file (server.key beside it)

    def client(self, role: str) -> Path:
        """The secret key file of the client of ``role`` (monitor, operator, admin)."""
        return self.clients[role]

    @property
    def server_key(self) -> Path:
        """The service's public key file."""
        return self.directory / "server.key"


def make_keys(root: str | os.PathLike[str], roles: tuple[str, ...] = KEY_ROLES) -> ServiceKeys:
    """A service key directory ``root/service`` with one client per role in its
    allow-list, each client's key pair in ``root/<role>/`` beside a copy of the service's
    public key (pyzmq's ``zmq.auth.create_certificates``, as ``cnc keys new`` writes)."""
    import shutil

    import zmq.auth  # here: the plugin imports this module at every pytest start

    service = Path(root) / "service"
    service.mkdir(parents=True)
    zmq.auth.create_certificates(service, "server")
    (service / "server.key_secret").chmod(0o600)
    clients = {}
    for role in roles:
        own = Path(root) / role
        own.mkdir()
        public, secret = zmq.auth.create_certificates(own, role)
        allowed = service / "clients" / role
        allowed.mkdir(parents=True)
        shutil.copyfile(public, allowed / Path(public).name)
        shutil.copyfile(service / "server.key", own / "server.key")
        clients[role] = Path(secret)
    return ServiceKeys(service, clients)


class ServiceProcess:
    """A running ``cnc-service``: its process, endpoint and everything it logged so far.

    ``log`` grows while the service runs (a thread reads its stderr line by line, so the
    pipe never fills up); ``stop`` ends it with SIGINT, as Ctrl-C would.
    """

    def __init__(self, process: subprocess.Popen[str], program_dir: Path,
                 owned_dir: tempfile.TemporaryDirectory[str] | None = None) -> None:
        self.process = process
        self.program_dir = program_dir  # the service's program store
        self.output_dir: Path | None = None  # its output area (the files the kernel writes)
        self.endpoint = ""  # set once the service has logged it
        self.ads_address: tuple[str, int] | None = None  # (host, port) when ADS is on
        self.ams_net_id: str | None = None  # the service's AMS Net ID when ADS is on
        self.keys: ServiceKeys | None = None  # set by start_service(keys=True)
        self._owned_keys: tempfile.TemporaryDirectory[str] | None = None
        self.log: list[str] = []
        self._changed = threading.Condition()
        self._ended = False  # stderr closed: the process is gone
        self._owned_dir = owned_dir
        threading.Thread(target=self._pump, name=f"cnc-service-{process.pid}-log",
                         daemon=True).start()

    def _pump(self) -> None:
        for line in self.process.stderr:  # type: ignore[union-attr]
            with self._changed:
                self.log.append(line.rstrip("\n"))
                self._changed.notify_all()
        with self._changed:
            self._ended = True
            self._changed.notify_all()

    @property
    def log_text(self) -> str:
        """The log so far as one text."""
        return "\n".join(self.log)

    def wait_for_log(self, pattern: str, timeout_s: float = 10.0) -> str:
        """The first log line (already logged or still to come) that matches the regular
        expression ``pattern``. Raises ``TimeoutError`` (with the log) when none comes
        within ``timeout_s``, ``RuntimeError`` when the service ends without it."""
        regex = re.compile(pattern)
        deadline = time.monotonic() + timeout_s
        seen = 0
        with self._changed:
            while True:
                for line in self.log[seen:]:
                    if regex.search(line):
                        return line
                seen = len(self.log)
                if self._ended:
                    raise RuntimeError(
                        f"cnc-service ended without logging {pattern!r}:\n{self.log_text}")
                left_s = deadline - time.monotonic()
                if left_s <= 0:
                    raise TimeoutError(f"cnc-service did not log {pattern!r} within "
                                       f"{timeout_s:g} s:\n{self.log_text}")
                self._changed.wait(left_s)

    def stop(self, timeout_s: float = STOP_TIMEOUT_S) -> int:
        """SIGINT, then the exit code (0: stopped cleanly). A service that has not ended
        ``timeout_s`` after SIGINT is killed; its code is then negative and the log says
        so. Removes the program store the service was started with, if it made one."""
        if self.process.poll() is None:
            self.process.send_signal(signal.SIGINT)
        try:
            code = self.process.wait(timeout_s)
        except subprocess.TimeoutExpired:
            self.process.kill()
            code = self.process.wait()
            self._join_log()
            with self._changed:
                self.log.append(f"(cnc-service did not stop within {timeout_s:g} s of "
                                "SIGINT: killed)")
        self._join_log()
        if self._owned_dir is not None:
            self._owned_dir.cleanup()
            self._owned_dir = None
        if self._owned_keys is not None:
            self._owned_keys.cleanup()
            self._owned_keys = None
        return code

    def _join_log(self) -> None:
        """Wait until the last lines the service wrote are in ``log``."""
        with self._changed:
            self._changed.wait_for(lambda: self._ended, STOP_TIMEOUT_S)


def service_command(*args: str) -> list[str]:
    """The command line ``start_service(*args)`` runs: ``cnc-service`` on a free loopback
    port with the virtual clock, ADS and OPC UA off, unless ``args`` name another
    endpoint, clock, ``--ads`` or ``--opcua`` address (the last occurrence of an option
    wins)."""
    argv = [sys.executable, "-m", "cnc_objects.service.main", "--endpoint", "tcp://127.0.0.1:*"]
    if "--clock" not in args:
        argv += ["--clock", "virtual"]
    if "--ads" not in args:
        argv += ["--ads", "off"]
    if "--opcua" not in args:  # services side by side never compete for port 4840
        argv += ["--opcua", "off"]
    return [*argv, *args]


#: The last byte of every loopback address ``free_loopback_ads_address`` gave.
_ADS_HOSTS_GIVEN: set[int] = set()


def free_loopback_ads_address() -> str:
    """``127.0.0.<n>:48898`` that nothing listens on right now (n in 2..254, chosen at
    random, so that parallel test runs rarely pick the same), and not given before in
    this process while another is left: AdsLib, pyads' router, keeps its connection to an
    address after a service there stopped, and a later service at the same address then
    gets no answer through it (pyads: "timeout elapsed (1861)")."""
    candidates = list(range(2, 255))
    random.shuffle(candidates)
    candidates.sort(key=lambda n: n in _ADS_HOSTS_GIVEN)  # the fresh ones first
    for n in candidates:
        host = f"127.0.0.{n}"
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
            try:
                probe.bind((host, AMS_TCP_PORT))
            except OSError:
                continue
        _ADS_HOSTS_GIVEN.add(n)
        return f"{host}:{AMS_TCP_PORT}"
    raise RuntimeError(f"no loopback address 127.0.0.2..254 has port {AMS_TCP_PORT} free")


def start_service(
    *args: str,
    program_dir: str | os.PathLike[str] | None = None,
    cwd: str | os.PathLike[str] | None = None,
    timeout_s: float = START_TIMEOUT_S,
    ads: bool | str = False,
    keys: bool | str | os.PathLike[str] = False,
    wrapper: tuple[str, ...] = (),
) -> ServiceProcess:
    """Start ``cnc-service`` (see ``service_command``) and return once it listens.

    ``program_dir``: the program store; by default an empty directory of this service
    only, removed by ``stop``. ``args`` are further ``cnc-service`` options (``--config
    FILE``, ``--speed 1``, ...). ``ads``: False leaves ADS off (unless ``args`` give
    ``--ads``); True serves ADS on a loopback address of this service's own,
    ``127.0.0.<n>:48898`` (another is tried when a parallel service took it first); a
    string is the ``--ads`` address. ``keys``: True makes CURVE keys of this service's
    own (``ServiceProcess.keys``, ``make_keys``); a path starts it with ``--keys PATH``.
    ``wrapper``: a command the service runs under (``setpriv ...`` to drop privileges).
    Raises ``RuntimeError`` with the service's log when it exits before listening,
    ``TimeoutError`` when it has not listened after ``timeout_s`` (the process is killed
    then).
    """
    if keys is True:
        owned = tempfile.TemporaryDirectory(prefix="cnc-keys-")
        made = make_keys(owned.name)
        try:
            service = start_service(*args, "--keys", str(made.directory), program_dir=program_dir,
                                    cwd=cwd, timeout_s=timeout_s, ads=ads, wrapper=wrapper)
        except BaseException:
            owned.cleanup()
            raise
        service.keys, service._owned_keys = made, owned
        return service
    if keys is not False:
        args = (*args, "--keys", os.fspath(keys))
    if ads is False or "--ads" in args:
        return _start(args, program_dir, cwd, timeout_s, wrapper)
    for _ in range(ADS_START_ATTEMPTS if ads is True else 1):
        address = free_loopback_ads_address() if ads is True else str(ads)
        try:
            return _start((*args, "--ads", address), program_dir, cwd, timeout_s, wrapper)
        except RuntimeError as exc:
            if ads is not True or _ADS_BUSY not in str(exc):
                raise
    raise RuntimeError(f"cnc-service found no free ADS address in {ADS_START_ATTEMPTS} tries")


def _start(args: tuple[str, ...], program_dir: str | os.PathLike[str] | None,
           cwd: str | os.PathLike[str] | None, timeout_s: float,
           wrapper: tuple[str, ...] = ()) -> ServiceProcess:
    owned = None
    if "--program-dir" in args:
        store = Path(args[args.index("--program-dir") + 1])
    elif program_dir is not None:
        store = Path(program_dir)
        args = (*args, "--program-dir", str(store))
    else:
        owned = tempfile.TemporaryDirectory(prefix="cnc-programs-")
        store = Path(owned.name) / "programs"  # the output area goes beside it, removed too
        args = (*args, "--program-dir", str(store))
    process = subprocess.Popen(
        [*wrapper, *service_command(*args)], cwd=cwd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE, text=True, errors="replace",
    )
    service = ServiceProcess(process, store, owned)
    try:
        line = service.wait_for_log(_LISTENING.pattern, timeout_s)
    except BaseException as exc:  # not listening: no process may be left behind
        if process.poll() is None:
            process.kill()
        code = service.stop()
        if isinstance(exc, RuntimeError):  # it ended by itself: say with which code
            raise RuntimeError(f"cnc-service exited with {code} before listening:\n"
                               f"{service.log_text}") from None
        raise
    service.endpoint = _LISTENING.search(line).group(1)  # type: ignore[union-attr]
    for logged in service.log:  # the ADS line comes before the ZeroMQ one
        found_output = _OUTPUT_AREA.search(logged)
        if found_output:
            service.output_dir = Path(found_output.group(1))
        found = _ADS_LISTENING.search(logged)
        if found:
            service.ads_address = (found.group(1), int(found.group(2)))
            service.ams_net_id = found.group(3)
    return service


@contextlib.contextmanager
def serving(*args: str, **options: object) -> Iterator[ServiceProcess]:
    """``start_service(*args, **options)`` for a ``with`` block. On leaving, the service
    must stop cleanly (exit code 0); otherwise ``AssertionError`` with its log."""
    service = start_service(*args, **options)  # type: ignore[arg-type]
    try:
        yield service
    finally:
        code = service.stop()
        assert code == 0, f"cnc-service exited with {code}:\n{service.log_text}"
