"""How many connections cnc-web holds, and how long one may take to send a request.

Each connection is wrapped in a ``ConnectionGuard`` (an asyncio protocol in front of
aiohttp's own):

- at most ``max_connections`` are open at once; one more is answered ``503 Service
  Unavailable`` with ``Retry-After: 1`` before anything is read, and closed: its sending
  side at once, the socket when the client closes or ``REFUSED_LINGER_S`` later (what
  it sent is discarded; closing at once would reset the connection and could lose the
  answer). The connections already open (a browser's pages, its WebSocket) go on.
- a connection that is not inside a request is closed when ``header_timeout_s`` passes:
  a request's line and headers must arrive within that time of the connection opening or
  of the previous response, so half-sent requests do not hold sockets. Inside a request
  (its handler running: an upload being read, a dry run, a WebSocket) nothing is timed
  here; a response still being sent when the time is up gets its time again.

``serve`` runs the application behind these guards until SIGINT or SIGTERM.
"""

from __future__ import annotations

import asyncio
import json
import logging
import signal
from collections.abc import Callable
from dataclasses import dataclass

from aiohttp import web

from .access import Handler

log = logging.getLogger(__name__)

MAX_CONNECTIONS = 256  # browsers open ~6 each; file descriptors stay far below 1024
HEADER_TIMEOUT_S = 10.0  # to send a request's headers, from the connection or last response
REFUSED_LINGER_S = 1.0  # a refused connection's socket, after its 503, until closed
KEEPALIVE_TIMEOUT_S = 75.0  # aiohttp's idle keep-alive (run_app's default), after ours

_OVER_CAP_BODY = json.dumps({"error": "cnc-web has too many connections open: try again"})
OVER_CAP_RESPONSE = (
    "HTTP/1.1 503 Service Unavailable\r\nContent-Type: application/json\r\n"
    f"Retry-After: 1\r\nConnection: close\r\nContent-Length: {len(_OVER_CAP_BODY)}\r\n\r\n"
    f"{_OVER_CAP_BODY}").encode("ascii")


@dataclass(frozen=True)
class ConnectionLimits:
    """The connection cap and the header timeout of one cnc-web."""

    max_connections: int = MAX_CONNECTIONS
    header_timeout_s: float = HEADER_TIMEOUT_S


@dataclass
class ConnectionCount:
    """The connections open now (admitted ones only)."""

    open: int = 0


class ConnectionGuard(asyncio.Protocol):
    """One connection: refused over the cap, closed when its request is slow to come;
    everything else goes to aiohttp's protocol (``make_inner()``)."""

    def __init__(self, make_inner: Callable[[], asyncio.Protocol], limits: ConnectionLimits,
                 count: ConnectionCount) -> None:
        self._make_inner = make_inner
        self._limits = limits
        self._count = count
        self._inner: asyncio.Protocol | None = None
        self._transport: asyncio.Transport | None = None
        self._timer: asyncio.TimerHandle | None = None
        self._requests = 0  # requests whose handler runs now on this connection

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        """Admit the connection (its header timer starts), or answer 503 and close it."""
        assert isinstance(transport, asyncio.Transport)
        if self._count.open >= self._limits.max_connections:
            log.warning("connection from %s refused: %d connections are open (the cap)",
                        transport.get_extra_info("peername"), self._count.open)
            transport.write(OVER_CAP_RESPONSE)
            transport.write_eof()
            self._timer = asyncio.get_running_loop().call_later(REFUSED_LINGER_S, transport.close)
            return
        self._count.open += 1
        self._transport = transport
        self._inner = self._make_inner()
        self._inner.connection_made(transport)
        self._arm()

    def data_received(self, data: bytes) -> None:
        """Bytes for aiohttp (a refused connection's are discarded)."""
        if self._inner is not None:
            self._inner.data_received(data)

    def eof_received(self) -> bool | None:
        """The peer closed its side (a refused connection then closes)."""
        return self._inner.eof_received() if self._inner is not None else False

    def pause_writing(self) -> None:
        """The send buffer is full (aiohttp waits)."""
        if self._inner is not None:
            self._inner.pause_writing()

    def resume_writing(self) -> None:
        """The send buffer drained."""
        if self._inner is not None:
            self._inner.resume_writing()

    def connection_lost(self, exc: Exception | None) -> None:
        """The connection ended: it no longer counts."""
        self._disarm()
        if self._inner is not None:
            self._count.open -= 1
            inner, self._inner = self._inner, None
            inner.connection_lost(exc)

    def request_started(self) -> None:
        """A request's headers came (its handler runs now): no timer while it runs."""
        self._requests += 1
        self._disarm()

    def request_ended(self) -> None:
        """The handler returned: the next request's headers are timed from now."""
        self._requests -= 1
        if self._requests == 0 and self._inner is not None:
            self._arm()

    def _arm(self) -> None:
        self._disarm()
        loop = asyncio.get_running_loop()
        self._timer = loop.call_later(self._limits.header_timeout_s, self._expire)

    def _disarm(self) -> None:
        if self._timer is not None:
            self._timer.cancel()
            self._timer = None

    def _expire(self) -> None:
        self._timer = None
        if self._transport is None or self._requests:
            return
        if self._transport.get_write_buffer_size():  # a response still being sent
            self._arm()
            return
        log.debug("connection from %s closed: no request within %g s",
                  self._transport.get_extra_info("peername"), self._limits.header_timeout_s)
        self._transport.close()


@web.middleware
async def connection_middleware(request: web.Request, handler: Handler) -> web.StreamResponse:
    """Tell the connection's guard that a request runs (its header timer stops)."""
    guard = request.transport.get_protocol() if request.transport is not None else None
    if not isinstance(guard, ConnectionGuard):  # a server without guards (aiohttp's own)
        return await handler(request)
    guard.request_started()
    try:
        return await handler(request)
    finally:
        guard.request_ended()


def serve(app: web.Application, host: str, port: int, limits: ConnectionLimits) -> None:
    """Serve ``app`` on ``host``:``port`` behind the guards until SIGINT or SIGTERM."""
    asyncio.run(_serve(app, host, port, limits))


async def _serve(app: web.Application, host: str, port: int, limits: ConnectionLimits) -> None:
    runner = web.AppRunner(app, handle_signals=False, access_log=None,
                           keepalive_timeout=KEEPALIVE_TIMEOUT_S)
    await runner.setup()
    server_factory = runner.server
    assert server_factory is not None  # set up above
    loop = asyncio.get_running_loop()
    stop = asyncio.Event()
    for signum in (signal.SIGINT, signal.SIGTERM):
        loop.add_signal_handler(signum, stop.set)
    count = ConnectionCount()
    listening = await loop.create_server(
        lambda: ConnectionGuard(server_factory, limits, count), host, port)
    try:
        await stop.wait()
    finally:
        listening.close()
        await runner.cleanup()
