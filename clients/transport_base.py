"""What both transports share (``transport``: asyncio, ``sync_transport``: blocking): the
DEALER socket with its handshake watch, invoke ids, and per-subscription sample buffers.

Its own module so that the blocking client (``cnc read``) loads neither asyncio nor
``zmq.asyncio``: the async transport imports this, not the other way round.
"""

from __future__ import annotations

import itertools
from collections import deque
from typing import Any

import zmq

from cnc_objects.protocol.constants import AdsCommand
from cnc_objects.protocol.frames import Notification, RawSample, encode_request

from .client_core import SAMPLE_BUFFER
from .curve import ClientCurve, HandshakeWatch
from .errors import AdsConnectionError, NoReplyError

_NOBLOCK = int(zmq.NOBLOCK)
# Samples of handles not yet claimed: they can overtake the reply that names the handle,
# for as many subscriptions as are opened at once. The oldest unclaimed handle (most
# likely a deleted subscription's last samples) makes room for a new one.
EARLY_HANDLES = 4096


def _new_socket(
    context: zmq.Context[zmq.Socket[bytes]], endpoint: str, curve: ClientCurve | None = None
) -> tuple[zmq.Socket[bytes], HandshakeWatch]:
    """A connected DEALER socket and the watch on its handshakes."""
    sock = context.socket(zmq.DEALER)
    sock.setsockopt(zmq.LINGER, 0)
    sock.setsockopt(zmq.SNDHWM, 100_000)
    sock.setsockopt(zmq.RCVHWM, 100_000)
    if curve is not None:
        curve.secure(sock)
    watch = HandshakeWatch(sock, endpoint, curve)  # before connect: no event is missed
    try:
        sock.connect(endpoint)
    except zmq.ZMQError as exc:
        watch.close()
        sock.close()
        raise AdsConnectionError(0x748, f"cannot connect to {endpoint}: {exc}") from None
    return sock, watch


class _Transport:
    """What both transports share: invoke ids and per-subscription sample buffers."""

    def __init__(self, endpoint: str, timeout_s: float, curve: ClientCurve | None = None) -> None:
        self.endpoint = endpoint
        self.timeout_s = timeout_s
        self.curve = curve
        self._ids = itertools.count(1)
        self._samples: dict[int, deque[RawSample]] = {}
        self._early: dict[int, deque[RawSample]] = {}

    def _frame(self, command: int, port: int, fields: tuple[Any, ...]) -> tuple[int, bytes]:
        """A fresh invoke id (1..2**32-1) and the request frame that carries it."""
        invoke_id = next(self._ids)
        if invoke_id > 0xFFFFFFFF:
            self._ids = itertools.count(2)
            invoke_id = 1
        return invoke_id, encode_request(invoke_id, command, port, fields)

    def open_samples(self, handle: int, buffer_samples: int | None = SAMPLE_BUFFER) -> None:
        """Start buffering samples of ``handle`` (claims any that arrived early), at most
        ``buffer_samples`` (None: every sample until it is read)."""
        early = self._early.pop(handle, None)
        if early and buffer_samples == SAMPLE_BUFFER:
            self._samples[handle] = early
        else:
            self._samples[handle] = deque(early or (), maxlen=buffer_samples)

    def close_samples(self, handle: int) -> None:
        """Stop buffering samples of ``handle``."""
        self._samples.pop(handle, None)
        self._early.pop(handle, None)

    def _route(self, note: Notification) -> None:
        for sample in note.samples:
            buffer = self._samples.get(sample.handle)
            if buffer is None:
                buffer = self._early.get(sample.handle)
                if buffer is None:
                    if len(self._early) >= EARLY_HANDLES:
                        del self._early[next(iter(self._early))]  # the oldest (dicts keep order)
                    buffer = self._early[sample.handle] = deque(maxlen=SAMPLE_BUFFER)
            buffer.append(sample)

    def _timeout(self, command: int) -> NoReplyError:
        """The error of a request that got no reply; the client names it after what its
        caller asked for (``NoReplyError.asking``)."""
        return NoReplyError(AdsCommand(command).name, self.timeout_s, self.endpoint)
