"""cnc-service's end of the OPC UA process (``child``): it spawns the process, serves its
calls on the real ``Backend`` and supervises it (docs/opcua.md "One process of its own").

asyncua's work (sessions, Read, publish, encoding) runs in that process, under a GIL of
its own: the kernel's cycle thread no longer waits behind it. What stays here is what
every front end costs the service: the getters a Read calls, the notification hub's
samples (forwarded as they are, one frame per batch), the writes queued for the kernel.

Two socket pairs link the processes, both inherited by the child and held by no one else:

- calls (the child waits for each answer): READ of objects by handle, SUBSCRIBE at the
  hub;
- events (both ways, never waited for): NOTIFY samples and WRITTEN answers to the child,
  WRITE, UNSUBSCRIBE, READY and FAILED from it.

The child decides roles (``protocol.roles``, the rule every front end applies) as the
in-process front end did; the link is trusted as the loop's own calls were. A child
that ends while serving is logged and started again (``RESTARTS_MAX`` times within
``RESTART_WINDOW_S``, then OPC UA stays off and the log says so); its subscriptions at
the hub end with it.
"""

from __future__ import annotations

import asyncio
import itertools
import logging
import signal
import socket
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from cnc_objects.protocol.errors import AdsReturnCode

from ..backend import Backend
from .link_frames import FrameBuffer, HubWatch, Link, ReadFailed, frame

log = logging.getLogger(__name__)

CHILD_MODULE = "cnc_objects.service.opcua.child"
#: How long the child may take from its START to READY (a cold start imports the
#: nodesets: seconds, more under load).
START_TIMEOUT_S = 300.0
#: How long a stopped child may take to close its sessions before it is killed.
STOP_TIMEOUT_S = 5.0
RESTARTS_MAX = 3  # restarts of a child that keeps ending within ...
RESTART_WINDOW_S = 60.0  # ... this long of its previous start; then OPC UA stays off
#: Bytes of notifications waiting for a child that does not read them: beyond, the hub
#: counts its samples as dropped (as for a ZeroMQ client whose queue is full).
EVENTS_BUFFER_MAX_BYTES = 16 << 20


@dataclass(frozen=True)
class Ready:
    """What a child serves, for the start-up log line."""

    url: str
    security_note: str
    start_s: float
    cache_note: str
    port: int  # where it listens (the one asked for, or the one given for 0)
    pid: int  # the process's


class OpcUaRefused(Exception):
    """The child could not serve: the one line to print (exit code 2)."""


