"""The open connections of the ZeroMQ front end, counted and capped from outside libzmq.

A ROUTER socket accepts every TCP connection itself, buffers each one's incomplete frame
inside libzmq (it allocates the size a frame announces, up to ``MAXMSGSIZE``) and has no
call that closes one peer. So the front end watches its socket's monitor
(``zmq_socket_monitor``: ``ACCEPTED`` and ``DISCONNECTED`` carry the connection's file
descriptor) on the event loop and counts the connections open; one beyond
``[limits] connections_per_front_end`` is shut down (``shutdown(2)`` on its descriptor:
libzmq then reads the end of the stream and drops that peer cleanly, freeing what it
held). Before shutting one down every event waiting is read, so that a descriptor
whose ``DISCONNECTED`` is already queued (and whose number may be reused) is never
taken for an open connection, and the descriptor must still be a TCP socket on the
front end's own port.

A frame that never completes is bounded by libzmq's heartbeat (set by ``ZmqServer``):
the timeout it starts with each PING is cancelled only by a whole message (a PONG is
one); a peer in the middle of a frame cannot send one, so its connection ends after at
most twice ``frame_timeout_s``. What incomplete frames can hold is then at most
``connections_per_front_end`` times the frame hard cap (``LimitsConfig.
zmq_receive_bound_bytes``), for at most that long.
"""

from __future__ import annotations

import asyncio
import logging
import os
import socket

import zmq
from zmq.utils.monitor import parse_monitor_message

from .connection_limits import ConnectionLimits

log = logging.getLogger(__name__)

_WATCHED = zmq.EVENT_ACCEPTED | zmq.EVENT_DISCONNECTED


class ZmqConnectionWatch:
    """Counts the connections of ``router`` (bound to ``port``) and shuts down those
    over ``limits.max_connections``."""

    def __init__(self, router: zmq.Socket[bytes], port: int, limits: ConnectionLimits,
                 loop: asyncio.AbstractEventLoop) -> None:
        self._router = router
        self._port = port
        self.limits = limits
        self._loop = loop
        self._monitor = router.get_monitor_socket(_WATCHED)
        self._open: set[int] = set()  # descriptors of the connections admitted
        self._refused = 0  # connections shut down over the cap, since start

    @property
    def refused(self) -> int:
        """Connections shut down because the cap was reached, since start."""
        return self._refused

    def start(self) -> None:
        """Watch the monitor on the loop."""
        self._loop.add_reader(self._monitor.FD, self._drain)
        self._loop.call_soon(self._drain)  # events may wait already (edge-triggered fd)

    def close(self) -> None:
        """Stop watching (before the router closes)."""
        self._loop.remove_reader(self._monitor.FD)
        try:
            self._router.disable_monitor()
        except zmq.ZMQError:
            pass
        self._monitor.close(linger=0)

    def _drain(self) -> None:
        """Read every waiting event, then shut down what is over the cap."""
        accepted: list[int] = []
        while True:
            try:
                parts = self._monitor.recv_multipart(zmq.NOBLOCK)
            except zmq.Again:
                break
            event = parse_monitor_message(parts)
            fd = int(event["value"])
            if event["event"] == zmq.EVENT_ACCEPTED:
                accepted.append(fd)
            elif fd in self._open:
                self._open.discard(fd)
                self.limits.release(0)
            elif fd in accepted:
                accepted.remove(fd)  # came and went between two drains
        for fd in accepted:
            peer = _peer_of(fd, self._port)
            if peer is None:
                continue  # no longer our connection: its DISCONNECTED is on its way
            if self.limits.admit(peer):
                self._open.add(fd)
            else:
                self._refused += 1
                _shut_down(fd)

    @property
    def open(self) -> int:
        """Connections open now (as far as the events read so far tell)."""
        return len(self._open)


def _borrow(fd: int) -> socket.socket:
    """A socket object on a duplicate of ``fd`` (closing it leaves ``fd`` to libzmq);
    ``OSError`` when ``fd`` is closed or no socket."""
    dup = os.dup(fd)
    try:
        return socket.socket(fileno=dup)
    except OSError:
        os.close(dup)
        raise


def _peer_of(fd: int, port: int) -> str | None:
    """``host:port`` of the TCP peer on descriptor ``fd`` when it is a connection to our
    ``port``; None otherwise (closed, or reused for something else)."""
    try:
        with _borrow(fd) as sock:
            if sock.type != socket.SOCK_STREAM or sock.getsockname()[1] != port:
                return None
            host, peer_port = sock.getpeername()[:2]
    except (OSError, IndexError, TypeError):
        return None
    return f"{host}:{peer_port}"


def _shut_down(fd: int) -> None:
    """End the TCP connection on ``fd`` both ways; libzmq sees the end of the stream on
    its next read and drops the peer (it closes the descriptor itself)."""
    try:
        with _borrow(fd) as sock:
            sock.shutdown(socket.SHUT_RDWR)
    except OSError as exc:
        log.debug("shutting down ZeroMQ connection fd %d: %s", fd, exc)
