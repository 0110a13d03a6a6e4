"""Transports: move frames between a client and the service over a ZeroMQ DEALER socket.

The client's methods are written once, as coroutines that ``await`` only two things of
their transport: ``exchange(command, port, fields)`` (a reply) and ``next_sample(handle)`` (a
notification sample). ``AsyncTransport`` (here) answers them on the event loop, with many
requests in flight matched by invoke id; ``SyncTransport`` (``sync_transport``) answers
them by blocking on the socket.

With ``curve`` (``clients.curve``) the socket is a CURVE client; either way a
``HandshakeWatch`` reads the socket's handshake events, so a service that refuses the
client (its key, or its lack of one) fails the requests with ``AuthenticationError``
instead of letting them time out.
"""

from __future__ import annotations

import asyncio
import logging
from typing import Any

import zmq

from cnc_objects.protocol.errors import ProtocolError
from cnc_objects.protocol.frames import RawSample, Response, decode_incoming

from .batching import QueuedRequest, ReplyWaiter, SumBatch, batchable, chunks, runs, sum_fields
from .client_core import SAMPLE_BUFFER as SAMPLE_BUFFER  # re-exported: its old home
from .curve import ClientCurve, HandshakeWatch
from .errors import AdsConnectionError, AuthenticationError, ServiceFullError
from .transport_base import (  # noqa: F401  (EARLY_HANDLES: its old home)
    _NOBLOCK,
    EARLY_HANDLES,
    _new_socket,
    _Transport,
)

log = logging.getLogger(__name__)


# --------------------------------------------------------------------------- async