class _Link:
    """One child's two sockets, served on the loop over ``backend``."""

    def __init__(self, backend: Backend, generation: int, pid: int) -> None:
        self.backend = backend
        self.generation = generation
        self.pid = pid
        self.getters: dict[int, Callable[[], Any]] = {}
        self.subscriptions: dict[int, Any] = {}  # the hub's handle -> its envelope
        self.answer: asyncio.Future[Ready] = backend.loop.create_future()
        self.ended = asyncio.Event()
        self.calls: asyncio.Transport | None = None
        self.events: asyncio.Transport | None = None
        self._out: list[bytes] = []

    # ------------------------------------------------------------ sending events

    def send(self, message: tuple[Any, ...]) -> bool:
        """Queue an event frame for the child (written once per loop pass); False when
        the child does not read them (``EVENTS_BUFFER_MAX_BYTES``) or is gone."""
        events = self.events
        if events is None or events.is_closing():
            return False
        if events.get_write_buffer_size() > EVENTS_BUFFER_MAX_BYTES:
            return False
        if not self._out:
            self.backend.loop.call_soon(self._flush)
        self._out.append(frame(message))
        return True

    def _flush(self) -> None:
        out, self._out = self._out, []
        events = self.events
        if events is not None and not events.is_closing():
            events.write(b"".join(out))

    # ------------------------------------------------------------ calls

    def attach_calls(self, transport: asyncio.Transport) -> None:
        """The calls socket's transport (the child's blocking calls)."""
        self.calls = transport

    def attach_events(self, transport: asyncio.Transport) -> None:
        """The events socket's transport (notifications and write answers go there)."""
        self.events = transport

    def answer_call(self, transport: asyncio.Transport, message: tuple[Any, ...]) -> None:
        """A call of the child, answered on its socket."""
        transport.write(frame(self.call(message)))

    def take_event(self, _: asyncio.Transport, message: tuple[Any, ...]) -> None:
        """An event of the child (its writes, its unsubscribes)."""
        self.event(message)

    def call(self, message: tuple[Any, ...]) -> tuple[Any, ...]:
        """Answer a frame of the calls socket."""
        match message[0]:
            case Link.READ:
                return Link.READ, [self._read(h) for h in message[1]]
            case Link.SUBSCRIBE:
                _, key, envelope, watch, cycle_ns = message
                return (Link.SUBSCRIBE, *self._subscribe(key, envelope, HubWatch(*watch), cycle_ns))
        raise ValueError(f"unknown call {message[0]!r}")

    def _read(self, handle: int) -> Any:
        get = self.getters.get(handle)
        if get is None:
            entry = self.backend.space.by_handle(handle)
            if entry is None or entry.read is None:
                return ReadFailed(f"no readable object with handle {handle}")
            get = self.getters[handle] = entry.read
        try:
            return get()
        except Exception as exc:  # the child logs it as the in-process front end did
            return ReadFailed(f"{type(exc).__name__}: {exc}")

    def _subscribe(self, key: int, envelope: Any, watch: HubWatch, cycle_ns: int
                   ) -> tuple[int, int | str]:
        # the hub counts its limits per client: the child's variable, of this child
        ours = ((*envelope[0], self.generation), *envelope[1:])
        send = self.send

        def notify(_: Any, port: int, samples: list[list[Any]]) -> bool:
            return send((Link.NOTIFY, key, port, samples))

        code, answer = self.backend.hub.add(ours, watch, cycle_ns, notify)
        if not code:
            self.subscriptions[answer] = ours  # type: ignore[index]
        return code, answer

    # ------------------------------------------------------------ events

    def event(self, message: tuple[Any, ...]) -> None:
        """A frame of the events socket."""
        match message[0]:
            case Link.WRITE:
                self._write(message[1], message[2], message[3])
            case Link.UNSUBSCRIBE:
                envelope = self.subscriptions.pop(message[2], None)
                if envelope is not None:
                    self.backend.hub.delete(envelope, message[2])
            case Link.READY if not self.answer.done():
                self.answer.set_result(Ready(**message[1], pid=self.pid))
            case Link.FAILED if not self.answer.done():
                self.answer.set_exception(OpcUaRefused(message[1]))
            case _:
                log.error("OPC UA process: unexpected link frame %r", message[0])

    def _write(self, call: int, items: list[tuple[int, bytes]], holder: Any) -> None:
        """Decode the writes with the service's address space and queue them for the
        kernel; WRITTEN once it applied them (a refusal in decoding answers at once)."""
        backend = self.backend
        decoded = []
        for handle, data in items:
            entry = backend.space.by_handle(handle)
            if entry is None:
                self.send((Link.WRITTEN, call, [(AdsReturnCode.DEVICE_SYMBOLNOTFOUND,
                                                  f"no object with handle {handle}")]))
                return
            obj = entry.obj
            code, message, writes = backend.decode_writes(obj.port, obj.group, obj.offset, data)
            if code:
                self.send((Link.WRITTEN, call, [(code, message)]))
                return
            decoded.extend(writes)

        def applied(results: list[tuple[int, str]]) -> None:
            self.send((Link.WRITTEN, call, results))

        backend.apply_writes(decoded, applied, holder=holder)

    def lost(self) -> None:
        """The child is gone: its subscriptions end, its calls socket is closed."""
        if self.calls is not None:
            self.calls.close()
        subscriptions, self.subscriptions = self.subscriptions, {}
        for handle, envelope in subscriptions.items():
            self.backend.hub.delete(envelope, handle)
        if not self.answer.done():
            self.answer.set_exception(ConnectionError("the OPC UA process ended"))
        self.ended.set()


class _LinkSocket(asyncio.Protocol):
    """One socket of a child's link: its transport handed to ``attach``, its frames each
    to ``handle`` (which may answer on the transport), its end to ``lost``; a frame that
    fails closes the link (the child is ours: a bad frame is a broken child)."""

    def __init__(self, what: str, attach: Callable[[asyncio.Transport], None],
                 handle: Callable[[asyncio.Transport, tuple[Any, ...]], None],
                 lost: Callable[[], None] = lambda: None) -> None:
        self.what, self.attach, self.handle, self.lost = what, attach, handle, lost
        self.frames = FrameBuffer()
        self.transport: asyncio.Transport | None = None

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        assert isinstance(transport, asyncio.Transport)
        self.transport = transport
        self.attach(transport)

    def data_received(self, data: bytes) -> None:
        assert self.transport is not None
        try:
            for message in self.frames.feed(data):
                self.handle(self.transport, message)
        except Exception:
            log.exception("OPC UA process: a bad %s; the link is closed", self.what)
            self.transport.close()

    def connection_lost(self, exc: Exception | None) -> None:
        self.lost()


