"""One ADS client's TCP connection: AMS frames in, replies and notifications out.

An asyncio ``Protocol`` on the service's event loop. Frames are cut from the stream by
``AmsStreamParser`` and answered in order, as a router would:

- a peer without a route is closed as soon as it connects (logged with its address); a
  routed peer that sends from a Net ID that is not its route's is closed at that frame
  (logged with address and Net ID);
- every request is served with the role of the frame's Net ID (its route's, or the
  loopback role; ``ads_routes``): beyond it, ADS 0x704 from the dispatcher;
- a frame for another AMS Net ID gets AMS error 0x7 (target machine not found), one for
  a port nobody serves AMS error 0x6 (target port not found), both in the AMS header with
  no data, as a router answers;
- an AMS header whose data length disagrees with the AMS/TCP length gets AMS error 0xE;
  a frame too short for an AMS header is skipped (logged): there is no invoke id to
  answer;
- a frame for the router itself (AMS/TCP command not 0) is answered as a TwinCAT router
  answers its local clients (``_router_frame``): port connect, port close, get local Net
  ID; any other is skipped (logged);
- a frame longer than the maximum closes this connection only;
- when the connection closes, the jog keys it pressed are released (``jog_holds``);
- every ADS request goes to the dispatcher; payloads that do not decode get the ADS
  error the decoder names (0x701 unknown command, 0x705 wrong size), with the length
  the client expects for that command.

Frames with the response flag (0x0001) are not answered: a client never asks with one.
A connection over its request rate (``[limits] requests_per_s_per_client``, a token
bucket per connection, ``rate_limit``) is not read until it has a token again: its
frames wait (at most those of one read from the socket), nothing is refused, and TCP
slows the client down as a busy router would.
A peer that does not read what it is sent is not read either, until it catches up; its
notifications are dropped meanwhile, so a slow client cannot grow the service's memory.

What connections hold is bounded (``connection_limits``, ``[limits]``): a connection
beyond ``connections_per_front_end`` takes the seat of the keyless connection (a peer
of the loopback rule) idle longest, if idle ``idle_connection_s``, or else is closed as
soon as it connects; a frame still
incomplete ``frame_timeout_s`` after its first byte closes its connection; a read that
takes the incomplete frames of all connections over ``receive_buffer_bytes_total``
closes the connection it came from. Each is logged (throttled); the others are served.
"""

from __future__ import annotations

import asyncio
import logging
from collections import deque
from time import perf_counter
from typing import Any, Protocol

from cnc_objects.protocol.ads_commands import decode_request, encode_error_response
from cnc_objects.protocol.ams import (
    AmsFrame,
    AmsHeader,
    AmsStreamParser,
    FrameProblem,
    RouterFrame,
    SkippedFrame,
    StreamItem,
    encode_reply_frame,
    format_net_id,
)
from cnc_objects.protocol.ams_router import (
    decode_port,
    describe,
    encode_local_net_id_reply,
    encode_port_connect_reply,
)
from cnc_objects.protocol.constants import AdsCommand, AmsStateFlag, AmsTcpCommand
from cnc_objects.protocol.errors import AdsReturnCode, ProtocolError
from cnc_objects.protocol.roles import Role

from ..connection_limits import ConnectionLimits, Seat
from ..dispatch import Dispatcher
from ..log_throttle import ThrottledWarning
from ..notifications import NotificationHub
from ..rate_limit import BYTES_PER_TOKEN, RateLimiter, extra_tokens
from .client_ports import ClientPorts, PortRefused
from .routes import Admission, RouteTable

log = logging.getLogger(__name__)

_E = AdsReturnCode
_RESPONSE = AmsStateFlag.RESPONSE
_ADD = AdsCommand.ADD_DEVICE_NOTIFICATION
_READ_WRITE = AdsCommand.READ_WRITE
_ADMIN = Role.ADMIN


class Listener(Protocol):
    """What a connection needs of the server that accepted it (``AdsTcpServer``)."""

    net_id: bytes  # the service's AMS Net ID
    ports: frozenset[int]  # the AMS ports served
    routes: RouteTable
    max_frame_bytes: int
    dispatcher: Dispatcher
    hub: NotificationHub
    connections: set[AmsConnection]  # the open connections, for closing them all
    rate: RateLimiter | None  # requests per connection; None: no limit
    limits: ConnectionLimits  # open connections and bytes of incomplete frames
    client_ports: ClientPorts  # the AMS ports handed out by port registration


