"""ADS frames by hand over a TCP socket, no ADS library in between: what a test sends and
gets, byte for byte."""

from __future__ import annotations

import itertools
import socket
import struct
from dataclasses import dataclass

from cnc_objects.testing import ServiceProcess

READ_DEVICE_INFO, READ, WRITE, READ_STATE, WRITE_CONTROL = 1, 2, 3, 4, 5


ADD_NOTIFICATION, DELETE_NOTIFICATION, NOTIFICATION, READ_WRITE = 6, 7, 8, 9


REQUEST, RESPONSE = 0x0004, 0x0005


GEO, COM, PLC, SYSTEM = 551, 553, 851, 10000


CH1_GEO, CH1_COM = 0x121301, 0x120101


CLIENT_NET_ID = bytes([10, 11, 12, 13, 1, 1])


CLIENT_PORT = 32905


TIMEOUT_S = 10.0


_invoke_ids = itertools.count(1)


@dataclass(frozen=True)
class Reply:
    """A frame the service sent, split by the specification's layout."""

    target_net_id: bytes
    target_port: int
    source_net_id: bytes
    source_port: int
    command: int
    flags: int
    length: int
    error: int
    invoke_id: int
    data: bytes

    @property
    def result(self) -> int:
        """The ADS result: the data's first u32."""
        return struct.unpack_from("<I", self.data)[0]


def frame(command: int, data: bytes = b"", *, port: int, target: bytes, invoke_id: int,
          flags: int = REQUEST, length: int | None = None,
          source: bytes = CLIENT_NET_ID) -> bytes:
    """A request frame from the Net ID ``source``; ``length`` overrides the AMS header's
    data length."""
    header = struct.pack("<6sH6sHHHIII", target, port, source, CLIENT_PORT, command,
                         flags, len(data) if length is None else length, 0, invoke_id)
    return struct.pack("<HI", 0, 32 + len(data)) + header + data


class RawAds:
    """A TCP connection speaking AMS frames built by hand."""

    def __init__(self, service: ServiceProcess, receive_buffer_bytes: int | None = None,
                 source_address: str | None = None) -> None:
        """``source_address``: the local IP address to connect from (default: any)."""
        host, port = service.ads_address  # type: ignore[misc]
        self.net_id = bytes(int(p) for p in service.ams_net_id.split("."))  # type: ignore[union-attr]
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        if receive_buffer_bytes is not None:  # before connecting: it sets the TCP window
            self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, receive_buffer_bytes)
        if source_address is not None:
            self.sock.bind((source_address, 0))
        self.sock.settimeout(TIMEOUT_S)
        self.sock.connect((host, port))
        self.sock.setsockopt(socket.IPPROTO_TCP, socket.TCP_NODELAY, 1)
        self._buffer = b""
        self.notifications: list[Reply] = []  # received while waiting for a reply

    def close(self) -> None:
        self.sock.close()

    def send(self, command: int, data: bytes = b"", port: int = PLC, **options: object) -> int:
        """Send one request; its invoke id."""
        invoke_id = int(options.pop("invoke_id", next(_invoke_ids)))  # type: ignore[call-overload]
        target = options.pop("target", self.net_id)
        self.sock.sendall(frame(command, data, port=port, target=target,  # type: ignore[arg-type]
                                invoke_id=invoke_id, **options))  # type: ignore[arg-type]
        return invoke_id

    def _read(self, size: int) -> bytes:
        while len(self._buffer) < size:
            chunk = self.sock.recv(65536)
            if not chunk:
                raise ConnectionError("the service closed the connection")
            self._buffer += chunk
        out, self._buffer = self._buffer[:size], self._buffer[size:]
        return out

    def receive(self) -> Reply:
        """The next frame the service sends (reply or notification)."""
        reserved, length = struct.unpack("<HI", self._read(6))
        assert reserved == 0
        body = self._read(length)
        fields = struct.unpack_from("<6sH6sHHHIII", body)
        assert fields[6] == length - 32, "AMS data length must match the AMS/TCP length"
        return Reply(*fields, body[32:])

    def reply(self, invoke_id: int) -> Reply:
        """The reply to ``invoke_id`` (notifications in between are kept for later)."""
        while True:
            got = self.receive()
            if got.flags == RESPONSE:  # a notification is a request from the service
                assert got.invoke_id == invoke_id, f"reply to {got.invoke_id}, not {invoke_id}"
                return got
            self.notifications.append(got)

    def notification(self) -> Reply:
        """The next DeviceNotification (kept ones first)."""
        while True:
            got = self.notifications.pop(0) if self.notifications else self.receive()
            if got.command == NOTIFICATION and got.flags == REQUEST:
                return got

    def call(self, command: int, data: bytes = b"", port: int = PLC, **options: object) -> Reply:
        """Send a request and return its reply."""
        return self.reply(self.send(command, data, port, **options))

    def closed_by_peer(self) -> bool:
        """True once the service has closed the connection (waits up to the timeout)."""
        try:
            while True:
                self._read(len(self._buffer) + 1)
        except (ConnectionError, OSError):
            return True


def read(group: int, offset: int, length: int) -> bytes:
    return struct.pack("<III", group, offset, length)


def write(group: int, offset: int, data: bytes) -> bytes:
    return struct.pack("<III", group, offset, len(data)) + data


def read_write(group: int, offset: int, read_length: int, data: bytes) -> bytes:
    return struct.pack("<IIII", group, offset, read_length, len(data)) + data


def add_notification(group: int, offset: int, length: int, mode: int, cycle_100ns: int) -> bytes:
    return struct.pack("<IIIIII", group, offset, length, mode, 0, cycle_100ns) + bytes(16)
