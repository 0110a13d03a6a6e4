"""The open connections of the ZeroMQ front end, counted and capped from outside libzmq.

A ROUTER socket accepts every TCP connection itself, buffers each one's incomplete frame
inside libzmq (it allocates the size a frame announces, up to ``MAXMSGSIZE``) and has no
call that closes one peer. So the front end watches its socket's monitor
(``zmq_socket_monitor``: ``ACCEPTED`` and ``DISCONNECTED`` carry the connection's file
descriptor) and gives each connection a seat (``connection_limits``); a connection is
closed by ``shutdown(2)`` on its descriptor (libzmq then reads the end of the stream and
drops that peer cleanly, freeing what it held). Before deciding, every event waiting is
read, so that a descriptor whose ``DISCONNECTED`` is already queued (and whose number
may be reused) is never taken for an open connection, and the descriptor must still be
a TCP socket on the front end's own port.

Which connection a message came from: its ``ZMQ_SRCFD`` (read once per routing id,
``seat_of``), so each request marks its connection's seat used, a CURVE connection's
seat becomes keyed with its first request, and the end of a connection (its
``DISCONNECTED``: the peer closed, was killed, or libzmq's heartbeat gave up on it) is
told by its routing id (``ended``): the backend releases the jog keys it held.

A full table makes room by closing an idle keyless connection; when it cannot, the
newcomer is told so in its handshake: the ZAP handler (``security.ZapAuthenticator``,
also without CURVE) asks ``door`` and refuses it with ZAP status 500
(``ZAP_STATUS_TABLE_FULL``), which the client's monitor reports and the client library
names ("connection table full"). ZAP tells the peer's IP address, not its descriptor: a
handshake is taken for the connection from that address accepted first whose handshake
has not come yet (handshakes come in the order of their connections); should it be
another one, the one over the cap passes instead and takes a seat with its first
request (made by closing an idle keyless one, else over the cap by one). Connections over the cap
that wait for their handshake are bounded too: beyond a second table's worth they are
shut down at once.

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
import threading
from collections.abc import Callable

import zmq
from zmq.utils.monitor import parse_monitor_message

from .connection_limits import ConnectionLimits, Seat

log = logging.getLogger(__name__)

_WATCHED = zmq.EVENT_ACCEPTED | zmq.EVENT_DISCONNECTED
_SRCFD = int(zmq.SRCFD)


class ZmqConnectionWatch:
    """Seats the connections of ``router`` (bound to ``port``) in ``limits``; refuses
    those over ``limits.max_connections`` (through ``door``, or at once)."""

    def __init__(self, router: zmq.Socket[bytes], port: int, limits: ConnectionLimits,
                 loop: asyncio.AbstractEventLoop, zap: bool = False) -> None:
        """``zap``: a ZAP handler asks ``door`` in every handshake (else a connection
        over the cap is shut down as it comes)."""
        self._router = router
        self._port = port
        self.limits = limits
        self._loop = loop
        self._zap = zap
        self._monitor = router.get_monitor_socket(_WATCHED)
        self._lock = threading.Lock()  # the ZAP thread drains too (``door``)
        self._seats: dict[int, Seat] = {}  # descriptor -> seat of an admitted connection
        self._waiting: dict[int, str] = {}  # descriptor -> peer, over the cap, in handshake
        # descriptor -> peer host of each connection whose handshake has not reached ZAP
        # yet, in the order accepted (the order their ZAP requests come in)
        self._tickets: dict[int, str] = {}
        self._routing: dict[int, bytes] = {}  # descriptor -> routing id, once it sent
        self.by_routing_id: dict[bytes, Seat] = {}  # for the server's drain
        # told (on the loop) the routing id of each connection that ended after it sent
        self.ended: Callable[[bytes], None] | None = None
        self._refused = 0  # connections refused over the cap, since start

    @property
    def refused(self) -> int:
        """Connections refused because the cap was reached, since start."""
        return self._refused

    def start(self) -> None:
        """Watch the monitor on the loop."""
        self._loop.add_reader(self._monitor.FD, self._drain_locked)
        self._loop.call_soon(self._drain_locked)  # events may wait already (edge-triggered)

    def close(self) -> None:
        """Stop watching (before the router closes)."""
        self._loop.remove_reader(self._monitor.FD)
        with self._lock:
            try:
                self._router.disable_monitor()
            except zmq.ZMQError:
                pass
            self._monitor.close(linger=0)

    def door(self, host: str, keyed: bool) -> bool:
        """The ZAP handler's question for a handshake from ``host`` (called on its
        thread), ``keyed`` when it brings a key of the allow-list: False when the
        connection is over the cap and no room can be made for it (the handshake is
        refused, ZAP 500). ZAP names the address only: the handshake is taken for the
        connection from ``host`` accepted first whose handshake has not come yet."""
        with self._lock:
            self._drain()
            fd = next((f for f, h in self._tickets.items() if h == host), None)
            if fd is None or fd not in self._waiting:
                if fd is not None:
                    del self._tickets[fd]
                return True
            del self._tickets[fd]
            if not (keyed and self.limits.make_room(True)):
                return False  # over the cap
            seat = self._seat(fd, self._waiting.pop(fd), force=True)  # a keyless one left
            if seat is not None:
                seat.keyed = True
            return True

    def seat_of(self, routing_id: bytes, frame: zmq.Frame, keyed: bool) -> Seat | None:
        """The seat of the connection a message (``frame``) with a new ``routing_id``
        came from; ``keyed``: the message carries a CURVE key's User-Id. A connection
        that passed its handshake although counted over the cap takes a seat now."""
        try:
            fd = int(frame.get(_SRCFD))
        except zmq.ZMQError:
            return None
        with self._lock:
            self._drain()
            self._tickets.pop(fd, None)  # it passed its handshake
            seat = self._seats.get(fd)
            peer = self._waiting.pop(fd, None)
            if seat is None and peer is not None:  # in, over the cap: room if there is
                seat = self._seat(fd, peer, force=not self.limits.make_room(keyed))
            if seat is None:
                return None
            seat.keyed = keyed
            self._routing[fd] = routing_id
            self.by_routing_id[routing_id] = seat
            return seat

    def _drain_locked(self) -> None:
        with self._lock:
            self._drain()

    def _drain(self) -> None:
        """Read every waiting event, then seat (or refuse) the connections accepted."""
        accepted: list[int] = []
        while True:
            try:
                parts = self._monitor.recv_multipart(zmq.NOBLOCK)
            except (zmq.Again, zmq.ZMQError):
                break
            event = parse_monitor_message(parts)
            fd = int(event["value"])
            if event["event"] == zmq.EVENT_ACCEPTED:
                accepted.append(fd)
            elif fd in accepted:
                accepted.remove(fd)  # came and went between two drains
            else:
                self._gone(fd)
        for fd in accepted:
            peer = _peer_of(fd, self._port)
            if peer is None:
                continue  # no longer our connection: its DISCONNECTED is on its way
            if self._seat(fd, peer) is not None:
                if self._zap:
                    self._tickets[fd] = _host(peer)
                continue
            self._refused += 1
            self.limits.over_cap.note(peer)
            if self._zap and len(self._waiting) < self.limits.max_connections:
                self._waiting[fd] = peer
                self._tickets[fd] = _host(peer)
            else:
                _shut_down(fd)

    def _seat(self, fd: int, peer: str, force: bool = False) -> Seat | None:
        seat = self.limits.admit(peer, False, lambda: self._evict(fd), False, force)
        if seat is not None:
            self._seats[fd] = seat
        return seat

    def _evict(self, fd: int) -> None:
        """Close the connection on ``fd`` to free its seat, if ``fd`` is still ours."""
        if _peer_of(fd, self._port) is not None:
            _shut_down(fd)

    def _gone(self, fd: int) -> None:
        """``fd``'s connection ended: free its seat (or its place in the waiting room)."""
        self._waiting.pop(fd, None)
        self._tickets.pop(fd, None)
        seat = self._seats.pop(fd, None)
        if seat is not None:
            self.limits.release(seat, 0)
        routing_id = self._routing.pop(fd, None)
        if routing_id is None:
            return
        if self.by_routing_id.get(routing_id) is seat:
            del self.by_routing_id[routing_id]
        if self.ended is not None:  # this may run on the ZAP thread (``door``)
            self._loop.call_soon_threadsafe(self.ended, routing_id)

    @property
    def open(self) -> int:
        """Connections open now (as far as the events read so far tell)."""
        return len(self._seats)


def _host(peer: str) -> str:
    """The host of ``host:port`` as ZAP names it (no brackets)."""
    return peer.rsplit(":", 1)[0].strip("[]")


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
