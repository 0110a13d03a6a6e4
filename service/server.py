"""The ZeroMQ front end: a ROUTER socket on the event loop, in front of the dispatcher.

Batched pattern: the socket's file descriptor wakes the loop once, then every waiting
frame is drained without blocking and answered in the same pass, so a client with many
requests in flight costs one wake-up per batch, not one await per message.

Nothing a client sends can stop the server (``[limits]``, ``limits``): a frame over
``max_frame_bytes`` is answered 0x70B and dropped, one over twice that cuts its client
off before it is buffered (ZeroMQ's MAXMSGSIZE); requests over a client's rate wait in
its mailbox (``rate_limit``), a full mailbox is answered 0x502; frames that do not
decode get an error reply (or are dropped, logged, when not even the invoke id can be
read), everything else gets an answer from the dispatcher. Replies to a client that
does not read wait up to the send high-water mark, then are dropped (counted, logged
now and then). A connection beyond ``connections_per_front_end`` takes the seat of an
idle keyless one or is refused in its handshake ("connection table full", ZAP 500;
``zmq_connections``), and a frame (or greeting) incomplete after ``frame_timeout_s`` ends its
connection through libzmq's heartbeat (``zmq_connections``). A vanished client's
notifications are dropped: ZeroMQ says a client is gone when a send to it fails, so
clients with notifications get an empty notification frame every ``PROBE_S`` (a client
that only subscribed on change to a value that never changes would otherwise never be
sent anything).

The envelope of a client is its ROUTER identity frames (a tuple of bytes): the routing
id ZeroMQ gives the connection, then whatever parts the client put before its frame,
echoed back with the reply. Limits count per connection (the routing id): extra parts
do not make a client several.

With CURVE (``curve``, ``cnc-service --keys``) the ZAP handler of ``security`` admits
clients by public key and names each connection's role in its User-Id, which ZeroMQ
attaches to every message; the server reads it per message and the dispatcher decides
(``Dispatcher.dispatch_as``). Without CURVE every peer may everything (``main`` binds
loopback only then, unless told ``--insecure``).
"""

from __future__ import annotations

import asyncio
import errno
import logging
from time import perf_counter
from typing import Any

import msgpack
import zmq

from cnc_objects.protocol.constants import AdsCommand, CncPort
from cnc_objects.protocol.errors import AdsReturnCode, ProtocolError
from cnc_objects.protocol.frames import (
    decode_request,
    encode_error,
    encode_notification,
    encode_rows_response,
    pack_rows,
)
from cnc_objects.protocol.roles import Role

from .backend import Backend
from .connection_limits import ConnectionLimits, Seat
from .dispatch import Dispatcher
from .limits import LimitsConfig, oversized_reply, rate_limiter, request_head
from .log_throttle import ThrottledWarning
from .rate_limit import BYTES_PER_TOKEN as _BYTES_PER_TOKEN
from .rate_limit import RateLimiter, extra_tokens
from .security import ZAP_DOMAIN, ServerCurve, ZapAuthenticator
from .zmq_connections import ZmqConnectionWatch

log = logging.getLogger(__name__)

DRAIN_BATCH = 256  # frames handled per wake-up before yielding to other callbacks
PROBE_S = 2.0  # clients with notifications are sent an empty notification this often
RELEASE_MIN_S = 0.001  # waiting requests are released in batches at most this often
RELEASE_BUDGET_S = 0.005  # loop time one release pass may take before it yields
DROP_LOG_S = 10.0  # dropped replies and frames are logged at most this often (with a count)

_NOBLOCK = int(zmq.NOBLOCK)
_SNDMORE_NOBLOCK = int(zmq.SNDMORE | zmq.NOBLOCK)
_EVENTS = int(zmq.EVENTS)
_POLLIN = int(zmq.POLLIN)
_packb = msgpack.Packer(use_bin_type=True, autoreset=True).pack  # as protocol.frames packs
_USER_ID = "User-Id"  # message property: the ZAP handler's name for the connection
_READ_WRITE = AdsCommand.READ_WRITE
_BROWSE = AdsCommand.BROWSE
#: The rows of the last browse answered and their packing: the dispatcher keeps a pattern's
#: rows (one list, never changed), so a browse of ``*`` after the first packs nothing.
_browsed: tuple[list[Any], bytes] | None = None