class AmsConnection(asyncio.Protocol):
    """The protocol instance of one TCP connection."""

    def __init__(self, server: Listener) -> None:
        self._server = server
        self._net_id = server.net_id
        self._ports = server.ports
        self._dispatch = server.dispatcher.dispatch
        self._dispatch_as = server.dispatcher.dispatch_as
        self._parser = AmsStreamParser(server.max_frame_bytes)
        self._transport: asyncio.Transport | None = None
        self._admission = Admission(False)
        self._envelopes: set[tuple[Any, ...]] = set()  # clients with notifications
        self.peer = "?"
        self._skipped = ThrottledWarning(log, "ADS frame skipped")
        self.paused = False  # the peer does not read: notifications are dropped
        self._rate = server.rate
        self._held: deque[StreamItem] | None = None  # waiting for the rate
        self._held_timer: asyncio.TimerHandle | None = None
        self._limits = server.limits
        self._seat: Seat | None = None  # counted by the limits (released when lost)
        self._buffered = 0  # bytes of the incomplete frame, as the limits account them
        self._frame_started_s: float | None = None  # first byte of the incomplete frame
        self._frame_timer: asyncio.TimerHandle | None = None

    # ------------------------------------------------------------ asyncio.Protocol

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        """Admit the peer by its address, or close at once."""
        self._transport = transport  # type: ignore[assignment]
        peername = transport.get_extra_info("peername") or ("?", 0)
        self.peer = f"{peername[0]}:{peername[1]}"
        self._skipped = ThrottledWarning(log, f"ADS {self.peer}: frame skipped")
        self._admission = self._server.routes.admit(str(peername[0]))
        if not self._admission.allowed:
            log.warning("ADS connection from %s refused: no route for this address", self.peer)
            transport.close()
            return
        # keyed: a peer by route (not the loopback rule): it never gives up its seat
        seat = self._limits.admit(self.peer, self._admission.roles is not None, self.close)
        if seat is None:  # the table is full: closed at once, as a full router does
            transport.close()
            return
        self._seat = seat
        self._server.connections.add(self)
        log.debug("ADS connection from %s", self.peer)

    def data_received(self, data: bytes) -> None:
        """Answer every frame ``data`` completes, in order."""
        parser = self._parser
        items = parser.feed(data)
        if items and self._seat is not None:
            self._seat.used_s = perf_counter()  # not idle: keeps its seat
        if (parser.buffered or self._buffered) and not self._account(items):
            return
        if self._held is not None:  # earlier frames wait for the rate: these behind them
            self._held.extend(items)
            return
        self._answer(items)

    def _account(self, items: list[StreamItem]) -> bool:
        """Tell the limits what the incomplete frame now holds and time it; False when
        that closed the connection (over the receive budget)."""
        buffered = self._parser.buffered
        if not self._limits.buffer(self.peer, self._buffered, buffered):
            self._buffered = 0
            self._parser = AmsStreamParser(self._parser.max_frame_bytes)  # free it now
            self.close()
            return False
        self._buffered = buffered
        if not buffered:
            self._frame_started_s = None
        elif self._frame_started_s is None or items:  # a new frame began
            self._frame_started_s = perf_counter()
            if self._frame_timer is None:
                self._frame_timer = asyncio.get_running_loop().call_later(
                    self._limits.frame_timeout_s, self._frame_deadline)
        return True

    def _frame_deadline(self) -> None:
        """The timer of the incomplete frame: close when it is still the same frame."""
        self._frame_timer = None
        started_s = self._frame_started_s
        if started_s is None or self._transport is None:
            return
        left_s = started_s + self._limits.frame_timeout_s - perf_counter()
        if left_s > 0:  # another frame began since: time that one
            self._frame_timer = asyncio.get_running_loop().call_later(
                left_s, self._frame_deadline)
            return
        self._limits.timed_out.note(f"{self.peer} ({self._buffered} bytes)")
        self.close()

    def _answer(self, items: list[StreamItem]) -> None:
        """Answer ``items`` in order while the rate allows; hold the rest."""
        rate = self._rate
        now_s = perf_counter() if rate is not None else 0.0
        for k, item in enumerate(items):
            if self._transport is None or self._transport.is_closing():
                return
            if rate is not None and not rate.admit(self, now_s):
                self._hold(items[k:], rate.wait_s(self, now_s))
                return
            if type(item) is AmsFrame:
                self._frame(item)
            elif type(item) is RouterFrame:
                self._router_frame(item)
            else:
                self._bad_frame(item)  # type: ignore[arg-type]

    def _hold(self, items: list[StreamItem], wait_s: float) -> None:
        """Over the rate: keep ``items`` and stop reading until a token is due."""
        self._held = deque(items)
        if self._transport is not None:
            self._transport.pause_reading()
        loop = asyncio.get_running_loop()
        self._held_timer = loop.call_later(max(wait_s, 0.001), self._release)

    def _release(self) -> None:
        """A token is due: answer the frames that waited, then read again."""
        self._held_timer = None
        held, self._held = self._held, None
        self._answer(list(held or ()))
        transport = self._transport
        if self._held is None and not self.paused and transport is not None \
                and not transport.is_closing():
            transport.resume_reading()

    def connection_lost(self, exc: Exception | None) -> None:
        """Forget the connection and delete its notifications."""
        for timer in (self._held_timer, self._frame_timer):
            if timer is not None:
                timer.cancel()
        self._held_timer = self._frame_timer = None
        if self._seat is not None:
            self._limits.release(self._seat, self._buffered)
            self._seat = None
            self._buffered = 0
        self._held = None
        if self._rate is not None:
            self._rate.forget(self)
        self._server.connections.discard(self)
        self._server.client_ports.release_all(self)  # its registered AMS ports
        # its jog keys are released at once (the dead-man, ``jog_holds``)
        self._server.dispatcher.backend.connection_ended(self, f"from {self.peer} closed")
        hub = self._server.hub
        for envelope in self._envelopes:
            hub.drop_client(envelope)
        self._envelopes.clear()
        self._transport = None
        if self._parser.buffered:
            log.debug("ADS connection from %s closed inside a frame (%d bytes)",
                      self.peer, self._parser.buffered)

    def pause_writing(self) -> None:
        """The peer does not read: take no more requests from it (their replies would
        pile up here) and drop notifications until it catches up."""
        self.paused = True
        log.debug("ADS %s does not read its replies: not reading it until it does", self.peer)
        if self._transport is not None:
            self._transport.pause_reading()

    def resume_writing(self) -> None:
        """The peer reads again: take its requests again."""
        self.paused = False
        if self._held is None and self._transport is not None \
                and not self._transport.is_closing():
            self._transport.resume_reading()  # unless frames wait for the rate

    # ------------------------------------------------------------ sending

    def write(self, payload: bytes) -> bool:
        """Send ``payload``; False when the connection is gone."""
        transport = self._transport
        if transport is None or transport.is_closing():
            return False
        transport.write(payload)
        return True

    def close(self) -> None:
        """Close the connection (what was written is still sent)."""
        if self._transport is not None:
            self._transport.close()

    # ------------------------------------------------------------ frames

    def _frame(self, frame: AmsFrame) -> None:
        header = frame.header
        if header.state_flags & _RESPONSE:
            log.debug("ADS %s sent a response frame (command %d); ignored",
                      self.peer, header.command_id)
            return
        role = self._admission.role_of(header.source_net_id)
        if role is None:
            log.warning("ADS connection from %s (AMS Net ID %s) closed: no route for this "
                        "Net ID from this address", self.peer, format_net_id(header.source_net_id))
            self.close()
            return
        if header.target_net_id != self._net_id:
            self._router_error(header, _E.TARGETMACHINENOTFOUND)
            return
        if header.target_port not in self._ports:
            self._router_error(header, _E.TARGETPORTNOTFOUND)
            return
        try:
            request = decode_request(
                header.command_id, header.invoke_id, header.target_port, frame.data)
        except ProtocolError as exc:
            log.debug("ADS %s: %s", self.peer, exc)
            error = encode_error_response(header.command_id, exc.code)
            self.write(encode_reply_frame(header, error))
            return
        envelope = (self, header.source_net_id, header.source_port)
        if header.command_id == _ADD:
            self._envelopes.add(envelope)
        if role is _ADMIN:
            reply = self._dispatch(envelope, request)
        else:
            reply = self._dispatch_as(envelope, request, role)
        if reply is not None:
            self.write(reply)
        rate = self._rate
        if rate is not None:  # a big or a sum request costs more than one token
            size = len(frame.data) if reply is None else len(frame.data) + len(reply)
            if size >= BYTES_PER_TOKEN or request.COMMAND == _READ_WRITE:
                rate.charge(self, extra_tokens(request, size))

    def _router_error(self, header: AmsHeader, code: int) -> None:
        """The AMS error a router answers: in the header, no data."""
        log.debug("ADS %s: AMS error 0x%x for %s:%d", self.peer, code,
                  format_net_id(header.target_net_id), header.target_port)
        self.write(encode_reply_frame(header, b"", code))

    def _router_frame(self, frame: RouterFrame) -> None:
        """A command to the router (``protocol.ams_router``), answered as TwinCAT's router
        answers the clients on its own machine: only peers of the loopback rule (TwinCAT's
        router takes these on 127.0.0.1 only); a routed peer is closed."""
        command = frame.command
        if self._admission.roles is not None:
            log.warning("ADS connection from %s closed: AMS/TCP command %s is answered to "
                        "clients on this machine only; a remote client sends from its "
                        "route's AMS Net ID", self.peer, describe(command))
            self.close()
            return
        match command:
            case AmsTcpCommand.PORT_CONNECT:
                self._port_connect(frame.data)
            case AmsTcpCommand.PORT_CLOSE:
                self._port_close(frame.data)
            case AmsTcpCommand.GET_LOCAL_NET_ID:
                self.write(encode_local_net_id_reply(self._net_id))
            case _:  # router notes go to clients, never come from them
                self._skipped.note(f"AMS/TCP command {describe(command)} ({len(frame.data)} "
                                   "bytes) is not answered: a router answers 0x1000 port "
                                   "connect, 0x0001 port close and 0x1002 get local Net ID")

    def _port_connect(self, data: bytes) -> None:
        """Register an AMS port for this client; its AMS Net ID is the service's, as a
        TwinCAT router gives its local clients its own. Refused: closed (logged), as
        TwinCAT's router ends the connection of a client whose port is taken."""
        wanted = decode_port(data)
        if wanted is None:
            self._skipped.note(f"AMS/TCP port connect with {len(data)} bytes of data, not "
                               "2 (the port wanted, 0: any)")
            return
        try:
            port = self._server.client_ports.register(self, wanted)
        except PortRefused as exc:
            log.warning("ADS connection from %s closed: port registration refused: %s",
                        self.peer, exc)
            self.close()
            return
        log.debug("ADS %s: registered AMS port %s:%d", self.peer,
                  format_net_id(self._net_id), port)
        self.write(encode_port_connect_reply(self._net_id, port))

    def _port_close(self, data: bytes) -> None:
        """Release a registered port; the connection closes with its last port, as
        TwinCAT's router ends it (ads-client waits for that)."""
        port = decode_port(data) if data else None
        ports = self._server.client_ports
        if port is None or not ports.release(self, port):
            what = f"port {port}" if port is not None else f"{len(data)} bytes (not 2: a port)"
            self._skipped.note(f"AMS/TCP port close of {what}: not a port this connection "
                               "registered; nothing released")
            return
        log.debug("ADS %s: released AMS port %d", self.peer, port)
        if not ports.held(self):
            self.close()

    def _bad_frame(self, error: SkippedFrame) -> None:
        if error.problem is FrameProblem.TOO_LONG:
            log.warning("ADS connection from %s closed: %s (%d bytes)", self.peer, error,
                        self._parser.max_frame_bytes)
            self.close()
            return
        self._skipped.note(error)
        if error.header is not None and not error.header.state_flags & _RESPONSE:
            self._router_error(error.header, _E.INVALIDAMSLENGTH)