class AsyncTransport(_Transport):
    """DEALER socket on the running event loop; replies matched to futures by invoke id.

    Timeouts are enforced by one sweeper task (every quarter of the timeout) rather than
    a timer per request: with many requests in flight a timer each costs more than the
    request itself. A request therefore fails between 1 and 1.25 timeouts after it was
    sent, with ``NoReplyError`` (an ``AdsTimeoutError``).

    ``batch``: the reads and writes of one loop turn go out as sum commands
    (``clients.batching``); False sends each request as its own frame.
    """

    def __init__(self, endpoint: str, timeout_s: float, context: zmq.Context[zmq.Socket[bytes]] | None = None,
                 curve: ClientCurve | None = None, batch: bool = True) -> None:
        super().__init__(endpoint, timeout_s, curve)
        self.batch = batch
        self.frames_sent = 0  # request frames handed to ZeroMQ: what batching saves
        self._context = context or zmq.Context.instance()
        self._sock: zmq.Socket[bytes] | None = None
        self._watch: HandshakeWatch | None = None
        # what a request on a closed transport raises: not connected, or refused
        self._closed: AdsConnectionError = AdsConnectionError(
            0x748, "the client is not connected; use 'async with'")
        self._loop: asyncio.AbstractEventLoop | None = None
        # invoke id -> (future or sum batch, sweep generation when sent, command id)
        self._pending: dict[int, tuple[ReplyWaiter, int, int]] = {}
        self._generation = 0
        self._sample_waiters: dict[int, asyncio.Future[None]] = {}
        self._drain_scheduled = False
        # encoded frames, and (batching) reads and writes not yet encoded
        self._outbox: list[tuple[int, bytes] | QueuedRequest] = []
        self._batched = False  # the outbox holds a QueuedRequest
        self._sweeper: asyncio.Task[None] | None = None

    async def open(self) -> None:
        """Connect (ZeroMQ connects in the background; requests queue until it has)."""
        self._loop = asyncio.get_running_loop()
        sock, watch = _new_socket(self._context, self.endpoint, self.curve)
        self._sock, self._watch = sock, watch
        raw: Any = zmq.Socket.__mro__[1]  # the Cython methods, without pyzmq's Python wrappers
        self._raw_send = raw.send.__get__(sock)
        self._raw_recv = raw.recv.__get__(sock)
        self._raw_get = raw.get.__get__(sock)
        self._loop.add_reader(sock.FD, self._drain)
        self._loop.add_reader(watch.fd, self._check_handshake)
        self._loop.call_soon(self._check_handshake)  # the edge-triggered fd may not say
        self._sweeper = self._loop.create_task(self._sweep(), name="cnc-client-timeouts")

    async def close(self) -> None:
        """Disconnect; requests still waiting fail with AdsConnectionError."""
        self._shut(AdsConnectionError(0x748, "the client was closed"))

    def _check_handshake(self) -> None:
        """A handshake the service refused closes the transport: every request fails
        with the reason, now and later (ZeroMQ would not retry a refused key anyway)."""
        if self._watch is not None and self._watch.check() is not None:
            self._shut(self._watch.failure)  # type: ignore[arg-type]

    def _shut(self, closed: AdsConnectionError) -> None:
        """Close the socket; pending requests and sample waits fail with ``closed``."""
        if self._sock is None:
            return
        if self._sweeper is not None:
            self._sweeper.cancel()
        loop = self._loop
        loop.remove_reader(self._sock.FD)  # type: ignore[union-attr]
        if self._watch is not None:
            loop.remove_reader(self._watch.fd)  # type: ignore[union-attr]
            self._watch.close()
            self._watch = None
        self._sock.close(linger=0)
        self._sock = None
        if isinstance(closed, (AuthenticationError, ServiceFullError)):  # later ones say why
            self._closed = closed
        for fut, _, _ in self._pending.values():
            if not fut.done():
                fut.set_exception(closed)
        for entry in self._outbox:  # batched requests get their invoke id when sent
            if type(entry) is QueuedRequest and not entry.fut.done():
                entry.fut.set_exception(closed)
        self._outbox.clear()
        for waiter in self._sample_waiters.values():
            if not waiter.done():
                waiter.set_exception(closed)
        self._pending.clear()

    async def pause(self, seconds: float) -> None:
        """Wait ``seconds`` of wall time."""
        await asyncio.sleep(seconds)

    def exchange(self, command: int, port: int, fields: tuple[Any, ...]) -> asyncio.Future[Response]:
        """Send a request; the future is its reply, or fails after ``timeout_s`` (see the
        class doc). A plain function, so that awaiting a reply costs one frame less."""
        if self._sock is None:
            raise self._closed
        fut = self._loop.create_future()  # type: ignore[union-attr]
        if self.batch and batchable(command, fields):  # encoded at the end of the turn
            self._outbox.append(QueuedRequest(fut, command, port, fields))
            self._batched = True
            self._schedule_drain()
            return fut
        invoke_id, frame = self._frame(command, port, fields)
        self._pending[invoke_id] = (fut, self._generation, command)
        # Frames wait in the outbox until the end of this loop pass and then go out back
        # to back: ZeroMQ's I/O thread is woken once per burst instead of once per frame.
        self._outbox.append((invoke_id, frame))
        if not self._drain_scheduled:
            self._drain_scheduled = True
            self._loop.call_soon(self._drain)  # type: ignore[union-attr]
        return fut

    async def next_sample(self, handle: int) -> RawSample:
        """The next buffered sample of ``handle``, waiting for one if needed."""
        while True:
            buffer = self._samples[handle]
            if buffer:
                return buffer.popleft()
            waiter = self._loop.create_future()  # type: ignore[union-attr]
            self._sample_waiters[handle] = waiter
            try:
                await waiter
            finally:
                self._sample_waiters.pop(handle, None)

    async def _sweep(self) -> None:
        # Requests are stamped with the sweep generation instead of a clock reading; one
        # sent in generation g has waited at least 4 quarters when generation g + 5 starts.
        period = max(0.001, self.timeout_s / 4)
        while True:
            await asyncio.sleep(period)
            self._generation += 1
            self._check_handshake()  # a refusal explains the timeouts: say it instead
            if self._sock is None:
                return
            expired = self._generation - 5
            pending = self._pending
            for invoke_id, (fut, generation, command) in list(pending.items()):
                if fut.done():  # its caller was cancelled: the reply will not be awaited
                    del pending[invoke_id]
                elif generation <= expired:
                    del pending[invoke_id]
                    fut.set_exception(self._timeout(command))

    def _schedule_drain(self) -> None:
        if not self._drain_scheduled:
            self._drain_scheduled = True
            self._loop.call_soon(self._drain)  # type: ignore[union-attr]

    def _resend(self, item: QueuedRequest) -> None:
        """Send a batched request again, alone (``SumBatch``)."""
        if self._sock is None:
            if not item.fut.done():
                item.fut.set_exception(self._closed)
            return
        invoke_id, frame = self._frame(item.command, item.port, item.fields)
        self._pending[invoke_id] = (item.fut, self._generation, item.command)
        self._outbox.append((invoke_id, frame))
        self._schedule_drain()

    def _assemble(self, outbox: list[tuple[int, bytes] | QueuedRequest]) -> list[tuple[int, bytes]]:
        """The outbox as frames: each run of batched reads or writes as sum commands
        (``clients.batching``), a lone one as its plain request; in the order issued."""
        frames: list[tuple[int, bytes]] = []
        pending, generation = self._pending, self._generation
        for entry in runs(outbox):
            if type(entry) is not list:
                frames.append(entry)
                continue
            for chunk in chunks(entry):
                if len(chunk) == 1:
                    item = chunk[0]
                    invoke_id, frame = self._frame(item.command, item.port, item.fields)
                    pending[invoke_id] = (item.fut, generation, item.command)
                else:
                    command, port, fields = sum_fields(chunk)
                    invoke_id, frame = self._frame(command, port, fields)
                    # timeouts name the items' command (READ), not the ReadWrite carrying it
                    pending[invoke_id] = (SumBatch(chunk, self._resend), generation,
                                          chunk[0].command)
                frames.append((invoke_id, frame))
        return frames

    def _flush(self) -> None:
        send, pending = self._raw_send, self._pending
        outbox: Any = self._outbox
        self._outbox = []
        if self._batched:
            self._batched = False
            outbox = self._assemble(outbox)
        self.frames_sent += len(outbox)
        for k, (_, frame) in enumerate(outbox):
            try:
                send(frame, _NOBLOCK)
            except zmq.Again:  # the service stopped reading: fail what could not go out
                full = AdsConnectionError(0x748, "send queue full; the service is not reading")
                for failed, _ in outbox[k:]:
                    entry = pending.get(failed)
                    if entry is not None and not entry[0].done():
                        entry[0].set_exception(full)
                return

    def _drain(self) -> None:
        """Send what waits in the outbox, then handle every frame that came in."""
        self._drain_scheduled = False
        if self._sock is None:
            return
        if self._outbox:
            self._flush()  # a send can consume the fd's edge: we read right after anyway
        recv = self._raw_recv
        pending = self._pending
        while True:
            try:
                raw = recv(_NOBLOCK)
            except zmq.Again:
                return
            try:
                message = decode_incoming(raw)
            except ProtocolError as exc:
                log.warning("dropped an unreadable frame from %s: %s", self.endpoint, exc)
                continue
            if type(message) is Response:
                entry = pending.pop(message.invoke_id, None)
                if entry is not None and not entry[0].done():
                    entry[0].set_result(message)
            else:
                self._route(message)  # type: ignore[arg-type]
                for sample in message.samples:  # type: ignore[union-attr]
                    waiter = self._sample_waiters.get(sample.handle)
                    if waiter is not None and not waiter.done():
                        waiter.set_result(None)
