"""The AMS router's own commands on AMS/TCP: port registration, as a local client asks a
TwinCAT router for its AMS address.

A client on the router's machine that has no AMS address of its own (ads-client and so
Node-RED's ADS nodes without a local AMS Net ID, ads-rs with ``Source::Request``,
HslCommunication's auto Net ID) asks the router for one before its first ADS request.
These frames have a non-zero first u16 in the AMS/TCP header (``AmsTcpCommand``) and no
AMS header; all integers are little-endian::

    port connect (client -> router)    0x1000  length 2   requested port u16 (0: any)
    port connect (router -> client)    0x1000  length 8   client Net ID 6 x u8, port u16
    port close   (client -> router)    0x0001  length 2   the client's port u16
    get local Net ID (client -> router) 0x1002 length 4   (ignored)
    get local Net ID (router -> client) 0x1002 length 6   the router's Net ID 6 x u8

The layout is ads-client's (``_registerAdsPort``, ``_unregisterAdsPort``,
``AMS_HEADER_FLAG`` in jisotalo/ads-client) and ads-rs's (``Client::new`` with
``Source::Request``, the port close in ``Drop``); Beckhoff's specification names the
field "reserved" and documents only the 0 of an AMS command. A port close has no reply:
TwinCAT's router ends the connection instead (ads-client waits for that).
"""

from __future__ import annotations

import struct

from .ams import AMS_TCP_HEADER
from .constants import AmsTcpCommand

_PORT = struct.Struct("<H")
NET_ID_BYTES = 6


def decode_port(data: bytes) -> int | None:
    """The u16 port of a port connect or port close; a port connect without data asks
    for any port (0). None when ``data`` is not 2 bytes (nor empty)."""
    if len(data) == _PORT.size:
        port: int = _PORT.unpack(data)[0]
        return port
    return 0 if not data else None


def encode_port_connect_reply(net_id: bytes, port: int) -> bytes:
    """The router's answer to a port connect: the client's AMS address."""
    return AMS_TCP_HEADER.pack(AmsTcpCommand.PORT_CONNECT, NET_ID_BYTES + _PORT.size) \
        + net_id + _PORT.pack(port)


def encode_local_net_id_reply(net_id: bytes) -> bytes:
    """The router's answer to a get local Net ID: its own AMS Net ID."""
    return AMS_TCP_HEADER.pack(AmsTcpCommand.GET_LOCAL_NET_ID, NET_ID_BYTES) + net_id


def describe(command: int) -> str:
    """``0x1000 (port connect)`` for a router command, ``0x1234`` for an unknown one."""
    try:
        name = AmsTcpCommand(command).name.lower().replace("_", " ")
    except ValueError:
        return f"0x{command:04x}"
    return f"0x{command:04x} ({name})"
