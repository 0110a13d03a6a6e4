"""The ADS front end: AMS/TCP on the service's event loop, for unmodified ADS clients.

``AdsTcpServer`` listens (asyncio, one ``AmsConnection`` protocol per connection, no
thread per connection) and is the ``FrontEnd`` of its ``Dispatcher``: it encodes the
dispatcher's answers as AMS frames (``protocol.ams``, ``protocol.ads_commands``) and
sends them on the connection a request came from.

The envelope of an ADS client is ``(connection, client Net ID, client port)``: the
address its requests came from, where replies and notifications go. AMS has no room for
the sentence our ZeroMQ error replies carry; it is logged (debug) instead.

Served AMS ports: 551 GEO, 552 SDA, 553 COM, 851 PLC (HLI symbols) and 10000 (the system
service). By-name access (handles, value by name, symbol information) resolves every
object on every port.
"""

from __future__ import annotations

import asyncio
import itertools
import logging
import socket
import struct
from typing import Any

from cnc_objects.protocol import ads_commands
from cnc_objects.protocol.ams import (
    FRAME_HEADER,
    REQUEST_FLAGS,
    RESPONSE_FLAGS,
    format_net_id,
    parse_net_id,
)
from cnc_objects.protocol.constants import (
    AMS_MAX_FRAME_BYTES,
    AdsCommand,
    AmsPort,
    CncPort,
)
from cnc_objects.protocol.errors import AdsReturnCode, describe_code

from ..backend import Backend
from ..connection_limits import ConnectionLimits
from ..dispatch import Dispatcher
from ..limits import LimitsConfig
from ..rate_limit import RateLimiter
from .client_ports import ClientPorts
from .connection import AmsConnection
from .routes import RouteTable

log = logging.getLogger(__name__)

#: AMS ports this service answers on; a frame for any other gets AMS error 0x6.
SERVED_PORTS = frozenset({*CncPort, AmsPort.SYSTEM_SERVICE})

_AMS_HEADER_BYTES = 32
_READ = AdsCommand.READ
_READ_WRITE = AdsCommand.READ_WRITE
_NOTIFICATION = AdsCommand.DEVICE_NOTIFICATION
_encode_response = ads_commands.encode_response
_pack_frame = FRAME_HEADER.pack
_pack_ok_data = struct.Struct("<II").pack  # result 0 and data length of Read/ReadWrite


def default_net_id(host: str) -> str:
    """The AMS Net ID a service bound to ``host`` takes by default: its IPv4 address and
    ``.1.1``, as TwinCAT derives one. A wildcard or non-IPv4 address takes this host's
    own address (its name resolved), else 127.0.0.1."""
    try:
        parts = socket.inet_aton(host)
    except OSError:
        parts = b"\x00\x00\x00\x00"
    if parts == b"\x00\x00\x00\x00":
        try:
            parts = socket.inet_aton(socket.gethostbyname(socket.gethostname()))
        except OSError:
            parts = b"\x7f\x00\x00\x01"
    return ".".join(str(b) for b in parts) + ".1.1"