class OpcUaProcess:
    """The OPC UA process of one service: ``spawn`` early (it imports asyncua while the
    service builds its kernel), ``start`` once the backend exists, ``close`` at the end."""

    def __init__(self, host: str, port: int, security: Any, limits: Any) -> None:
        self.host, self.port = host, port
        self._facts = {"host": host, "port": port, "security": security, "limits": limits}
        self._generation = itertools.count(1)
        self._process: asyncio.subprocess.Process | None = None
        self._sockets: tuple[socket.socket, socket.socket] | None = None
        self._link: _Link | None = None
        self._backend: Backend | None = None
        self._supervisor: asyncio.Task[None] | None = None
        self._closing = False

    async def spawn(self) -> None:
        """Start the process; it waits for ``start``."""
        calls, child_calls = socket.socketpair()
        events, child_events = socket.socketpair()
        fds = (child_calls.fileno(), child_events.fileno())
        try:
            self._process = await asyncio.create_subprocess_exec(
                sys.executable, "-m", CHILD_MODULE, *(str(fd) for fd in fds), pass_fds=fds)
        finally:
            child_calls.close()
            child_events.close()
        self._sockets = (calls, events)

    async def start(self, backend: Backend) -> Ready:
        """Send the child what it serves and wait until it serves; ``OpcUaRefused`` with
        the line to print when it cannot (the child has ended then)."""
        self._backend = backend
        if self._process is None:
            await self.spawn()
        ready = await self._start_child(backend)
        self._facts["port"] = ready.port  # a child started again listens where this one did
        self._supervisor = backend.loop.create_task(self._supervise(), name="opcua-supervisor")
        return ready

    async def _start_child(self, backend: Backend) -> Ready:
        assert self._sockets is not None and self._process is not None
        calls, events = self._sockets
        self._sockets = None
        link = _Link(backend, next(self._generation), self._process.pid)
        loop = backend.loop
        await loop.connect_accepted_socket(
            lambda: _LinkSocket("call", link.attach_calls, link.answer_call), calls)
        await loop.connect_accepted_socket(
            lambda: _LinkSocket("event", link.attach_events, link.take_event, link.lost),
            events)
        self._link = link
        root = logging.getLogger()
        formatter = root.handlers[0].formatter if root.handlers else None
        link.send((Link.START, {
            **self._facts, "objects": backend.space.objects(),
            "machine": backend.kernel.config, "log_level": root.getEffectiveLevel(),
            "log_format": getattr(formatter, "_fmt", None) or logging.BASIC_FORMAT}))
        try:
            async with asyncio.timeout(START_TIMEOUT_S):
                return await link.answer
        except ConnectionError as exc:
            code = await self._process.wait()
            raise OpcUaRefused(f"the OPC UA process ended (exit code {code}) before it "
                               "served") from exc
        except OpcUaRefused:
            await self._stop_process()
            raise
        except TimeoutError:
            await self._stop_process()
            raise OpcUaRefused(f"the OPC UA process did not serve within {START_TIMEOUT_S:g} s"
                               ) from None

    async def _supervise(self) -> None:
        """Start a child again when it ends while serving (module docstring)."""
        starts: list[float] = []
        while True:
            link = self._link
            assert link is not None and self._process is not None
            await link.ended.wait()
            code = await self._process.wait()
            if self._closing:
                return
            now = time.monotonic()
            starts = [t for t in starts if now - t < RESTART_WINDOW_S]
            if len(starts) >= RESTARTS_MAX:
                log.error("the OPC UA process ended (exit code %s), %d times within %g s: "
                          "OPC UA is off", code, len(starts) + 1, RESTART_WINDOW_S)
                return
            log.error("the OPC UA process ended (exit code %s): starting it again", code)
            starts.append(now)
            assert self._backend is not None
            try:
                await self.spawn()
                ready = await self._start_child(self._backend)
            except (OpcUaRefused, OSError) as exc:
                log.error("OPC UA is off: %s", exc)
                return
            log.info("OPC UA on %s again (built in %.2f s; process %d)", ready.url,
                     ready.start_s, ready.pid)

    async def _stop_process(self) -> None:
        process = self._process
        if process is None or process.returncode is not None:
            return
        process.send_signal(signal.SIGTERM)
        try:
            async with asyncio.timeout(STOP_TIMEOUT_S):
                await process.wait()
        except TimeoutError:
            log.warning("the OPC UA process did not stop within %g s: killed", STOP_TIMEOUT_S)
            process.kill()
            await process.wait()

    async def close(self) -> None:
        """Stop the child (its sessions close) and the supervision."""
        self._closing = True
        if self._supervisor is not None:
            self._supervisor.cancel()
        await self._stop_process()
        link = self._link
        for transport in (link.calls, link.events) if link is not None else ():
            if transport is not None:
                transport.close()
        if self._sockets is not None:
            for sock in self._sockets:
                sock.close()
