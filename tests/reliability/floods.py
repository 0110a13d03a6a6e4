"""Connection floods and half-sent frames, as an attacker sends them: raw TCP sockets,
no client library.

- ``ads_half_frame``: an AMS/TCP frame whose header announces ``announced`` bytes, sent
  without its last ``missing`` bytes;
- ``zmtp_half_frame``: a ZeroMQ (ZMTP 3.0, NULL mechanism) greeting and READY as a
  DEALER sends them, then one data frame announcing ``announced`` bytes, sent without
  its last ``missing`` bytes;
- ``Flood``: many such connections opened at once and kept open, with a count of those
  the service has closed since.
"""

from __future__ import annotations

import socket
import struct
import time
from collections.abc import Callable

from cnc_objects.protocol.ams import AMS_HEADER_BYTES, FRAME_HEADER, REQUEST_FLAGS
from cnc_objects.protocol.constants import AdsCommand

ADS_TARGET = bytes([127, 0, 0, 1, 1, 1])
ADS_SOURCE = bytes([127, 0, 0, 1, 9, 9])
CONNECT_TIMEOUT_S = 10.0


def ads_half_frame(announced: int, missing: int) -> bytes:
    """An AMS/TCP Write frame whose AMS/TCP length says ``announced`` bytes, without its
    last ``missing`` bytes (its data all zero)."""
    data_bytes = announced - AMS_HEADER_BYTES
    head = FRAME_HEADER.pack(0, announced, ADS_TARGET, 851, ADS_SOURCE, 30000,
                             AdsCommand.WRITE, REQUEST_FLAGS, data_bytes, 0, 1)
    return head + bytes(data_bytes - missing)


def zmtp_greeting() -> bytes:
    """A ZMTP 3.0 client greeting (NULL mechanism) and its READY command (DEALER)."""
    greeting = (b"\xff" + bytes(8) + b"\x7f" + bytes([3, 0]) + b"NULL".ljust(20, b"\x00")
                + b"\x00" + bytes(31))
    prop = b"\x0bSocket-Type" + struct.pack(">I", 6) + b"DEALER"
    body = b"\x05READY" + prop
    return greeting + bytes([0x04, len(body)]) + body


def zmtp_half_frame(announced: int, missing: int) -> bytes:
    """Greeting, READY, and a data frame of ``announced`` bytes without its last
    ``missing`` bytes."""
    return zmtp_greeting() + b"\x02" + struct.pack(">Q", announced) + bytes(announced - missing)


class Flood:
    """``count`` TCP connections to ``address``, each sent ``payload`` and held open."""

    def __init__(self, address: tuple[str, int], count: int, payload: bytes) -> None:
        self.sockets: list[socket.socket] = []
        for _ in range(count):
            sock = socket.create_connection(address, timeout=CONNECT_TIMEOUT_S)
            sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, 4096)
            try:
                sock.sendall(payload)
            except OSError:  # closed by the service already (over a limit)
                pass
            self.sockets.append(sock)

    def closed_by_service(self) -> int:
        """How many of the connections the service has closed (EOF or reset)."""
        closed = 0
        for sock in self.sockets:
            sock.setblocking(False)
            try:
                while True:
                    data = sock.recv(65536)
                    if not data:
                        closed += 1
                        break
            except BlockingIOError:
                pass  # open, nothing more to read
            except OSError:
                closed += 1
        return closed

    def wait_closed(self, at_least: int, timeout_s: float) -> int:
        """Wait until at least ``at_least`` are closed; how many are (maybe fewer after
        ``timeout_s``)."""
        return wait_until(lambda: self.closed_by_service(), at_least, timeout_s)

    def close(self) -> None:
        """Close every connection of the flood."""
        for sock in self.sockets:
            sock.close()
        self.sockets.clear()

    def __enter__(self) -> Flood:
        return self

    def __exit__(self, *exc: object) -> None:
        self.close()


def wait_until(measure: Callable[[], int], at_least: int, timeout_s: float) -> int:
    """Poll ``measure`` until it gives at least ``at_least`` or ``timeout_s`` passed; its
    last value."""
    deadline = time.monotonic() + timeout_s
    value = measure()
    while value < at_least and time.monotonic() < deadline:
        time.sleep(0.05)
        value = measure()
    return value


class AdsProbe:
    """One ADS connection of a well-behaved client: ``read_device_info`` asks and waits
    for its reply (the ADS result code of the response)."""

    def __init__(self, address: tuple[str, int], net_id: str) -> None:
        self.sock = socket.create_connection(address, timeout=CONNECT_TIMEOUT_S)
        self.net_id = bytes(int(p) for p in net_id.split("."))
        self._invoke_id = 0

    def read_device_info(self, timeout_s: float = CONNECT_TIMEOUT_S) -> int:
        """The result code of a ReadDeviceInfo to port 851; OSError when no reply."""
        self._invoke_id += 1
        self.sock.settimeout(timeout_s)
        self.sock.sendall(FRAME_HEADER.pack(
            0, AMS_HEADER_BYTES, self.net_id, 851, ADS_SOURCE, 30000,
            AdsCommand.READ_DEVICE_INFO, REQUEST_FLAGS, 0, 0, self._invoke_id))
        while True:
            head = self._exactly(FRAME_HEADER.size)
            fields = FRAME_HEADER.unpack(head)
            data = self._exactly(fields[8])
            if fields[10] == self._invoke_id:
                return int.from_bytes(data[:4], "little")

    def _exactly(self, count: int) -> bytes:
        chunks = bytearray()
        while len(chunks) < count:
            chunk = self.sock.recv(count - len(chunks))
            if not chunk:
                raise ConnectionError("the service closed the connection")
            chunks += chunk
        return bytes(chunks)

    def close(self) -> None:
        """Close the connection."""
        self.sock.close()