def _browse_reply(invoke_id: int, rows: list[Any]) -> bytes:
    """A browse's reply, its rows packed once per list of rows (the event loop's time, and
    the cycle's wait for the GIL meanwhile: issue 37)."""
    global _browsed
    kept = _browsed
    if kept is None or kept[0] is not rows:
        kept = _browsed = (rows, pack_rows(rows))
    return encode_rows_response(invoke_id, _BROWSE, rows, kept[1])


Envelope = tuple[bytes, ...]


class ZmqServer:
    """Serves a ``Backend`` on a ZeroMQ ROUTER socket (msgpack frames, ``protocol.frames``)."""

    first_sample_delay_s = 0.0  # the first sample follows the acknowledgement at once

    def __init__(
        self,
        backend: Backend,
        endpoint: str,
        context: zmq.Context[zmq.Socket[bytes]] | None = None,
        curve: ServerCurve | None = None,
        limits: LimitsConfig | None = None,
    ) -> None:
        limits = limits or LimitsConfig()
        self._loop = backend.loop
        self._context = context or zmq.Context()
        self._owns_context = context is None
        sock = self._context.socket(zmq.ROUTER)
        sock.setsockopt(zmq.LINGER, 0)
        sock.setsockopt(zmq.ROUTER_MANDATORY, 1)  # a vanished client raises, not blackholes
        # Frames over the hard cap cut the peer off before they are buffered.
        sock.setsockopt(zmq.MAXMSGSIZE, limits.frame_hard_cap_bytes)
        sock.setsockopt(zmq.SNDHWM, limits.send_hwm_messages)
        sock.setsockopt(zmq.RCVHWM, limits.receive_hwm_messages)
        # A frame that never completes: libzmq's heartbeat timeout is cancelled only by a
        # whole message, which a peer in the middle of a frame cannot send
        # (zmq_connections); a greeting that never completes: the handshake interval.
        timeout_ms = max(1, round(limits.frame_timeout_s * 1000))
        sock.setsockopt(zmq.HEARTBEAT_IVL, timeout_ms)
        sock.setsockopt(zmq.HEARTBEAT_TIMEOUT, timeout_ms)
        sock.setsockopt(zmq.HANDSHAKE_IVL, timeout_ms)
        self._max_frame_bytes = limits.max_frame_bytes
        self.rate = rate_limiter(limits)
        self._release_timer: asyncio.TimerHandle | None = None
        self._probe_timer: asyncio.TimerHandle | None = None
        # replies not sent (the client's queue was full), and frames without a readable
        # invoke id (no reply possible): a client causes them at will, so they are
        # counted and logged now and then
        self._replies_dropped = ThrottledWarning(
            log, "replies to clients dropped; a client does not read its replies "
            "(send_hwm_messages)", DROP_LOG_S)
        self._unreadable = ThrottledWarning(log, "dropped a frame with no readable invoke id",
                                            DROP_LOG_S)
        self._auth: ZapAuthenticator | None = None
        self._roles: dict[str, Role] | None = None  # User-Id -> role; None: no CURVE
        if curve is not None:  # the ZAP handler must answer before the first client comes
            self._auth = curve.authenticator(self._context)
            self._auth.start()
            curve.secure(sock)
            self._roles = curve.allow_list.roles_by_user
        elif endpoint.startswith("tcp://"):  # ZAP only to say "connection table full"
            self._auth = ZapAuthenticator(self._context)
            self._auth.start()
            sock.zap_domain = ZAP_DOMAIN.encode()
        try:
            sock.bind(endpoint)
        except zmq.ZMQError:
            sock.close()
            if self._auth is not None:
                self._auth.stop()
            if self._owns_context:
                self._context.term()
            raise
        self._sock = sock
        # The Cython socket methods: pyzmq's Python wrappers cost more than the send itself.
        raw: Any = zmq.Socket.__mro__[1]
        self._raw_send = raw.send.__get__(sock)
        self._raw_recv = raw.recv.__get__(sock)
        self._raw_get = raw.get.__get__(sock)
        self.endpoint = sock.getsockopt_string(zmq.LAST_ENDPOINT)
        # Open connections, capped ([limits] connections_per_front_end); TCP only.
        self.connections: ZmqConnectionWatch | None = None
        self._seats: dict[bytes, Seat] = {}  # routing id -> its connection's seat
        if self.endpoint.startswith("tcp://"):
            self.connections = ZmqConnectionWatch(
                sock, int(self.endpoint.rsplit(":", 1)[1]),
                ConnectionLimits("ZeroMQ", limits), self._loop, self._auth is not None)
            self._seats = self.connections.by_routing_id
            self.connections.ended = self._ended
            if self._auth is not None:
                self._auth.door = self.connections.door
        self.hub = backend.hub
        self.dispatcher = Dispatcher(backend, self)
        self._dispatch = self.dispatcher.dispatch
        self._drain_scheduled = False

    # ------------------------------------------------------------ life cycle

    def start(self) -> None:
        """Begin serving on the loop."""
        self._loop.add_reader(self._sock.FD, self._drain)
        self._schedule_drain()  # frames may already wait; the edge-triggered fd won't say
        self._probe_timer = self._loop.call_later(PROBE_S, self._probe)
        if self.connections is not None:
            self.connections.start()

    def close(self) -> None:
        """Stop serving and close the socket."""
        self._loop.remove_reader(self._sock.FD)
        if self.connections is not None:
            self.connections.close()
        for timer in (self._release_timer, self._probe_timer):
            if timer is not None:
                timer.cancel()
        self._sock.close(linger=0)
        if self._auth is not None:
            self._auth.stop()
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
        roles, dispatch_as = self._roles, self.dispatcher.dispatch_as
        max_frame_bytes, rate, now_s = self._max_frame_bytes, self.rate, perf_counter()
        seats, watch = self._seats, self.connections
        for _ in range(DRAIN_BATCH):
            try:
                part = recv(_NOBLOCK, False)  # a zmq.Frame: .more is cheaper than RCVMORE
            except zmq.Again:
                break
            # every frame of a CURVE connection carries its User-Id; none: the lowest role
            role = None if roles is None else roles.get(part.get(_USER_ID), Role.MONITOR)
            frames = [part.bytes]
            while part.more:
                part = recv(_NOBLOCK, False)
                frames.append(part.bytes)
            envelope, raw = tuple(frames[:-1]), frames[-1]
            seat = seats.get(frames[0])
            if seat is None and watch is not None:  # a new connection: which one
                seat = watch.seat_of(frames[0], part, role is not None)
            if seat is not None:
                seat.used_s = now_s  # not idle: keeps its seat
            # Limits count per connection: its routing id, not the parts a client adds.
            if len(raw) > max_frame_bytes or (
                    rate is not None and not rate.admit(frames[0], now_s)):
                self._limit(envelope, raw, role, now_s)
                continue
            try:
                request = decode_request(raw)
            except ProtocolError as exc:
                reply = self._refuse(exc)
            else:
                reply = (dispatch(envelope, request) if role is None
                         else dispatch_as(envelope, request, role))
                if rate is not None:  # a big or a sum request costs more than one token
                    size = len(raw) if reply is None else len(raw) + len(reply)
                    if size >= _BYTES_PER_TOKEN or request.COMMAND == _READ_WRITE:
                        rate.charge(frames[0], extra_tokens(request, size))
            if reply is not None:
                deliver(envelope, reply)
        else:
            self._schedule_drain()  # more may wait: come back after other callbacks ran
        self._look_for_input()

    def _serve(self, envelope: Envelope, raw: bytes, role: Role | None) -> None:
        """Answer one frame that waited for its turn, and charge what it cost (as
        ``_drain`` does)."""
        try:
            request = decode_request(raw)
        except ProtocolError as exc:
            reply = self._refuse(exc)
        else:
            reply = (self._dispatch(envelope, request) if role is None
                     else self.dispatcher.dispatch_as(envelope, request, role))
            if self.rate is not None:
                size = len(raw) if reply is None else len(raw) + len(reply)
                self.rate.charge(envelope[0], extra_tokens(request, size))
        if reply is not None:
            self._deliver(envelope, reply)

    # ------------------------------------------------------------ limits

    def _limit(self, envelope: Envelope, raw: bytes, role: Role | None, now_s: float) -> None:
        """A frame over the size limit, or over its client's rate."""
        if len(raw) > self._max_frame_bytes:
            reply = oversized_reply(raw, self._max_frame_bytes)
            log.debug("frame of %d bytes over max_frame_bytes %d%s", len(raw),
                      self._max_frame_bytes, "" if reply else " (no invoke id: dropped)")
        else:
            rate = self.rate
            assert rate is not None
            if rate.hold(envelope[0], (envelope, raw, role), len(raw)):
                self._schedule_release(now_s)
                return
            reply = self._mailbox_full(raw, rate)
        if reply is not None:
            self._deliver(envelope, reply)

    @staticmethod
    def _mailbox_full(raw: bytes, rate: RateLimiter) -> bytes | None:
        head = request_head(raw)
        if head is None:
            return None
        return encode_error(
            *head, AdsReturnCode.ROUTER_MAILBOXFULL,
            f"the mailbox of this client is full: its requests over its rate of "
            f"{rate.rate_per_s:g}/s wait there ([limits] requests_per_s_per_client, "
            "request_mailbox); wait for replies before sending more",
        )

    def _schedule_release(self, now_s: float) -> None:
        if self._release_timer is None and self.rate is not None:
            delay_s = self.rate.next_release_s(now_s)
            if delay_s is not None:
                self._release_timer = self._loop.call_later(
                    max(delay_s, RELEASE_MIN_S), self._release)

    def _release(self) -> None:
        """Serve the waiting requests whose clients have tokens again."""
        self._release_timer = None
        assert self.rate is not None
        now_s = perf_counter()
        for envelope, raw, role in self.rate.release(now_s):
            self._serve(envelope, raw, role)  # charges its client before the next is taken
            if perf_counter() - now_s > RELEASE_BUDGET_S:
                break  # the rest in a later pass: other callbacks (and clients) go first
        self._schedule_release(perf_counter())
        self._look_for_input()

    def _probe(self) -> None:
        """Send clients with notifications an empty notification: a send to a client
        that is gone fails, and its notifications are dropped (``_deliver``)."""
        probe = encode_notification(CncPort.COM, [])
        for envelope, notify in self.hub.clients():
            if notify == self.notify:
                self._deliver(envelope, probe)
        self._look_for_input()
        self._probe_timer = self._loop.call_later(PROBE_S, self._probe)

    def _ended(self, routing_id: bytes) -> None:
        """A connection ended (``zmq_connections``): the jog keys it held are released."""
        self.dispatcher.backend.connection_ended(routing_id, f"0x{routing_id.hex()} closed")

    def _gone(self, envelope: Envelope) -> None:
        """Forget a client ZeroMQ says is gone: its notifications, its waiting requests."""
        self.hub.drop_client(envelope)
        if self.rate is not None:
            self.rate.forget(envelope[0])

    def _dropped(self, exc: zmq.ZMQError) -> None:
        """Count a reply that could not be sent; log now and then, not for every one (a
        client that does not read would flood the log)."""
        self._replies_dropped.note(exc)

    def _refuse(self, exc: ProtocolError) -> bytes | None:
        """The error reply to a frame that did not decode; None when it has no invoke id."""
        if exc.invoke_id is None:
            self._unreadable.note(exc)
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
                self._gone(envelope)
            else:
                self._dropped(exc)
            return False
        return True

    # ------------------------------------------------------------ FrontEnd (dispatch.py)

    @staticmethod
    def ok(envelope: Envelope, req: Any, *fields: Any) -> bytes:
        """``[invoke_id, command, 0, *fields]``: ``frames.encode_response``, packed here
        without its own call (the dispatch hot path). A browse's rows (the catalogue) are
        packed row by row, so that the cycle thread gets the GIL between them
        (``encode_rows_response``)."""
        if req.COMMAND == _BROWSE:
            return _browse_reply(req.invoke_id, fields[0])
        frame: bytes = _packb([req.invoke_id, req.COMMAND, 0, *fields])
        return frame

    @staticmethod
    def error(envelope: Envelope, req: Any, code: int, message: str) -> bytes:
        """``[invoke_id, command, code, message]``."""
        return encode_error(req.invoke_id, req.COMMAND, code, message)

    def send(self, envelope: Envelope, payload: bytes) -> bool:
        """Send a frame outside a drain pass; False when it could not be delivered (also
        after ``close``: a kernel reply that comes while the service stops is dropped)."""
        if self._sock.closed:
            return False
        delivered = self._deliver(envelope, payload)
        self._look_for_input()
        return delivered

    def notify(self, envelope: Envelope, port: int, samples: list[list[Any]]) -> bool:
        """One notification frame with ``samples``."""
        return self.send(envelope, encode_notification(port, samples))

    @staticmethod
    def cycle_ns(req: Any) -> int:
        """Frames carry the cycle time in ms."""
        cycle_ms: int = req.cycle_time_ms
        return cycle_ms * 1_000_000
