"""The OPC UA process: ``python -m cnc_objects.service.opcua.child CALLS_FD EVENTS_FD``,
spawned and supervised by cnc-service (``host``), never started by hand.

It imports asyncua and the front end while the service builds its kernel, then waits
for the START frame (what to serve: the objects, the machine's configuration, where to
listen, security, limits, logging), builds the OPC UA server over a ``LinkedBackend``
and answers READY (or FAILED with the one line the service prints, and ends). It serves
until SIGTERM or until the service's end of the link closes; SIGINT (a terminal's
Ctrl-C reaches the whole process group) is left to the service, which then stops it.
"""

from __future__ import annotations

import asyncio
import logging
import os
import signal
import socket
import sys
from typing import Any

from .limits import OpcUaLimits
from .link_frames import FrameBuffer, Link, frame
from .linked_backend import CallLink, LinkedBackend
from .security import OpcUaSecurityError
from .server import OpcUaServer

log = logging.getLogger("cnc_objects.service.opcua.child")  # not __main__ (run with -m)


class _Events(asyncio.Protocol):
    """The events socket, child end: START, NOTIFY and WRITTEN in; WRITE, UNSUBSCRIBE,
    READY and FAILED out."""

    def __init__(self) -> None:
        self.frames = FrameBuffer()
        self.started: asyncio.Future[dict[str, Any]] = asyncio.get_running_loop().create_future()
        self.closed = asyncio.Event()
        self.backend: LinkedBackend | None = None
        self.transport: asyncio.Transport | None = None

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        assert isinstance(transport, asyncio.Transport)
        self.transport = transport

    def send(self, message: tuple[Any, ...]) -> None:
        if self.transport is not None and not self.transport.is_closing():
            self.transport.write(frame(message))

    def data_received(self, data: bytes) -> None:
        backend = self.backend
        for message in self.frames.feed(data):
            match message[0]:
                case Link.NOTIFY if backend is not None:
                    backend.hub.notified(message[1], message[2], message[3])
                case Link.WRITTEN if backend is not None:
                    backend.written(message[1], message[2])
                case Link.START if not self.started.done():
                    self.started.set_result(message[1])
                case _:
                    log.error("OPC UA process: unexpected link frame %r", message[0])

    def connection_lost(self, exc: Exception | None) -> None:
        if self.backend is not None:
            self.backend.link_lost()
        if not self.started.done():
            self.started.set_exception(ConnectionError("the service closed the OPC UA link"))
        self.closed.set()


async def serve(calls_fd: int, events_fd: int) -> int:
    """Serve OPC UA as the service's START frame says; the exit code."""
    loop = asyncio.get_running_loop()
    events = _Events()
    await loop.connect_accepted_socket(lambda: events, socket.socket(fileno=events_fd))
    try:
        facts = await events.started
    except ConnectionError:
        return 1
    logging.basicConfig(level=facts["log_level"], format=facts["log_format"])
    backend = LinkedBackend(facts["objects"], facts["machine"],
                            CallLink(socket.socket(fileno=calls_fd)), events.send)
    events.backend = backend
    server = OpcUaServer(backend, facts["security"], OpcUaLimits.from_config(facts["limits"]))
    host, port = facts["host"], facts["port"]
    try:
        await server.start(host, port)
    except OpcUaSecurityError as exc:
        await _refuse(server, events, f"cannot serve OPC UA on {host}:{port}: {exc}")
        return 2
    except OSError as exc:
        reason = os.strerror(exc.errno) if exc.errno and exc.errno > 0 else exc.strerror or str(exc)
        await _refuse(server, events, f"cannot listen for OPC UA on {host}:{port}: {reason}")
        return 2
    stop = asyncio.Event()
    loop.add_signal_handler(signal.SIGTERM, stop.set)
    events.send((Link.READY, {"url": server.url, "security_note": server.security_note,
                              "start_s": server.start_s, "cache_note": server.cache_note,
                              "port": server.address[1]}))
    ended = asyncio.ensure_future(events.closed.wait())
    stopped = asyncio.ensure_future(stop.wait())
    try:
        await asyncio.wait([ended, stopped], return_when=asyncio.FIRST_COMPLETED)
    finally:
        ended.cancel()
        stopped.cancel()
    if not stop.is_set():  # the service is gone (killed): nothing left to serve from, and
        # every getter would fail until asyncua had closed its sessions one by one
        log.error("the service closed the OPC UA link: the OPC UA process ends")
        logging.shutdown()
        os._exit(1)
    await server.close()
    return 0


async def _refuse(server: OpcUaServer, events: _Events, line: str) -> None:
    """Tell the service the one line it prints, and close what was built."""
    events.send((Link.FAILED, line))
    await server.close()
    if events.transport is not None:
        events.transport.close()


def main(argv: list[str]) -> int:
    """The entry point: ``CALLS_FD EVENTS_FD``, the sockets the service passed."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # the service stops us (module docstring)
    return asyncio.run(serve(int(argv[0]), int(argv[1])))


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
