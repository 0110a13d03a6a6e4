"""The blocking transport and the driver that runs client coroutines on it.

``SyncTransport``'s awaitables yield themselves to ``drive``, which performs the socket
I/O and sends the result back into the coroutine, so the blocking client runs the same
method bodies as the async one, without an event loop or a thread.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Coroutine, Generator
from typing import Any, TypeVar

import zmq

from cnc_objects.protocol.errors import ProtocolError
from cnc_objects.protocol.frames import RawSample, Response, decode_incoming

from .curve import ClientCurve, HandshakeWatch
from .errors import AdsConnectionError
from .transport_base import _NOBLOCK, _new_socket, _Transport

log = logging.getLogger(__name__)
T = TypeVar("T")


class _Pending:
    """An awaitable that yields itself to ``drive``, which sends back the result."""

    __slots__ = ("transport", "invoke_id", "frame", "command", "handle")

    def __init__(
        self,
        transport: SyncTransport,
        invoke_id: int = 0,
        frame: bytes = b"",
        command: int = 0,
        handle: int = 0,
    ) -> None:
        self.transport = transport
        self.invoke_id = invoke_id  # 0: waiting for a sample of ``handle``
        self.frame = frame
        self.command = command
        self.handle = handle

    def __await__(self) -> Generator[_Pending, Any, Any]:
        return (yield self)


class _Pause:
    """An awaitable that makes ``drive`` sleep (the blocking client's asyncio.sleep)."""

    __slots__ = ("seconds",)

    def __init__(self, seconds: float) -> None:
        self.seconds = seconds

    @property
    def transport(self) -> _Pause:
        return self

    def perform(self, pause: _Pause) -> None:
        time.sleep(pause.seconds)

    def __await__(self) -> Generator[_Pause, Any, Any]:
        return (yield self)


class SyncTransport(_Transport):
    """DEALER socket used by blocking calls; no event loop, no thread."""

    def __init__(self, endpoint: str, timeout_s: float, context: zmq.Context[zmq.Socket[bytes]] | None = None,
                 curve: ClientCurve | None = None) -> None:
        super().__init__(endpoint, timeout_s, curve)
        self._context = context or zmq.Context.instance()
        self._sock: zmq.Socket[bytes] | None = None
        self._watch: HandshakeWatch | None = None
        self._shaken = False  # a handshake succeeded: requests go straight out

    async def open(self) -> None:
        """Connect. Replies are awaited by a blocking receive with a timeout (cheaper
        than polling first); the first request waits for the handshake instead, so that
        a refusal is told at once (``HandshakeWatch``)."""
        sock, self._watch = _new_socket(self._context, self.endpoint, self.curve)
        self._sock = sock
        self._shaken = self.endpoint.startswith("inproc://")  # inproc has no handshake
        self._timeout_ms = max(1, int(self.timeout_s * 1000))
        sock.setsockopt(zmq.RCVTIMEO, self._timeout_ms)
        raw: Any = zmq.Socket.__mro__[1]  # the Cython methods, without pyzmq's Python wrappers
        self._raw_send = raw.send.__get__(sock)
        self._raw_recv = raw.recv.__get__(sock)

    async def close(self) -> None:
        """Disconnect."""
        if self._watch is not None:
            self._watch.close()
            self._watch = None
        if self._sock is not None:
            self._sock.close(linger=0)
            self._sock = None

    def pause(self, seconds: float) -> _Pause:
        """Await to wait ``seconds`` of wall time (blocking)."""
        return _Pause(seconds)

    def exchange(self, command: int, port: int, fields: tuple[Any, ...]) -> _Pending:
        """Awaitable reply to a request (performed by ``drive``)."""
        invoke_id, frame = self._frame(command, port, fields)
        return _Pending(self, invoke_id, frame, command)

    def next_sample(self, handle: int) -> _Pending:
        """Awaitable next sample of ``handle`` (performed by ``drive``)."""
        return _Pending(self, handle=handle)

    def perform(self, pending: _Pending) -> Response | RawSample:
        """Do the blocking I/O a ``_Pending`` stands for."""
        sock = self._sock
        if sock is None:
            raise AdsConnectionError(0x748, "the client is not connected; use 'with'")
        invoke_id = pending.invoke_id
        if not invoke_id:
            buffer = self._samples[pending.handle]
            sock.setsockopt(zmq.RCVTIMEO, -1)  # samples come when they come
            try:
                while not buffer:
                    self._receive(sock)
            finally:
                sock.setsockopt(zmq.RCVTIMEO, self._timeout_ms)
            return buffer.popleft()
        deadline = time.monotonic() + self.timeout_s
        shortened = False
        if not self._shaken:
            self._handshake(pending.command)
            sock.setsockopt(zmq.RCVTIMEO, max(1, int((deadline - time.monotonic()) * 1000)))
            shortened = True  # the reply gets what the handshake left of the timeout
        try:
            self._raw_send(pending.frame, _NOBLOCK)
        except zmq.Again:
            if shortened:
                sock.setsockopt(zmq.RCVTIMEO, self._timeout_ms)
            raise AdsConnectionError(0x748, "send queue full; the service is not reading") from None
        try:
            message = self._receive(sock)
            while message is None or message.invoke_id != invoke_id:
                # A notification or a late reply came first: wait only for what is left.
                left_ms = int((deadline - time.monotonic()) * 1000)
                if left_ms <= 0:
                    raise zmq.Again()
                sock.setsockopt(zmq.RCVTIMEO, left_ms)
                shortened = True
                message = self._receive(sock)
            return message
        except zmq.Again:
            self._handshake_failure()  # a refusal explains the silence: say it instead
            raise self._timeout(pending.command) from None
        finally:
            if shortened:
                sock.setsockopt(zmq.RCVTIMEO, self._timeout_ms)

    def _handshake(self, command: int) -> None:
        """Wait (up to the timeout) until the connection's handshake has ended; raise
        ``AuthenticationError`` when the service refused it, ``NoReplyError`` when none
        ended (no service)."""
        watch = self._watch
        if watch is None or not watch.wait(self.timeout_s):
            raise self._timeout(command)
        self._handshake_failure()
        self._shaken = True

    def _handshake_failure(self) -> None:
        if self._watch is not None and self._watch.check() is not None:
            self._shaken = False
            raise self._watch.failure  # type: ignore[misc]

    def _receive(self, sock: zmq.Socket[bytes]) -> Response | None:
        raw = self._raw_recv(0)
        try:
            message = decode_incoming(raw)
        except ProtocolError as exc:
            log.warning("dropped an unreadable frame from %s: %s", self.endpoint, exc)
            return None
        if type(message) is Response:
            return message  # a late reply to a timed-out request is dropped by the caller
        self._route(message)  # type: ignore[arg-type]
        return None


def drive(coro: Coroutine[Any, Any, T]) -> T:
    """Run a client coroutine to completion on a ``SyncTransport``, blocking."""
    send: Any = None
    error: BaseException | None = None
    while True:
        try:
            pending = coro.throw(error) if error is not None else coro.send(send)
        except StopIteration as stop:
            result: T = stop.value
            return result
        try:
            send, error = pending.transport.perform(pending), None
        except BaseException as exc:
            send, error = None, exc
