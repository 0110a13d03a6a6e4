"""The ZeroMQ front end: a ROUTER socket on the event loop, in front of the dispatcher.

Batched pattern: the socket's file descriptor wakes the loop once, then every waiting
frame is drained without blocking and answered in the same pass, so a client with many
requests in flight costs one wake-up per batch, not one await per message.

Nothing a client sends can stop the server: frames over the size limit cut that client
off (ZeroMQ's MAXMSGSIZE), frames that do not decode get an error reply (or are dropped,
logged, when not even the invoke id can be read), everything else gets an answer from
the dispatcher, a vanished client's notifications are dropped.

The envelope of a client is its ROUTER identity frames (a tuple of bytes).
"""

from __future__ import annotations

import asyncio
import errno
import logging
from typing import Any

import msgpack
import zmq

from cnc_objects.protocol.constants import MAX_DATA_BYTES
from cnc_objects.protocol.errors import ProtocolError
from cnc_objects.protocol.frames import decode_request, encode_error, encode_notification

from .backend import Backend
from .dispatch import Dispatcher

log = logging.getLogger(__name__)

DRAIN_BATCH = 256  # frames handled per wake-up before yielding to other callbacks

_NOBLOCK = int(zmq.NOBLOCK)
_SNDMORE_NOBLOCK = int(zmq.SNDMORE | zmq.NOBLOCK)
_EVENTS = int(zmq.EVENTS)
_POLLIN = int(zmq.POLLIN)
_packb = msgpack.Packer(use_bin_type=True, autoreset=True).pack  # as protocol.frames packs


Envelope = tuple[bytes, ...]


class ZmqServer:
    """Serves a ``Backend`` on a ZeroMQ ROUTER socket (msgpack frames, ``protocol.frames``)."""

    first_sample_delay_s = 0.0  # the first sample follows the acknowledgement at once

    def __init__(
        self,
        backend: Backend,
        endpoint: str,
        context: zmq.Context | None = None,
    ) -> None:
        self._loop = backend.loop
        self._context = context or zmq.Context()
        self._owns_context = context is None
        sock = self._context.socket(zmq.ROUTER)
        sock.setsockopt(zmq.LINGER, 0)
        sock.setsockopt(zmq.ROUTER_MANDATORY, 1)  # a vanished client raises, not blackholes
        sock.setsockopt(zmq.MAXMSGSIZE, 2 * MAX_DATA_BYTES)  # huge frames cut the peer off
        sock.setsockopt(zmq.SNDHWM, 100_000)
        sock.setsockopt(zmq.RCVHWM, 100_000)
        try:
            sock.bind(endpoint)
        except zmq.ZMQError:
            sock.close()
            if self._owns_context:
                self._context.term()
            raise
        self._sock = sock
        # The Cython socket methods: pyzmq's Python wrappers cost more than the send itself.
        raw = zmq.Socket.__mro__[1]
        self._raw_send = raw.send.__get__(sock)
        self._raw_recv = raw.recv.__get__(sock)
        self._raw_get = raw.get.__get__(sock)
        self.endpoint = sock.getsockopt_string(zmq.LAST_ENDPOINT)
        self.hub = backend.hub
        self.dispatcher = Dispatcher(backend, self)
        self._dispatch = self.dispatcher.dispatch
        self._drain_scheduled = False

    # ------------------------------------------------------------ life cycle

    def start(self) -> None:
        """Begin serving on the loop."""
        self._loop.add_reader(self._sock.FD, self._drain)
        self._schedule_drain()  # frames may already wait; the edge-triggered fd won't say

    def close(self) -> None:
        """Stop serving and close the socket."""
        self._loop.remove_reader(self._sock.FD)
        self._sock.close(linger=0)
        if self._owns_context:
            self._context.term()

    # ------------------------------------------------------------ socket

    def _schedule_drain(self) -> None:
        if not self._drain_scheduled:
            self._drain_scheduled = True
            self._loop.call_soon(self._drain)

    def _drain(self) -> None:
        """Handle every waiting frame (up to a batch); each reply goes out at once so a
        pipelining client overlaps its work with ours."""
        self._drain_scheduled = False
        recv, deliver, dispatch = self._raw_recv, self._deliver, self._dispatch
        for _ in range(DRAIN_BATCH):
            try:
                part = recv(_NOBLOCK, False)  # a zmq.Frame: .more is cheaper than RCVMORE
            except zmq.Again:
                break
            frames = [part.bytes]
            while part.more:
                part = recv(_NOBLOCK, False)
                frames.append(part.bytes)
            envelope = tuple(frames[:-1])
            try:
                request = decode_request(frames[-1])
            except ProtocolError as exc:
                reply = self._refuse(exc)
            else:
                reply = dispatch(envelope, request)
            if reply is not None:
                deliver(envelope, reply)
        else:
            self._schedule_drain()  # more may wait: come back after other callbacks ran
        self._look_for_input()

    @staticmethod
    def _refuse(exc: ProtocolError) -> bytes | None:
        """The error reply to a frame that did not decode; None when it has no invoke id."""
        if exc.invoke_id is None:
            log.warning("dropped a frame with no readable invoke id: %s", exc)
            return None
        return encode_error(exc.invoke_id, exc.command or 0, exc.code, str(exc))

    def _look_for_input(self) -> None:
        # ZeroMQ's fd is edge-triggered and a send can consume the edge: look again.
        if self._raw_get(_EVENTS) & _POLLIN:
            self._schedule_drain()

    def _deliver(self, envelope: Envelope, payload: bytes) -> bool:
        send = self._raw_send
        try:
            for part in envelope:
                send(part, _SNDMORE_NOBLOCK)
            send(payload, _NOBLOCK)
        except zmq.ZMQError as exc:
            if exc.errno == errno.EHOSTUNREACH:
                self.hub.drop_client(envelope)
            else:
                log.warning("reply to a client dropped: %s", exc)
            return False
        return True

    # ------------------------------------------------------------ FrontEnd (dispatch.py)

    @staticmethod
    def ok(envelope: Envelope, req: Any, *fields: Any) -> bytes:
        """``[invoke_id, command, 0, *fields]``: ``frames.encode_response``, packed here
        without its own call (the dispatch hot path)."""
        return _packb([req.invoke_id, req.COMMAND, 0, *fields])

    @staticmethod
    def error(envelope: Envelope, req: Any, code: int, message: str) -> bytes:
        """``[invoke_id, command, code, message]``."""
        return encode_error(req.invoke_id, req.COMMAND, code, message)

    def send(self, envelope: Envelope, payload: bytes) -> bool:
        """Send a frame outside a drain pass; False when it could not be delivered."""
        delivered = self._deliver(envelope, payload)
        self._look_for_input()
        return delivered

    def notify(self, envelope: Envelope, port: int, samples: list[list[Any]]) -> bool:
        """One notification frame with ``samples``."""
        return self.send(envelope, encode_notification(port, samples))

    @staticmethod
    def cycle_ns(req: Any) -> int:
        """Frames carry the cycle time in ms."""
        return req.cycle_time_ms * 1_000_000