class AdsTcpServer:
    """Serves a ``Backend`` over ADS (AMS/TCP) to every client that has a route."""

    #: Beckhoff's AdsLib (pyads) registers a notification handle only after it has read
    #: the AddDeviceNotification response, on another thread: a sample right behind the
    #: response finds no handle and is dropped. The first sample waits this long (a
    #: TwinCAT PLC, too, sends it from a later task cycle).
    first_sample_delay_s = 0.05

    def __init__(
        self,
        backend: Backend,
        routes: RouteTable | None = None,
        max_frame_bytes: int = AMS_MAX_FRAME_BYTES,
        rate: RateLimiter | None = None,
        limits: LimitsConfig | None = None,
    ) -> None:
        self.backend = backend
        self.hub = backend.hub
        self.net_id = b""  # set by start
        self.routes = routes if routes is not None else RouteTable()  # empty is falsy
        self.max_frame_bytes = max_frame_bytes
        self.rate = rate  # requests per connection ([limits]); None: no limit
        # open connections and bytes of incomplete frames ([limits])
        self.limits = ConnectionLimits("ADS", limits or LimitsConfig())
        self.ports = SERVED_PORTS
        # AMS ports handed to clients that register one (a client without a Net ID)
        self.client_ports = ClientPorts(reserved=SERVED_PORTS)
        self.dispatcher = Dispatcher(backend, self)
        self.connections: set[AmsConnection] = set()
        self.address: tuple[str, int] = ("", 0)
        self._server: asyncio.base_events.Server | None = None
        self._invoke_ids = itertools.count(1)  # of the notifications we send

    async def start(self, host: str, port: int, net_id: str | None = None) -> None:
        """Bind ``host:port`` and serve as AMS Net ID ``net_id`` (default: from the bound
        address, ``default_net_id``); ``OSError`` when the address cannot be bound."""
        server = await self.backend.loop.create_server(
            lambda: AmsConnection(self), host, port, reuse_address=True, start_serving=False,
        )
        sockname = server.sockets[0].getsockname()
        self.address = (sockname[0], sockname[1])
        self.net_id = parse_net_id(net_id or default_net_id(self.address[0]))
        self._server = server
        await server.start_serving()

    @property
    def net_id_text(self) -> str:
        """The AMS Net ID as ``a.b.c.d.e.f``."""
        return format_net_id(self.net_id)

    def close(self) -> None:
        """Stop listening and close every connection."""
        if self._server is not None:
            self._server.close()
            self._server = None
        for connection in list(self.connections):
            connection.close()

    # ------------------------------------------------------------ FrontEnd (dispatch.py)

    def ok(self, envelope: tuple[Any, ...], req: Any, *fields: Any) -> bytes:
        """The response frame of ``req`` with its fields."""
        command = req.COMMAND
        payload: bytes
        if command == _READ or command == _READ_WRITE:  # the hot path: data only
            data = fields[0]
            payload = _pack_ok_data(0, len(data)) + data
        else:
            payload = _encode_response(command, *fields)
        frame: bytes = _pack_frame(
            0, _AMS_HEADER_BYTES + len(payload), envelope[1], envelope[2], self.net_id,
            req.port, command, RESPONSE_FLAGS, len(payload), 0, req.invoke_id,
        )
        return frame + payload

    def error(self, envelope: tuple[Any, ...], req: Any, code: int, message: str) -> bytes:
        """The error response frame of ``req``: the command's length, result ``code``."""
        if code == AdsReturnCode.TARGETPORTNOTFOUND:
            # Over AMS the router answered for the port already; a port we serve that has
            # no objects (552, 10000) has no such index group.
            code = AdsReturnCode.DEVICE_INVALIDGRP
        log.debug("ADS %s:%d invoke %d: %s: %s", format_net_id(envelope[1]), envelope[2],
                  req.invoke_id, describe_code(code), message)
        payload = ads_commands.encode_error_response(req.COMMAND, code)
        return _pack_frame(
            0, _AMS_HEADER_BYTES + len(payload), envelope[1], envelope[2], self.net_id,
            req.port, req.COMMAND, RESPONSE_FLAGS, len(payload), 0, req.invoke_id,
        ) + payload

    @staticmethod
    def send(envelope: tuple[Any, ...], payload: bytes) -> bool:
        """Send on the client's connection; False when it is gone."""
        delivered: bool = envelope[0].write(payload)
        return delivered

    def notify(self, envelope: tuple[Any, ...], port: int, samples: list[list[Any]]) -> bool:
        """A DeviceNotification to the client's Net ID and port, from ``port`` of ours
        (where it subscribed); samples of one timestamp share a stamp. Dropped (False)
        while the client does not read what it was sent."""
        connection = envelope[0]
        if connection.paused:
            return False
        payload = ads_commands.encode_notification(
            [(timestamp, handle, data) for handle, _, timestamp, data in samples]
        )
        frame = _pack_frame(
            0, _AMS_HEADER_BYTES + len(payload), envelope[1], envelope[2], self.net_id, port,
            _NOTIFICATION, REQUEST_FLAGS, len(payload), 0, next(self._invoke_ids) & 0xFFFFFFFF,
        ) + payload
        delivered: bool = connection.write(frame)
        return delivered

    @staticmethod
    def cycle_ns(req: Any) -> int:
        """ADS gives the cycle time in 100 ns."""
        cycle_100ns: int = req.cycle_time_100ns
        return cycle_100ns * 100
