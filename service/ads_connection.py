"""One ADS client's TCP connection: AMS frames in, replies and notifications out.

An asyncio ``Protocol`` on the service's event loop. Frames are cut from the stream by
``AmsStreamParser`` and answered in order, as a router would:

- a peer without a route is closed as soon as it connects (logged with its address); a
  routed peer that sends from a Net ID that is not its route's is closed at that frame
  (logged with address and Net ID);
- a frame for another AMS Net ID gets AMS error 0x7 (target machine not found), one for
  a port nobody serves AMS error 0x6 (target port not found), both in the AMS header with
  no data, as a router answers;
- an AMS header whose data length disagrees with the AMS/TCP length gets AMS error 0xE;
  a frame too short for an AMS header, or not an AMS command, is skipped (logged): there
  is no invoke id to answer;
- a frame longer than the maximum closes this connection only;
- every ADS request goes to the dispatcher; payloads that do not decode get the ADS
  error the decoder names (0x701 unknown command, 0x705 wrong size), with the length
  the client expects for that command.

Frames with the response flag (0x0001) are not answered: a client never asks with one.
A peer that does not read what it is sent is not read either, until it catches up; its
notifications are dropped meanwhile, so a slow client cannot grow the service's memory.
"""

from __future__ import annotations

import asyncio
import logging
from typing import Any, Protocol

from cnc_objects.protocol.ads_commands import decode_request, encode_error_response
from cnc_objects.protocol.ams import (
    AmsFrame,
    AmsHeader,
    AmsStreamParser,
    FrameError,
    FrameProblem,
    encode_reply_frame,
    format_net_id,
)
from cnc_objects.protocol.constants import AdsCommand, AmsStateFlag
from cnc_objects.protocol.errors import AdsReturnCode, ProtocolError

from .ads_routes import Admission, RouteTable
from .dispatch import Dispatcher
from .notifications import NotificationHub

log = logging.getLogger(__name__)

_E = AdsReturnCode
_RESPONSE = AmsStateFlag.RESPONSE
_ADD = AdsCommand.ADD_DEVICE_NOTIFICATION


class Listener(Protocol):
    """What a connection needs of the server that accepted it (``AdsTcpServer``)."""

    net_id: bytes  # the service's AMS Net ID
    ports: frozenset[int]  # the AMS ports served
    routes: RouteTable
    max_frame_bytes: int
    dispatcher: Dispatcher
    hub: NotificationHub
    connections: set[AmsConnection]  # the open connections, for closing them all


class AmsConnection(asyncio.Protocol):
    """The protocol instance of one TCP connection."""

    def __init__(self, server: Listener) -> None:
        self._server = server
        self._net_id = server.net_id
        self._ports = server.ports
        self._dispatch = server.dispatcher.dispatch
        self._parser = AmsStreamParser(server.max_frame_bytes)
        self._transport: asyncio.Transport | None = None
        self._admission = Admission(False)
        self._envelopes: set[tuple[Any, ...]] = set()  # clients with notifications
        self.peer = "?"
        self.paused = False  # the peer does not read: notifications are dropped

    # ------------------------------------------------------------ asyncio.Protocol

    def connection_made(self, transport: asyncio.BaseTransport) -> None:
        """Admit the peer by its address, or close at once."""
        self._transport = transport  # type: ignore[assignment]
        peername = transport.get_extra_info("peername") or ("?", 0)
        self.peer = f"{peername[0]}:{peername[1]}"
        self._admission = self._server.routes.admit(str(peername[0]))
        if not self._admission.allowed:
            log.warning("ADS connection from %s refused: no route for this address", self.peer)
            transport.close()
            return
        self._server.connections.add(self)
        log.debug("ADS connection from %s", self.peer)

    def data_received(self, data: bytes) -> None:
        """Answer every frame ``data`` completes, in order."""
        for item in self._parser.feed(data):
            if self._transport is None or self._transport.is_closing():
                return
            if type(item) is AmsFrame:
                self._frame(item)
            else:
                self._bad_frame(item)  # type: ignore[arg-type]

    def connection_lost(self, exc: Exception | None) -> None:
        """Forget the connection and delete its notifications."""
        self._server.connections.discard(self)
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
        if self._transport is not None and not self._transport.is_closing():
            self._transport.resume_reading()

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
        if not self._admission.accepts(header.source_net_id):
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
        reply = self._dispatch(envelope, request)
        if reply is not None:
            self.write(reply)

    def _router_error(self, header: AmsHeader, code: int) -> None:
        """The AMS error a router answers: in the header, no data."""
        log.debug("ADS %s: AMS error 0x%x for %s:%d", self.peer, code,
                  format_net_id(header.target_net_id), header.target_port)
        self.write(encode_reply_frame(header, b"", code))

    def _bad_frame(self, error: FrameError) -> None:
        if error.problem is FrameProblem.TOO_LONG:
            log.warning("ADS connection from %s closed: %s (%d bytes)", self.peer, error,
                        self._parser.max_frame_bytes)
            self.close()
            return
        log.warning("ADS %s: frame skipped: %s", self.peer, error)
        if error.header is not None and not error.header.state_flags & _RESPONSE:
            self._router_error(error.header, _E.INVALIDAMSLENGTH)
